// SPDX-License-Identifier: Apache-2.0
// Acceptance (issue H3): the camera pose check never fires with the right pose in 10^4 frames of
// the shipped arm cells: the moving UR5 cell run for 9000 frames (its pick-and-place cycle loops;
// the person comes and goes in frames 120-600) and the fixed UR5 cell for 1000 (the person stands
// behind the arm from frame 195 on).

#include "../support/pose_runs.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

TEST(CameraPoseCheckLong, NeverFiresInTenThousandFramesOfTheShippedArmCells) {
  struct Run {
    const char* cell;
    size_t frames;
  };
  size_t checked = 0;
  for (const Run run : {Run{"cell-ur5-moving.yaml", 9000}, Run{"cell-ur5.yaml", 1000}}) {
    const std::string frames = std::to_string(run.frames);
    const auto lines = test::run_frame_reasons(run.cell, "--set sim.frames=" + frames, std::string("pose_long_") + run.cell);
    ASSERT_EQ(lines.size(), run.frames) << run.cell;
    EXPECT_EQ(test::first_with(lines, "camera_pose_mismatch"), -1) << run.cell;
    checked += lines.size();
  }
  EXPECT_EQ(checked, 10000U);
}

}  // namespace
}  // namespace hrcsense
