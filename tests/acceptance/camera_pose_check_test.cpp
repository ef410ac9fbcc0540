// SPDX-License-Identifier: Apache-2.0
// Acceptance (issue H3): a camera 1° or 1 cm off the pose hrcsense is told stops with
// camera_pose_mismatch within max(30 frames, 1 s) of the first frame with the arm in view, from
// the start (before and while learning) and after a knock during a run; with the right pose it
// does not fire. The simulator renders from the true pose (sim.camera_T_base_camera, docs/SIMULATOR.md);
// the arm is in view from frame 0 in both shipped arm cells (fixed, and moving over the table).

#include "../support/pose_runs.hpp"
#include "../support/sanitized.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::first_with;
using test::run_frame_reasons;

// Both cells run at 30 frames/s: 1 s is 30 frames, so the bound is 30 frames.
constexpr int64_t kBoundFrames = std::max<int64_t>(30, 30 * 1);

// The told pose of both cells: camera.T_base_camera {translation_m: [2.0, 0, 1.6],
// rotation_rpy_deg: [-125, 0, 90]}.
std::string true_pose(const std::string& translation, const std::string& rpy, const std::string& key = "camera_T_base_camera") {
  return "--set 'sim." + key + "={translation_m: " + translation + ", rotation_rpy_deg: " + rpy + "}'";
}

struct PoseError {
  const char* name;
  std::string set;
};

const PoseError kErrors[] = {
    {"tilted_1deg", true_pose("[2.0, 0, 1.6]", "[-124, 0, 90]")},      // roll: the camera looks 1° higher
    {"turned_1deg", true_pose("[2.0, 0, 1.6]", "[-125, 0, 91]")},      // yaw: turned 1° about base z
    {"along_x_1cm", true_pose("[2.01, 0, 1.6]", "[-125, 0, 90]")},     // 1 cm further from the arm
    {"along_y_1cm", true_pose("[2.0, 0.01, 1.6]", "[-125, 0, 90]")},   // 1 cm to the side
    {"lower_1cm", true_pose("[2.0, 0, 1.59]", "[-125, 0, 90]")},       // 1 cm lower
};

// Under ASan and UBSan each run is several times slower: there the fixed cell and every third
// error stand for the rest, which the release build runs in full.
std::vector<const char*> pose_cells() {
  if (test::kSanitized) return {"cell-ur5.yaml"};
  return {"cell-ur5.yaml", "cell-ur5-moving.yaml"};
}
std::vector<PoseError> pose_errors() {
  std::vector<PoseError> errors;
  const size_t step = test::kSanitized ? 3 : 1;
  for (size_t i = 0; i < std::size(kErrors); i += step) errors.push_back(kErrors[i]);
  return errors;
}

TEST(CameraPoseCheck, AWrongPoseStopsFromTheStart) {
  for (const char* cell : pose_cells()) {
    for (const PoseError& error : pose_errors()) {
      const auto frames = run_frame_reasons(cell, "--frames 60 " + error.set, std::string("pose_start_") + error.name);
      ASSERT_EQ(frames.size(), 60U) << cell << " " << error.name;
      const int64_t first = first_with(frames, "camera_pose_mismatch");
      EXPECT_GE(first, 0) << cell << " " << error.name << ": never fired";
      EXPECT_LE(first, kBoundFrames) << cell << " " << error.name;
      // Once fired it holds while the pose stays wrong.
      for (const auto& f : frames) {
        if (first >= 0 && f.frame > first) {
          EXPECT_EQ(f.reason_code, "camera_pose_mismatch") << cell << " " << f.frame;
        }
      }
    }
  }
}

TEST(CameraPoseCheck, AKnockDuringTheRunStopsWithinTheBound) {
  constexpr int64_t kKnock = 150;  // after learning (100 frames), the person in the cell
  for (const char* cell : pose_cells()) {
    const std::string knock = "--frames 200 --set sim.camera_knock_frame=150 " +
                              true_pose("[2.0, 0, 1.6]", "[-124, 0, 90]", "camera_knock_T_base_camera");
    const auto frames = run_frame_reasons(cell, knock, std::string("pose_knock_") + cell);
    ASSERT_EQ(frames.size(), 200U) << cell;
    EXPECT_EQ(first_with(frames, "camera_pose_mismatch"), first_with(frames, "camera_pose_mismatch", kKnock))
        << cell << ": fired before the knock";
    const int64_t first = first_with(frames, "camera_pose_mismatch", kKnock);
    EXPECT_GE(first, kKnock) << cell;
    EXPECT_LE(first, kKnock + kBoundFrames) << cell;
  }
}

TEST(CameraPoseCheck, TheRightPoseNeverFiresInTheShortRuns) {
  if (test::kSanitized) GTEST_SKIP() << "the ci build runs it and CameraPoseCheckLong's 10 000 frames; the check runs under the sanitizers in the other CameraPoseCheck tests (CI time)";
  for (const char* cell : pose_cells()) {
    const auto frames = run_frame_reasons(cell, "--frames 300", std::string("pose_right_") + cell);
    ASSERT_EQ(frames.size(), 300U) << cell;
    EXPECT_EQ(first_with(frames, "camera_pose_mismatch"), -1) << cell;
  }
}

TEST(CameraPoseCheck, OffForTheCheckSwitchedOff) {
  const auto frames = run_frame_reasons("cell-ur5.yaml", "--frames 40 --set safety.pose_check=false " + kErrors[0].set,
                                        "pose_off");
  ASSERT_EQ(frames.size(), 40U);
  EXPECT_EQ(first_with(frames, "camera_pose_mismatch"), -1);
}

}  // namespace
}  // namespace hrcsense
