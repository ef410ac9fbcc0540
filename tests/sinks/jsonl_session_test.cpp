// SPDX-License-Identifier: Apache-2.0
// The JSON Lines header's `session` (docs/OUTPUT.md; issue 30 item 4): the process's session,
// the one the link's datagrams carry, written unsigned right after config_hash; null when the
// header was assembled without one.
#include "hrcsense/session.hpp"
#include "hrcsense/sinks/sinks.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>
#include <string>

namespace hrcsense {
namespace {

std::string header_line(uint32_t session) {
  std::ostringstream out;
  JsonLinesSink sink(out);
  RunHeader header;
  header.config_hash = "0123456789abcdef";
  header.session = session;
  sink.header(header);
  return out.str();
}

TEST(JsonLinesSession, TheHeaderCarriesTheSessionAfterTheConfigHash) {
  const std::string line = header_line(0xFFFFFFFFU);
  EXPECT_NE(line.find(R"("config_hash":"0123456789abcdef","session":4294967295,)"), std::string::npos) << line;
  EXPECT_EQ(nlohmann::json::parse(line).at("session").get<uint64_t>(), 4294967295U);
  EXPECT_NE(header_line(7).find(R"("session":7,)"), std::string::npos);
}

TEST(JsonLinesSession, NoSessionIsNull) {
  const std::string line = header_line(0);
  EXPECT_NE(line.find(R"("session":null,)"), std::string::npos) << line;
  EXPECT_TRUE(nlohmann::json::parse(line).at("session").is_null());
}

TEST(ProcessSession, NonZeroAndTheSameForTheWholeProcess) {
  const uint32_t session = process_session();
  EXPECT_NE(session, 0U);
  for (int k = 0; k < 100; ++k) EXPECT_EQ(process_session(), session);
}

}  // namespace
}  // namespace hrcsense
