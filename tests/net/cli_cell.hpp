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

namespace hrcsense::test {

// A noise-free cell: the UR5 of config/cell-ur5.yaml at its fixed pose, a floor, and a box that
// appears beside the arm at frame 15, after the 10 learning frames; 60 frames, paced (2 s).
// Noise-free, the learnt background and every contact are the same whichever frames were
// learnt from or dropped, so a run with a live state can be compared frame by frame with
// `robot.state.source: fixed` at the same joints.
inline constexpr const char* kCliCell = R"(source: {type: sim, seed: 1, pace: true}
sim: {width: 848, height: 480, fps: 30, frames: 60, noise: false, color: false}
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
inline std::string write_cli_cell(const std::string& name) {
  const std::string path = std::string(::testing::TempDir()) + "cli_cell_" + name + ".yaml";
  std::ofstream(path) << kCliCell;
  return path;
}

struct ToolRun {
  nlohmann::json header, summary;
  std::map<int64_t, nlohmann::json> frames;  ///< by frame index (a paced run may drop some)
};

inline ToolRun run_tool(const std::string& config, const std::string& extra, const std::string& name) {
  const std::string out = std::string(::testing::TempDir()) + "cli_" + name + ".jsonl";
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

}  // namespace hrcsense::test
