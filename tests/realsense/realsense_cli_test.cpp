// SPDX-License-Identifier: Apache-2.0
// Tests of the `hrcsense` executable's RealSense parts in a build without the SDK (CI): `run`
// with source.type realsense and `hrcsense devices` give one clear error and exit 2.
#include "../support/cli_folder.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

class RealSenseCli : public hrcsense::test::CliFolder {
 protected:
  void SetUp() override {
#ifdef HRCSENSE_HAVE_REALSENSE
    GTEST_SKIP() << "this build has the RealSense SDK: the no-SDK errors do not apply";
#endif
    CliFolder::SetUp();
  }

  // One line on stderr: the error, saying that the SDK is missing and how to get it.
  static void expect_no_sdk(const hrcsense::test::CliOutcome& outcome, const std::string& what) {
    EXPECT_EQ(outcome.exit_code, 2) << outcome.err;
    const std::vector<std::string> lines = outcome.err_lines();
    ASSERT_EQ(lines.size(), 1U) << outcome.err;
    EXPECT_EQ(lines[0], "hrcsense: error: " + what +
                            ": this hrcsense was built without the RealSense SDK (librealsense2); install Intel's "
                            "librealsense2-dev and rebuild (README, 'Cameras')");
    EXPECT_EQ(outcome.out, "");  // no JSON header for a source that was never opened
  }
};

TEST_F(RealSenseCli, RunWithoutTheSdkSaysHowToGetIt) {
  expect_no_sdk(run("run --set source.type=realsense"), "configuration: source.type 'realsense'");
  write("cell.yaml", "source: {type: realsense, fps: 90}\n");
  expect_no_sdk(run("run --config cell.yaml --frames 3"), "cell.yaml: source.type 'realsense'");
}

TEST_F(RealSenseCli, InfoWithoutTheSdkSaysHowToGetIt) {
  expect_no_sdk(run("info --set source.type=realsense"), "configuration: source.type 'realsense'");
}

TEST_F(RealSenseCli, DevicesWithoutTheSdkSaysHowToGetIt) {
  expect_no_sdk(run("devices"), "hrcsense devices");
}

TEST_F(RealSenseCli, ABadCameraKeyIsAConfigErrorBeforeTheSdkIsAsked) {
  const hrcsense::test::CliOutcome outcome = run("run --set source.type=realsense --set source.fps=45");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_NE(outcome.err.find("'source.fps'"), std::string::npos) << outcome.err;
  EXPECT_EQ(outcome.err.find("RealSense SDK"), std::string::npos) << outcome.err;
}

}  // namespace
