// SPDX-License-Identifier: Apache-2.0
// A cell with two simulated cameras on loopback DDS (docs/MULTICAMERA.md): `hrcsense cell` runs
// both and the fuser and ends with them; a camera process killed is a fused stop naming it
// (camera_stale), and the same camera started again (a new session) brings the cell back to run
// without restarting the fuser. The scene is small (424x240, a bare UR5 at work, nobody in the
// cell) so that both cameras keep their rate on two cores; under the sanitizers they cannot (each
// process is several times slower), and the tests skip there: the fusion's code runs under them in
// test_safety's CellFusion tests and in the fuzz target. Every wait is bounded.
#include "../support/child_process.hpp"
#include "../support/sanitized.hpp"
#include "dds_test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <chrono>
#include <memory>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using nlohmann::json;
using test::ChildProcess;

// Two cameras of the moving UR5 cell, 424x240 at 30 frames/s; the arm swings 0.6 rad and back in
// 1 s, so that the 30 learning frames see a whole cycle.
constexpr const char* kTwoCameraCell = R"(
source: {type: sim, seed: 1}
sim: {width: 424, height: 240, fps: 30, frames: 100000, noise: true, color: false}
camera:
  T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-125, 0, 90]}
cameras:
  - name: front
    T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-125, 0, 90]}
    fps: 30
  - name: left
    T_base_camera: {translation_m: [0.3, 2.2, 1.5], rotation_rpy_deg: [-124.3, 0, 180]}
    fps: 30
    source: {seed: 2}
scene:
  objects:
    - name: floor
      static: true
      shapes:
        - plane: {point: [0, 0, -0.75], normal: [0, 0, 1]}
    - name: table
      static: true
      shapes:
        - box: {min: [-0.4, -0.7, -0.05], max: [1.0, 0.7, 0.0]}
background: {frames: 30}
filters: {preset: sdk, spatial: {magnitude: 1}, temporal: {persistence: 0}}
robot:
  model: ur5
  padding_m: 0.05
  state: {source: sim}
  trajectory:
    interpolation: linear
    loop: true
    waypoints:
      - {t_s: 0.0, joints_rad: [-2.741593, -1.0, 1.6, -2.1708, -1.5708, 0.0]}
      - {t_s: 0.5, joints_rad: [-3.341593, -1.0, 1.6, -2.1708, -1.5708, 0.0]}
      - {t_s: 1.0, joints_rad: [-2.741593, -1.0, 1.6, -2.1708, -1.5708, 0.0]}
safety: {mode: zones}
)";

struct Cell {
  std::filesystem::path dir;
  std::string config;
  std::string domain_set;
};

Cell make_cell(const std::string& name) {
  Cell cell;
  cell.dir = std::filesystem::temp_directory_path() / ("hrcsense_multicamera_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(cell.dir);
  cell.config = (cell.dir / "cell.yaml").string();
  std::ofstream(cell.config) << kTwoCameraCell;
  cell.domain_set = "ros2.domain_id=" + std::to_string(test::test_domain());
  return cell;
}

// The exit code of a wait status (ChildProcess::wait), -1 for a child killed or signalled.
int exit_code(int status) { return status >= 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1; }

std::vector<json> read_lines(const std::filesystem::path& path) {
  std::vector<json> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
  return lines;
}

std::string epoch_in(double seconds) {
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  char text[64];
  std::snprintf(text, sizeof text, "sim.epoch=%.6f", static_cast<double>(now.tv_sec) + now.tv_nsec * 1e-9 + seconds);
  return text;
}

TEST(MultiCameraCell, TheCellCommandRunsBothCamerasAndTheFuserAndEndsWithThem) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  if (test::kSanitized) GTEST_SKIP() << "two cameras at 30 frames/s and a fuser cannot keep their rate under the sanitizers";
  const Cell cell = make_cell("cell");
  const std::string out = (cell.dir / "fused.jsonl").string();
  ChildProcess run({HRCSENSE_CLI, "cell", "--config", cell.config, "--set", cell.domain_set, "--frames", "120", "--out", out});
  EXPECT_EQ(exit_code(run.wait(60.0)), 0);
  const std::vector<json> lines = read_lines(out);
  ASSERT_GE(lines.size(), 3U);
  const json& header = lines.front();
  ASSERT_EQ(header["cameras"].size(), 2U);
  EXPECT_EQ(header["cameras"][0]["name"], "front");
  EXPECT_EQ(header["cameras"][1]["name"], "left");
  EXPECT_EQ(header["cameras"][1]["intrinsics"]["width"], 424);
  int run_frames = 0;
  for (const json& line : lines) {
    if (line["type"] != "frame") continue;
    ASSERT_EQ(line["cameras"].size(), 2U);
    if (line["verdict"] == "run") ++run_frames;
  }
  // 120 frames each, 30 learning: many of the last 90 instants fuse to run (nobody in the cell;
  // the others are slow for the stereo noise near the arm).
  EXPECT_GE(run_frames, 20) << out;
  const json& summary = lines.back();
  ASSERT_EQ(summary["type"], "summary");
  EXPECT_EQ(summary["end_reason_code"], "source_ended");
  ASSERT_EQ(summary["cameras"].size(), 2U);
  EXPECT_GE(summary["cameras"][1]["accepted"].get<int>(), 90);
  EXPECT_EQ(summary["cameras"][1]["out_of_order"], 0);
  EXPECT_EQ(summary["cameras"][1]["malformed"], 0);
  // Each camera's own run beside the fused output: what it alone would have decided.
  for (const char* camera : {"front", "left"}) {
    const std::vector<json> own = read_lines(cell.dir / (std::string("fused.") + camera + ".jsonl"));
    ASSERT_GE(own.size(), 120U) << camera;
    EXPECT_EQ(own.front()["type"], "header");
  }
  std::filesystem::remove_all(cell.dir);
}

