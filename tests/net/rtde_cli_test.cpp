// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` with `robot.state.source: rtde`, end to end: the tool runs as a child process
// and reads the joints from the fake controller (tests/net/fake_rtde_controller.hpp) in this
// process, on 127.0.0.1 and an ephemeral port, streaming in real time on the steady clock. The
// expectations come from the same cell run with `robot.state.source: fixed` at the same joints
// (tests/net/cli_cell.hpp), and from the fake's schedule: it goes silent after a second,
// keeping the connection open.

#include "cli_cell.hpp"
#include "fake_rtde_controller.hpp"

#include "hrcsense/clock.hpp"

#include <gtest/gtest.h>

#include <cstdio>
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
  const ToolRun fixed = run_tool(config, "--set source.pace=false", "fixed");
  ASSERT_EQ(fixed.frames.size(), 60U);

  SteadyClock steady;
  FakeRtdeScript script;
  script.samples_per_connection = 125;  // 1 s at 125 Hz, then silent with the connection open
  script.joints = [](double, JointAngles& q, JointAngles& qd) {
    q = kCliJoints;
    qd = JointAngles{};
  };
  FakeRtdeController fake(script, steady);
  fake.start([](int64_t) {});
  const ToolRun live = run_tool(config,
                            "--set robot.state.source=rtde --set robot.state.host=127.0.0.1 --set robot.state.port=" +
                                std::to_string(fake.port()),
                            "rtde");
  fake.stop();
  std::remove(config.c_str());

  EXPECT_EQ(live.header.at("robot_state"), "rtde");
  ASSERT_FALSE(live.frames.empty());
  EXPECT_EQ(fake.frequencies(), std::vector<double>{125.0});
  const nlohmann::json& robot = live.summary.at("robot_state");
  EXPECT_EQ(robot.at("connections"), 1);
  EXPECT_EQ(robot.at("accepted"), 125);
  EXPECT_EQ(robot.at("malformed"), 0);

  // While the controller streams: every frame with a contact has the fixed run's contact, on
  // the joints the controller sent.
  int with_contact = 0;
  for (const auto& [index, frame] : live.frames) {
    if (!frame.at("valid").template get<bool>() || frame.at("distance_m").is_null()) continue;
    ++with_contact;
    const nlohmann::json& expected = fixed.frames.at(index);
    ASSERT_FALSE(expected.at("distance_m").is_null()) << index;
    EXPECT_NEAR(frame.at("distance_m").get<double>(), expected.at("distance_m").get<double>(), 1e-5) << index;
    EXPECT_EQ(frame.at("verdict"), expected.at("verdict")) << index;
    for (size_t j = 0; j < 6; ++j) EXPECT_NEAR(frame.at("joints_rad").at(j).get<double>(), kCliJoints[j], 1e-9) << index;
  }
  EXPECT_GE(with_contact, 5) << "the box should be seen while the controller streams";

  // Silent for the last ~0.8 s of the 2 s run: the last frames are stale, none says `run`.
  const nlohmann::json& last = live.frames.rbegin()->second;
  EXPECT_EQ(last.at("reason_code"), "robot_state_stale");
  EXPECT_EQ(last.at("verdict"), "stop");
  for (const auto& [index, frame] : live.frames) {
    if (frame.at("reason_code") == "robot_state_stale") {
      EXPECT_EQ(frame.at("verdict"), "stop") << index;
    }
  }
}

}  // namespace
}  // namespace hrcsense
