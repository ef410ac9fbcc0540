// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` with `robot.state.source: rtde`, end to end: the tool runs as a child process
// and reads the joints from the fake controller (tests/net/fake_rtde_controller.hpp) in this
// process, on 127.0.0.1 and an ephemeral port, streaming in real time on the steady clock. The
// expectations come from the same cell run with `robot.state.source: fixed` at the same joints
// (tests/net/cli_cell.hpp), and from the fake's schedule: it goes silent,
// keeping the connection open, once the run has written 30 frames (then the client's receive
// timeout drops the connection and its reconnects find no answer).

#include "cli_cell.hpp"
#include "fake_rtde_controller.hpp"

#include "hrcsense/clock.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::FakeRtdeController;
using test::FakeRtdeScript;
using test::kCliJoints;
using test::run_tool;
using test::ToolRun;

TEST(RtdeCli, RunFollowsTheControllerAndStopsWhenItFallsSilent) {
  const std::string config = test::write_cli_cell("rtde");

  // The oracle: the same cell with the joints fixed, every frame processed.
  const ToolRun fixed = run_tool(config, "--set source.pace=false", "rtde_fixed");

  SteadyClock steady;
  FakeRtdeScript script;
  script.samples_per_connection = 125 * 20;  // more than the run lasts
  script.joints = [](double, JointAngles& q, JointAngles& qd) {
    q = kCliJoints;
    qd = JointAngles{};
  };
  FakeRtdeController fake(script, steady);
  // After each package: once the run has written kSilentAfterFrames frames, stall with the
  // connection open until the run is over (bounded: 20 s).
  std::atomic<bool> run_over{false};
  const std::string out = test::cli_out_path("rtde");
  fake.start([&](int64_t) {
    if (test::frames_written(out) < test::kSilentAfterFrames) return;
    for (int i = 0; i < 4000 && !run_over; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  });
  const ToolRun live = run_tool(config,
                                "--set robot.state.source=rtde --set robot.state.host=127.0.0.1 --set robot.state.port=" +
                                    std::to_string(fake.port()),
                                "rtde");
  run_over = true;
  fake.stop();
  std::remove(config.c_str());

  EXPECT_EQ(live.header.at("robot_state"), "rtde");
  for (const double hz : fake.frequencies()) EXPECT_EQ(hz, 125.0);
  const nlohmann::json& robot = live.summary.at("robot_state");
  EXPECT_GE(robot.at("connections").get<int64_t>(), 1);
  EXPECT_GE(robot.at("accepted").get<int64_t>(), test::kSilentAfterFrames);  // 125 Hz against 30 fps
  EXPECT_EQ(robot.at("malformed"), 0);
  test::expect_follows_then_stops(live, fixed);
}

}  // namespace
}  // namespace hrcsense