// Reads the fuser's lines until `wanted` holds for one, at most `timeout_s`; that line.
template <typename Wanted>
json next_line_where(ChildProcess& fuser, double timeout_s, Wanted wanted) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::string text;
  while (std::chrono::steady_clock::now() < deadline) {
    const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
    if (!fuser.read_line(text, left)) break;
    json line = json::parse(text);
    if (line["type"] == "frame" && wanted(line)) return line;
  }
  return json();
}

TEST(MultiCameraCell, AKilledCameraStopsTheCellByNameAndItsRestartRecoversWithoutTheFuser) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  if (test::kSanitized) GTEST_SKIP() << "two cameras at 30 frames/s and a fuser cannot keep their rate under the sanitizers";
  const Cell cell = make_cell("restart");
  const std::string epoch = epoch_in(1.0);
  ChildProcess fuser({HRCSENSE_CLI, "fuse", "--config", cell.config, "--set", cell.domain_set});
  auto camera = [&](const char* name) {
    return std::make_unique<ChildProcess>(std::vector<std::string>{HRCSENSE_CLI, "run", "--config", cell.config, "--set",
                                                                   cell.domain_set, "--set", epoch, "--camera", name,
                                                                   "--out", "/dev/null"});
  };
  auto front = camera("front");
  auto left = camera("left");
  const auto is_run = [](const json& l) { return l["verdict"] == "run"; };
  ASSERT_FALSE(next_line_where(fuser, 20.0, is_run).is_null()) << "the cell never fused to run";

  // Kill left: within the stale rule's 2 periods (67 ms) and a decision, a stop naming it.
  ::kill(left->pid(), SIGKILL);
  const auto killed = std::chrono::steady_clock::now();
  const json stale = next_line_where(fuser, 5.0, [](const json& l) { return l["reason_code"] == "camera_stale"; });
  ASSERT_FALSE(stale.is_null()) << "no camera_stale after the kill";
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count(), 1.0);
  EXPECT_NE(stale["verdict_reason"].get<std::string>().find("'left'"), std::string::npos) << stale;
  EXPECT_EQ(stale["verdict"], "stop");
  const uint32_t old_session = stale["cameras"][1]["session"];

  // Start it again: a new session, a background to learn (30 frames, 1 s), then run.
  left = camera("left");
  const json back = next_line_where(fuser, 20.0, is_run);
  ASSERT_FALSE(back.is_null()) << "the cell did not recover after the restart";
  EXPECT_NE(back["cameras"][1]["session"].get<uint32_t>(), old_session);
  EXPECT_TRUE(back["cameras"][1]["valid"].get<bool>());

  // The fuser ends on SIGTERM with a stop and its summary, exit 0.
  ::kill(fuser.pid(), SIGTERM);
  std::string text, last, before_last;
  while (fuser.read_line(text, 5.0)) {
    before_last = last;
    last = text;
  }
  EXPECT_EQ(exit_code(fuser.wait(10.0)), 0);
  const json summary = json::parse(last);
  ASSERT_EQ(summary["type"], "summary");
  EXPECT_EQ(summary["end_reason_code"], "stop_requested");
  EXPECT_EQ(summary["cameras"][1]["sessions"], 2);
  EXPECT_EQ(json::parse(before_last)["verdict"], "stop");
  std::filesystem::remove_all(cell.dir);
}

}  // namespace
}  // namespace hrcsense
