// SPDX-License-Identifier: Apache-2.0
// Test support: `hrcsense run` as a child process on a small noise-free cell, for the tests
// that feed it a live robot state from this process (rtde_cli_test.cpp, udp_json_test.cpp).
#pragma once

#include "hrcsense/types.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>

#include <unistd.h>

namespace hrcsense::test {

// A noise-free cell: the UR5 of config/cell-ur5.yaml at its fixed pose, a floor, and a box that
// appears beside the arm at frame 15, after the 10 learning frames; 75 frames, paced (2.5 s).
// Noise-free, the learnt background and every contact are the same whichever frames were
// learnt from or dropped, so a run with a live state can be compared frame by frame with
// `robot.state.source: fixed` at the same joints.
inline constexpr const char* kCliCell = R"(source: {type: sim, seed: 1, pace: true}
sim: {width: 848, height: 480, fps: 30, frames: 75, noise: false, color: false}
camera:
  T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-125, 0, 90]}
scene:
  objects:
    - name: floor
      static: true
      shapes:
        - plane: {point: [0, 0, -0.75], normal: [0, 0, 1]}
    - name: box
      static: false
      first_frame: 15
      shapes:
        - box: {min: [0.5, -0.1, 0.0], max: [0.7, 0.1, 0.3]}
background: {frames: 10}
robot:
  model: ur5
  base_frame: base
  padding_m: 0.05
  joints_rad: [-0.941593, -1.5, 1.4, -1.7, -1.5708, 0.0]
safety: {slow_distance_m: 1.0, stop_distance_m: 0.5}
)";
inline const JointAngles kCliJoints{-0.941593, -1.5, 1.4, -1.7, -1.5708, 0.0};

/// Writes kCliCell to a temporary file and returns its path.
/// A file name in the test's temporary folder, with this process's id: two test runs on one
/// machine (a developer's and a clean clone's) must not read each other's files.
inline std::string temp_path(const std::string& stem, const std::string& extension) {
  return std::string(::testing::TempDir()) + stem + "_" + std::to_string(::getpid()) + extension;
}

inline std::string write_cli_cell(const std::string& name) {
  const std::string path = temp_path("cli_cell_" + name, ".yaml");
  std::ofstream(path) << kCliCell;
  return path;
}

/// Where run_tool(…, name) writes its JSON Lines.
inline std::string cli_out_path(const std::string& name) { return temp_path("cli_" + name, ".jsonl"); }

/// How many frame lines the run writing `path` has written so far (the sink flushes every
/// line): lets a test's fake peer go silent at a point of the run, however late it started.
inline int frames_written(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  int frames = 0;
  while (std::getline(in, line)) frames += line.find("\"type\":\"frame\"") != std::string::npos ? 1 : 0;
  return frames;
}

struct ToolRun {
  nlohmann::json header, summary;
  std::map<int64_t, nlohmann::json> frames;  ///< by frame index (a paced run may drop some)
};

inline ToolRun run_tool(const std::string& config, const std::string& extra, const std::string& name) {
  const std::string out = cli_out_path(name);
  std::remove(out.c_str());
  const std::string command =
      std::string(HRCSENSE_CLI) + " run --config " + config + " " + extra + " --out " + out + " 2>/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  ToolRun run;
  std::ifstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    nlohmann::json j = nlohmann::json::parse(line);
    if (j.at("type") == "header") run.header = j;
    if (j.at("type") == "summary") run.summary = j;
    if (j.at("type") == "frame") run.frames[j.at("frame").get<int64_t>()] = j;
  }
  std::remove(out.c_str());
  return run;
}

/// `live` ran kCliCell with a live robot state that flowed from the start and fell silent once
/// the run had written kSilentAfterFrames frames. Checks, against `fixed` (the same cell with
/// `robot.state.source: fixed` at kCliJoints, every frame processed):
/// - while the state flowed, every frame with a contact has the fixed run's contact and
///   verdict, on the joints that were sent;
/// - from the first frame without a usable state after that, every frame is `stop`, for a
///   stale or missing state, to the end of the run.
inline constexpr int kSilentAfterFrames = 30;
inline void expect_follows_then_stops(const ToolRun& live, const ToolRun& fixed) {
  ASSERT_EQ(fixed.frames.size(), 75U);
  ASSERT_FALSE(live.frames.empty());
  int with_contact = 0, silent = 0;
  bool seen_valid = false;
  for (const auto& [index, frame] : live.frames) {
    const std::string reason = frame.at("reason_code").get<std::string>();
    const bool no_state = reason == "robot_state_stale" || reason == "no_robot_state";
    if (silent > 0 || (seen_valid && no_state)) {
      ++silent;
      EXPECT_TRUE(no_state) << index << ": " << reason;
      EXPECT_EQ(frame.at("verdict"), "stop") << index;
      continue;
    }
    seen_valid = seen_valid || frame.at("valid").get<bool>();
    if (!frame.at("valid").get<bool>() || frame.at("distance_m").is_null()) continue;
    ++with_contact;
    const nlohmann::json& expected = fixed.frames.at(index);
    ASSERT_FALSE(expected.at("distance_m").is_null()) << index;
    EXPECT_NEAR(frame.at("distance_m").get<double>(), expected.at("distance_m").get<double>(), 1e-5) << index;
    EXPECT_EQ(frame.at("verdict"), expected.at("verdict")) << index;
    for (size_t j = 0; j < 6; ++j) {
      EXPECT_NEAR(frame.at("joints_rad").at(j).get<double>(), kCliJoints[j], 1e-9) << index;
    }
  }
  EXPECT_GE(with_contact, 5) << "the box should be seen while the state flows";
  // 75 frames at 30 fps, silent after 30: well over a second of silence, against max_age_s 0.05.
  EXPECT_GE(silent, 10) << "the frames after the state fell silent should stop";
}

}  // namespace hrcsense::test
