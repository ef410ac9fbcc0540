// SPDX-License-Identifier: Apache-2.0
// Tests of SimRobotState (robot.state.source: sim): exact on the simulator's timeline, late
// by the latency with a seeded jitter, stale beyond robot.state.max_age_s.
#include "../support/scenes.hpp"
#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

using test::scene_path;

/// Joint 1 from 0 to 1 rad over 10 s (0.1 rad/s), the others at rest at 0.3 rad.
RobotTrajectory ramp() {
  RobotTrajectory t;
  t.waypoints.push_back({0.0, {0.0, 0.3, 0.3, 0.3, 0.3, 0.3}});
  t.waypoints.push_back({10.0, {1.0, 0.3, 0.3, 0.3, 0.3, 0.3}});
  return t;
}

TEST(SimRobotState, WithoutLatencyGivesTheTrajectoryAtTheFramesTimestamp) {
  const Config config = load_config(scene_path("cell-ur5-moving.yaml"), {"sim.noise=false", "sim.color=false"});
  Simulator sim = make_simulator(config);
  std::unique_ptr<RobotStateSource> states = make_robot_state_source(config);
  ASSERT_EQ(states->origin(), RobotStateOrigin::sim);
  Frame frame;
  for (const int64_t index : {0, 7, 31, 100, 433}) {
    sim.render(index, frame);
    RobotState state;
    ASSERT_TRUE(states->state_at(frame.timestamp_ns, state));
    const TrajectorySample expected = joints_at(*config.robot_state.trajectory, static_cast<double>(index) / 30.0);
    EXPECT_TRUE(state.valid);
    EXPECT_EQ(state.origin, RobotStateOrigin::sim);
    EXPECT_EQ(state.host_time_ns, frame.timestamp_ns);
    for (size_t j = 0; j < 6; ++j) {
      EXPECT_NEAR(state.q_rad[j], expected.q_rad[j], 1e-9) << index;
      EXPECT_NEAR(state.qd_rad_s[j], expected.qd_rad_s[j], 1e-9) << index;
    }
  }
}

TEST(SimRobotState, LatencyMakesTheStateLag) {
  SimRobotState::Params params;
  params.latency_s = 0.03;  // 500 Hz samples; max_age 0.05 s
  SimRobotState states(ramp(), params);
  RobotState state;
  // At 5 s the newest known sample holds 4.970 s (known at 5.000 s); the history moves it on
  // with its velocity for one period (2 ms): 0.1 rad/s · 4.972 s.
  ASSERT_TRUE(states.state_at(5'000'000'000, state));
  EXPECT_EQ(state.origin, RobotStateOrigin::sim);
  EXPECT_EQ(state.host_time_ns, 5'000'000'000);
  EXPECT_NEAR(state.q_rad[0], 0.4972, 1e-9);
  EXPECT_NEAR(state.qd_rad_s[0], 0.1, 1e-12);
  EXPECT_NEAR(state.q_rad[1], 0.3, 1e-12);
  // Frame by frame at 30 fps: always behind the truth by latency minus one period.
  for (int64_t i = 151; i < 200; ++i) {
    const int64_t t_ns = i * 1'000'000'000 / 30;
    ASSERT_TRUE(states.state_at(t_ns, state)) << i;
    const double truth = 0.1 * static_cast<double>(t_ns) * 1e-9;
    EXPECT_LE(state.q_rad[0], truth - 0.1 * 0.028 + 1e-9) << i;
    EXPECT_GE(state.q_rad[0], truth - 0.1 * 0.030 - 1e-9) << i;
  }
}

TEST(SimRobotState, LatencyBeyondMaxAgeIsStale) {
  SimRobotState::Params params;
  params.latency_s = 0.08;
  params.history.max_age_s = 0.05;
  SimRobotState states(ramp(), params);
  RobotState state;
  EXPECT_FALSE(states.state_at(2'000'000'000, state));
  EXPECT_FALSE(state.valid);
  // Before the first sample is known: no state at all.
  SimRobotState early(ramp(), params);
  EXPECT_FALSE(early.state_at(10'000'000, state));
}

TEST(SimRobotState, JitterIsSeededAndBounded) {
  SimRobotState::Params params;
  params.latency_s = 0.01;
  params.jitter_s = 0.02;
  params.seed = 7;
  SimRobotState a(ramp(), params);
  SimRobotState b(ramp(), params);
  params.seed = 8;
  SimRobotState c(ramp(), params);
  int differ = 0;
  for (int64_t i = 30; i < 90; ++i) {
    const int64_t t_ns = i * 1'000'000'000 / 30;
    RobotState sa, sb, sc;
    ASSERT_TRUE(a.state_at(t_ns, sa));
    ASSERT_TRUE(b.state_at(t_ns, sb));
    ASSERT_TRUE(c.state_at(t_ns, sc));
    EXPECT_EQ(sa.q_rad[0], sb.q_rad[0]) << i;
    differ += sa.q_rad[0] != sc.q_rad[0] ? 1 : 0;
    // Known at latency plus [0, jitter), then moved on by at most one period (2 ms).
    const double truth = 0.1 * static_cast<double>(t_ns) * 1e-9;
    EXPECT_LE(sa.q_rad[0], truth - 0.1 * (0.01 - 0.002) + 1e-9) << i;
    EXPECT_GE(sa.q_rad[0], truth - 0.1 * (0.03 + 0.002) - 1e-9) << i;
  }
  EXPECT_GT(differ, 10);
  EXPECT_EQ(a.stats().samples.rejected(), 0);
  EXPECT_GT(a.stats().samples.accepted, 100);
}

}  // namespace
}  // namespace hrcsense
