// SPDX-License-Identifier: Apache-2.0
// ros2.publish in a build without Cyclone DDS: a configuration error (exit 2) saying what the
// build lacks, as source.type ros2 is. With Cyclone the outputs are tested on loopback in
// tests/dds (this family does not confine DDS to loopback, so it publishes nothing).
#include "../support/run_cli.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

TEST(Ros2PublishCli, WithoutCycloneDdsIsAConfigurationError) {
#if HRCSENSE_HAVE_DDS
  GTEST_SKIP() << "this build has Cyclone DDS: tests/dds runs ros2.publish on loopback";
#else
  const test::CliResult result = test::cli("run --set ros2.publish=true --frames 1");
  EXPECT_EQ(result.exit_code, 2) << result.out;
  EXPECT_NE(result.out.find("ros2.publish"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("built without Cyclone DDS"), std::string::npos) << result.out;
#endif
}

}  // namespace
}  // namespace hrcsense
