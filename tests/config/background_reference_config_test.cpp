// SPDX-License-Identifier: Apache-2.0
// background.reference (issue 30, item 6): a string key, empty by default, documented in
// docs/CONFIG.md's background table, read into Config and the effective configuration. The file
// itself is read at start (tests/cli/teach_cli_test.cpp: a missing file is a ConfigError naming
// the key and the file, a damaged one an IoError naming the file), so that `hrcsense teach` can
// write the reference a configuration already names.
#include "config_test_util.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

namespace hrcsense {
namespace {

using test::expect_config_error;

TEST(BackgroundReferenceConfig, DefaultIsNoneAndAPathIsRead) {
  EXPECT_TRUE(load_config("", {}).background_reference.empty());
  const Config set = load_config("", {"background.reference=cell/reference.bin"});
  EXPECT_EQ(set.background_reference, "cell/reference.bin");
  EXPECT_NE(set.canonical_yaml.find("reference: cell/reference.bin"), std::string::npos) << set.canonical_yaml;
  EXPECT_NE(config_hash(set), config_hash(load_config("", {})));
  // A file that does not exist yet is fine here: teach writes it.
  test::TempDir dir;
  const std::string file = dir.write("cell.yaml", "background: {frames: 10, reference: not-yet.bin}\n");
  EXPECT_EQ(load_config(file, {}).background_reference, "not-yet.bin");
}

TEST(BackgroundReferenceConfig, WrongTypeOrMisspeltKeyIsAnErrorNamingIt) {
  expect_config_error("", {"background.reference=[a, b]"}, {"'background.reference'"});
  expect_config_error("", {"background.reference={x: 1}"}, {"'background.reference'"});
  expect_config_error("", {"background.referense=r.bin"}, {"unknown key 'background.referense'"});
}

TEST(BackgroundReferenceConfig, KeyIsDocumentedInTheBackgroundTable) {
  std::ifstream in(std::string(HRCSENSE_SOURCE_DIR) + "/docs/CONFIG.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string docs = text.str();
  const size_t section = docs.find("\n## background\n");
  ASSERT_NE(section, std::string::npos);
  const size_t next = docs.find("\n## ", section + 1);
  const size_t row = docs.find("| `background.reference` | string | `\"\"` |", section);
  ASSERT_NE(row, std::string::npos) << "no row for background.reference in docs/CONFIG.md";
  EXPECT_LT(row, next);
}

}  // namespace
}  // namespace hrcsense
