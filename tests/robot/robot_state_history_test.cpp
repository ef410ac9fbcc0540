// SPDX-License-Identifier: Apache-2.0
// The robot state history: interpolation, extrapolation for one sample period, staleness,
// rejected samples; and the sender-to-host clock map. Values worked by hand.
#include "hrcsense/robot_state_history.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hrcsense {
namespace {

constexpr int64_t kMs = 1'000'000;

// Joint 1 at q1 rad moving at qd1 rad/s, the others at rest, at t_ms on the host clock.
RobotState sample(int64_t t_ms, double q1, double qd1 = 0.0) {
  RobotState s;
  s.host_time_ns = t_ms * kMs;
  s.q_rad[0] = q1;
  s.qd_rad_s[0] = qd1;
  s.valid = true;
  s.origin = RobotStateOrigin::rtde;
  return s;
}

TEST(RobotStateHistory, NoSampleIsNoRobotState) {
  RobotStateHistory history;
  const RobotStateLookup lookup = history.at(5 * kMs);
  EXPECT_FALSE(lookup.state.valid);
  EXPECT_EQ(lookup.code, ReasonCode::no_robot_state);
}

// Samples at 0, 8 and 16 ms (125 Hz), q1 = 0, 0.008, 0.016 (1 rad/s). At 12 ms: halfway
// between 0.008 and 0.016 → 0.012.
TEST(RobotStateHistory, InterpolatesBetweenBracketingSamples) {
  RobotStateHistory history;
  ASSERT_TRUE(history.add(sample(0, 0.000, 1.0)));
  ASSERT_TRUE(history.add(sample(8, 0.008, 1.0)));
  ASSERT_TRUE(history.add(sample(16, 0.016, 1.0)));
  const RobotStateLookup lookup = history.at(12 * kMs);
  ASSERT_TRUE(lookup.state.valid);
  EXPECT_EQ(lookup.code, ReasonCode::clear);
  EXPECT_NEAR(lookup.state.q_rad[0], 0.012, 1e-12);
  EXPECT_NEAR(lookup.state.qd_rad_s[0], 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(lookup.age_ms, 0.0);  // the frame is older than the newest sample
  EXPECT_FALSE(lookup.extrapolated);
  EXPECT_EQ(lookup.state.host_time_ns, 12 * kMs);
  EXPECT_EQ(lookup.state.origin, RobotStateOrigin::rtde);
  // Exactly on a sample: that sample.
  EXPECT_NEAR(history.at(8 * kMs).state.q_rad[0], 0.008, 1e-12);
}

// Past the newest sample (16 ms, q1 0.016 at 1 rad/s, period 8 ms): at 20 ms q1 = 0.016 + 0.004;
// at 40 ms the extrapolation stops after one period: 0.016 + 0.008, age 24 ms (not stale at 50).
TEST(RobotStateHistory, ExtrapolatesForAtMostOnePeriod) {
  RobotStateHistory history;
  ASSERT_TRUE(history.add(sample(8, 0.008, 1.0)));
  ASSERT_TRUE(history.add(sample(16, 0.016, 1.0)));
  RobotStateLookup lookup = history.at(20 * kMs);
  ASSERT_TRUE(lookup.state.valid);
  EXPECT_NEAR(lookup.state.q_rad[0], 0.020, 1e-12);
  EXPECT_TRUE(lookup.extrapolated);
  EXPECT_DOUBLE_EQ(lookup.age_ms, 4.0);
  lookup = history.at(40 * kMs);
  ASSERT_TRUE(lookup.state.valid);
  EXPECT_NEAR(lookup.state.q_rad[0], 0.024, 1e-12);
  EXPECT_DOUBLE_EQ(lookup.age_ms, 24.0);
}

TEST(RobotStateHistory, StaleBeyondMaxAge) {
  RobotStateHistory history;  // max_age_s 0.05
  history.add(sample(100, 0.5));
  EXPECT_TRUE(history.at(150 * kMs).state.valid);  // exactly 50 ms: still allowed
  const RobotStateLookup lookup = history.at(151 * kMs);
  EXPECT_FALSE(lookup.state.valid);
  EXPECT_EQ(lookup.code, ReasonCode::robot_state_stale);
  EXPECT_DOUBLE_EQ(lookup.age_ms, 51.0);
}

TEST(RobotStateHistory, BeforeTheOldestSampleGivesTheOldest) {
  RobotStateHistory history;
  history.add(sample(10, 0.3));
  history.add(sample(18, 0.3));
  EXPECT_NEAR(history.at(2 * kMs).state.q_rad[0], 0.3, 1e-12);
}

// Rejected: NaN, a timestamp not after the previous one, and a jump. At 1 rad/s over 8 ms a
// joint may move 0.008 + 0.05 (tolerance) = 0.058 rad: 0.05 is accepted, 0.07 rejected.
TEST(RobotStateHistory, RejectsAndCountsBadSamples) {
  RobotStateHistory history;
  ASSERT_TRUE(history.add(sample(0, 0.0, 1.0)));
  RobotState nan = sample(8, 0.0);
  nan.q_rad[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(history.add(nan));
  RobotState inf = sample(8, 0.0);
  inf.qd_rad_s[5] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(history.add(inf));
  EXPECT_FALSE(history.add(sample(0, 0.0)));   // same time
  EXPECT_FALSE(history.add(sample(-8, 0.0)));  // earlier
  EXPECT_FALSE(history.add(sample(8, 0.07, 1.0)));
  EXPECT_TRUE(history.add(sample(8, 0.05, 1.0)));
  const RobotStateCounts& counts = history.counts();
  EXPECT_EQ(counts.accepted, 2);
  EXPECT_EQ(counts.rejected_non_finite, 2);
  EXPECT_EQ(counts.rejected_backwards, 2);
  EXPECT_EQ(counts.rejected_jump, 1);
  EXPECT_EQ(counts.rejected(), 5);
  EXPECT_EQ(history.size(), 2U);
}

// A UR5's joints are limited to ±360° = ±2π rad (its datasheet). 171.9° sent as radians,
// 1e300 and a value just past the limit are no pose of it: rejected, counted apart from the
// other rejections, the joint named by number and name with its value. The limit itself is in.
TEST(RobotStateHistory, RejectsAJointOutsideTheArmsLimits) {
  constexpr double kTwoPi = 6.283185307179586;
  RobotStateHistory history;
  history.params.q_min_rad.fill(-kTwoPi);
  history.params.q_max_rad.fill(kTwoPi);
  RobotState degrees = sample(0, 0.0);
  degrees.q_rad[1] = 171.9;
  EXPECT_FALSE(history.add(degrees));
  EXPECT_NE(history.last_rejection().find("joint 2 (shoulder_lift) 171.9 rad"), std::string::npos)
      << history.last_rejection();
  EXPECT_NE(history.last_rejection().find("-6.283..6.283 rad"), std::string::npos) << history.last_rejection();
  RobotState huge = sample(0, 0.0);
  huge.q_rad[5] = 1e300;
  EXPECT_FALSE(history.add(huge));
  EXPECT_NE(history.last_rejection().find("joint 6 (wrist_3) 1e+300 rad"), std::string::npos)
      << history.last_rejection();
  RobotState just_past = sample(0, -kTwoPi - 1e-9);
  EXPECT_FALSE(history.add(just_past));
  EXPECT_EQ(history.counts().rejected_limits, 3);
  EXPECT_EQ(history.counts().rejected(), 3);
  EXPECT_EQ(history.size(), 0U);
  EXPECT_EQ(history.at(0).code, ReasonCode::no_robot_state);

  EXPECT_TRUE(history.add(sample(0, kTwoPi)));
  EXPECT_EQ(history.counts().accepted, 1);
}

// Without limits set (no arm known) every finite value is taken: the limits are the arm's, and
// a run sets them from robot.arm.
TEST(RobotStateHistory, WithoutAnArmNoLimitApplies) {
  RobotStateHistory history;
  EXPECT_TRUE(history.add(sample(0, 1e300)));
  EXPECT_EQ(history.counts().rejected_limits, 0);
}

// After a gap longer than max_age_s (a reconnect) the arm may be anywhere: the new sample
// starts the history afresh instead of being rejected as a jump.
TEST(RobotStateHistory, AGapStartsAfresh) {
  RobotStateHistory history;
  history.add(sample(0, 0.0));
  history.add(sample(8, 0.0));
  ASSERT_TRUE(history.add(sample(500, 2.0)));
  EXPECT_EQ(history.size(), 1U);
  EXPECT_NEAR(history.at(500 * kMs).state.q_rad[0], 2.0, 1e-12);
  EXPECT_EQ(history.counts().rejected_jump, 0);
}

TEST(RobotStateHistory, KeepsTheNewestCapacitySamples) {
  RobotStateHistory history;
  const int n = static_cast<int>(RobotStateHistory::kCapacity) + 10;
  for (int i = 0; i < n; ++i) ASSERT_TRUE(history.add(sample(i, 0.0)));
  EXPECT_EQ(history.size(), RobotStateHistory::kCapacity);
  EXPECT_EQ(history.newest().host_time_ns, (n - 1) * kMs);
}

// The listener hears each accepted sample once, in order, as it is accepted (the history already
// holds it), and never a rejected one: of 0 ms (q 0), NaN at 8, a jump to 0.07 at 8 (more than
// 1 rad/s · 8 ms + 0.05), 0.05 at 8, a step back to 4, 0.1 after a gap at 500 ms, and a joint
// outside ±2π, the listener hears 0, 0.05 and 0.1 ms with their values and speed fractions.
TEST(RobotStateHistory, TheListenerHearsEachAcceptedSampleOnceInOrder) {
  struct Heard {
    int64_t t_ns;
    double q1;
    double speed_fraction;
    size_t size_then;  // the history's size when the listener ran
  };
  RobotStateHistory history;
  history.params.q_min_rad.fill(-6.3);
  history.params.q_max_rad.fill(6.3);
  std::vector<Heard> heard;
  history.listener = [&](const RobotState& s) {
    EXPECT_TRUE(s.valid);
    heard.push_back({s.host_time_ns, s.q_rad[0], s.speed_fraction, history.size()});
  };
  RobotState first = sample(0, 0.0, 1.0);
  first.speed_fraction = 0.25;
  RobotState nan = sample(8, 0.0, 1.0);
  nan.q_rad[2] = std::numeric_limits<double>::quiet_NaN();
  RobotState outside = sample(520, 0.1, 1.0);
  outside.q_rad[4] = 7.0;
  EXPECT_TRUE(history.add(first));
  EXPECT_FALSE(history.add(nan));
  EXPECT_FALSE(history.add(sample(8, 0.07, 1.0)));
  EXPECT_TRUE(history.add(sample(8, 0.05, 1.0)));   // speed fraction NaN: the source says none
  EXPECT_FALSE(history.add(sample(4, 0.05, 1.0)));
  EXPECT_TRUE(history.add(sample(500, 0.1, 1.0)));  // after a gap: the history starts afresh
  EXPECT_FALSE(history.add(outside));
  history.clear();

  ASSERT_EQ(heard.size(), 3U);
  EXPECT_EQ(heard[0].t_ns, 0);
  EXPECT_EQ(heard[0].q1, 0.0);
  EXPECT_EQ(heard[0].speed_fraction, 0.25);
  EXPECT_EQ(heard[0].size_then, 1U);
  EXPECT_EQ(heard[1].t_ns, 8 * kMs);
  EXPECT_EQ(heard[1].q1, 0.05);
  EXPECT_TRUE(std::isnan(heard[1].speed_fraction));
  EXPECT_EQ(heard[1].size_then, 2U);
  EXPECT_EQ(heard[2].t_ns, 500 * kMs);
  EXPECT_EQ(heard[2].q1, 0.1);
  EXPECT_EQ(heard[2].size_then, 1U);
  EXPECT_EQ(history.counts().accepted, 3);
  EXPECT_EQ(history.counts().rejected(), 4);

  // An empty listener tells nobody.
  history.listener = nullptr;
  EXPECT_TRUE(history.add(sample(600, 0.1)));
  EXPECT_EQ(heard.size(), 3U);
}

// The sender's clock runs 1000 s behind the host's; messages arrive after 3, 1 and 2 ms of
// transport: the offset is the smallest, 1000 s + 1 ms, so later messages map to sent + that
// (never later than their arrival).
TEST(SenderClockMap, UsesTheLeastDelayedMessage) {
  constexpr int64_t kS = 1'000'000'000;
  SenderClockMap map(5 * kS);
  EXPECT_EQ(map.to_host(10 * kS, 1010 * kS + 3 * kMs), 1010 * kS + 3 * kMs);
  EXPECT_EQ(map.to_host(11 * kS, 1011 * kS + 1 * kMs), 1011 * kS + 1 * kMs);
  EXPECT_EQ(map.to_host(12 * kS, 1012 * kS + 2 * kMs), 1012 * kS + 1 * kMs);
  // Two windows later the early minimum has aged out: only the last blocks count.
  EXPECT_EQ(map.to_host(18 * kS, 1018 * kS + 4 * kMs), 1018 * kS + 1 * kMs);  // new block; previous min 1 ms
  EXPECT_EQ(map.to_host(24 * kS, 1024 * kS + 5 * kMs), 1024 * kS + 4 * kMs);  // previous block's min 4 ms
  // The sender restarted (its clock went back): the map starts again.
  EXPECT_EQ(map.to_host(1 * kS, 1030 * kS), 1030 * kS);
}

}  // namespace
}  // namespace hrcsense
