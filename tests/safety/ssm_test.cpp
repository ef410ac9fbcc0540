// SPDX-License-Identifier: Apache-2.0
// The protective separation distance, its terms and the speed scale against values worked by
// hand (docs/SAFETY.md's formula): a fixed and a moving robot, both human speeds, with and
// without a deceleration; every part of T_r, a stopping table, stopping limits, the robot
// state's age in Z_r, and the stop when the present speed leaves no room.

#include "hrcsense/ssm.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hrcsense {
namespace {

// The defaults: v_h 1.6 m/s (2.0 within 0.5 m), controller latency 0.05 s, stopping time
// 0.5 s without a deceleration, d = 40 mm (C = 8·(40 − 14) = 208 mm), Z_r 0.01 m; the
// receiver's timeout is 0 unless a case sets it (no frame period or source latency either).
// Every case has a frame age of 0.03 s (T_r = 0.08 s) and Z_d 0.02 m.
SsmParams defaults() {
  SsmParams params;
  params.receiver_timeout_s = 0.0;
  return params;
}

SsmInput input(float distance_m, float robot_speed_mps) {
  SsmInput in;
  in.distance_m = distance_m;
  in.frame_age_s = 0.03;
  in.robot_speed_mps = robot_speed_mps;
  in.distance_uncertainty_m = 0.02F;
  return in;
}

TEST(Ssm, FixedRobotFar) {
  const SsmParams params = defaults();
  const SsmTerms t = protective_distance(params, input(2.0F, 0.0F), 0.0F);
  EXPECT_NEAR(t.reaction_time_s, 0.08, 1e-12);
  EXPECT_NEAR(t.stop_time_s, 0.5, 1e-12);    // applies at zero speed too
  EXPECT_NEAR(t.s_h_m, 1.6 * 0.58, 1e-6);    // 0.928
  EXPECT_EQ(t.s_r_m, 0.0F);
  EXPECT_EQ(t.s_s_m, 0.0F);
  EXPECT_NEAR(t.c_m, 0.208, 1e-6);
  EXPECT_NEAR(t.z_d_m, 0.02, 1e-7);
  EXPECT_NEAR(t.z_r_m, 0.01, 1e-7);
  EXPECT_NEAR(t.protective_distance_m, 1.166, 1e-5);
  EXPECT_EQ(ssm_speed_scale(params, input(2.0F, 0.0F)), 1.0F);
  // Just below S_p at rest: nothing the robot's speed can do, a stop.
  EXPECT_EQ(ssm_speed_scale(params, input(1.16F, 0.0F)), 0.0F);
  EXPECT_LT(allowed_robot_speed_mps(params, input(1.16F, 0.0F)), 0.0);
}

TEST(Ssm, WithinHalfAMetreThePersonIsFaster) {
  const SsmParams params = defaults();
  const SsmTerms t = protective_distance(params, input(0.4F, 0.0F), 0.0F);
  EXPECT_NEAR(t.s_h_m, 2.0 * 0.58, 1e-6);  // 1.16
  EXPECT_NEAR(t.protective_distance_m, 1.16 + 0.208 + 0.02 + 0.01, 1e-5);
  EXPECT_EQ(ssm_speed_scale(params, input(0.4F, 0.0F)), 0.0F);
  // At exactly 0.5 m the near speed still holds; just beyond it the walking speed.
  EXPECT_NEAR(protective_distance(params, input(0.5F, 0.0F), 0.0F).s_h_m, 1.16, 1e-6);
  EXPECT_NEAR(protective_distance(params, input(0.5001F, 0.0F), 0.0F).s_h_m, 0.928, 1e-6);
}

TEST(Ssm, MovingRobotWithoutDeceleration) {
  const SsmParams params = defaults();
  // v_r 0.5 m/s: S_r = 0.5·0.08 = 0.04, S_s = 0.5·0.5/2 = 0.125; S_p = 1.166 + 0.165 = 1.331.
  const SsmTerms t = protective_distance(params, input(2.0F, 0.5F), 0.5F);
  EXPECT_NEAR(t.s_r_m, 0.04, 1e-6);
  EXPECT_NEAR(t.s_s_m, 0.125, 1e-6);
  EXPECT_NEAR(t.protective_distance_m, 1.331, 1e-5);
  EXPECT_EQ(ssm_speed_scale(params, input(2.0F, 0.5F)), 1.0F);
  // S_p(v) = 1.166 + v·(T_r + T_s/2) = 1.166 + 0.33·v: at 2 m, v up to 0.834 / 0.33.
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(2.0F, 0.5F)), 0.834 / 0.33, 1e-5);
  // v_r 1 m/s at 1.3 m: S_p(1) = 1.496 > 1.3. The old rule slowed to 0.134 / 0.33 = 0.40606
  // m/s; the robot keeps 1 m/s for T_r and no braking is shorter than its stop: none fits.
  EXPECT_LT(allowed_robot_speed_mps(params, input(1.3F, 1.0F)), 0.0);
  EXPECT_EQ(ssm_speed_scale(params, input(1.3F, 1.0F)), 0.0F);
  EXPECT_NEAR(protective_distance(params, input(1.3F, 1.0F), 1.0F).protective_distance_m, 1.496, 1e-5);
  // At 0.4 m/s S_p = 1.298 ≤ 1.3: it may go on, up to 0.134 / 0.33 m/s.
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(1.3F, 0.4F)), 0.134 / 0.33, 1e-5);
  EXPECT_EQ(ssm_speed_scale(params, input(1.3F, 0.4F)), 1.0F);
}

TEST(Ssm, MovingRobotWithDeceleration) {
  SsmParams params = defaults();
  params.robot_decel_mps2 = 2.0F;
  params.robot_stop_time_s = 0.1;  // before braking starts
  // v_r 1 m/s: T_s = 0.1 + 1/2 = 0.6, S_h = 1.6·(0.08 + 0.6) = 1.088, S_r = 0.08,
  // S_s = 1·0.1 + 1²/(2·2) = 0.35; S_p = 1.088 + 0.08 + 0.35 + 0.208 + 0.02 + 0.01 = 1.756.
  const SsmTerms t = protective_distance(params, input(1.5F, 1.0F), 1.0F);
  EXPECT_NEAR(t.stop_time_s, 0.6, 1e-9);
  EXPECT_NEAR(t.s_h_m, 1.088, 1e-6);
  EXPECT_NEAR(t.s_r_m, 0.08, 1e-6);
  EXPECT_NEAR(t.s_s_m, 0.35, 1e-6);
  EXPECT_NEAR(t.protective_distance_m, 1.756, 1e-5);
  // S_p(v) = 0.526 + 0.98·v + 0.25·v² = 1.5: v = (−0.98 + √(0.98² + 0.974)) / 0.5 = 0.821654.
  // At 1 m/s now the robot is inside S_p(1) = 1.756: a stop. At 0.5 m/s now (S_p 1.0785) it
  // may go up to v, and at 0.9 m/s (S_p 1.6282) it may not.
  const double v = (-0.98 + std::sqrt(0.98 * 0.98 + 0.974)) / 0.5;
  EXPECT_LT(allowed_robot_speed_mps(params, input(1.5F, 1.0F)), 0.0);
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(1.5F, 0.5F)), v, 1e-5);
  EXPECT_EQ(ssm_speed_scale(params, input(1.5F, 0.5F)), 1.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(1.5F, 0.9F)), 0.0F);
  EXPECT_NEAR(protective_distance(params, input(1.5F, 1.0F), static_cast<float>(v)).protective_distance_m, 1.5, 1e-5);
  // At rest the brake delay still counts: S_p(0) = 1.6·0.18 + 0.238 = 0.526.
  EXPECT_NEAR(protective_distance(params, input(1.5F, 0.0F), 0.0F).protective_distance_m, 0.526, 1e-5);
}

TEST(Ssm, DetectionCapabilityBelow14mmGivesNoIntrusionDistance) {
  SsmParams params = defaults();
  params.detection_mm = 10.0F;
  EXPECT_EQ(protective_distance(params, input(2.0F, 0.0F), 0.0F).c_m, 0.0F);
  params.detection_mm = 40.0F;  // the formula's last value: 8·26 mm
  EXPECT_NEAR(protective_distance(params, input(2.0F, 0.0F), 0.0F).c_m, 0.208, 1e-6);
  params.detection_mm = 70.0F;  // coarser than 40 mm: an arm reaches through, ISO 13855's 850 mm
  EXPECT_NEAR(protective_distance(params, input(2.0F, 0.0F), 0.0F).c_m, 0.85, 1e-6);
}

TEST(Ssm, MovingAwayCountsAsStandingStill) {
  const SsmParams params = defaults();
  EXPECT_EQ(protective_distance(params, input(2.0F, -0.7F), -0.7F).s_r_m, 0.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(2.0F, -0.7F)), 1.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(1.0F, -0.7F)), 0.0F);  // too close even at rest
}

// ---- S2's terms, each against values worked by hand.

// T_r = frame age + one nominal frame period + the camera's latency before its stamp + the
// controller's latency + the receiver's silence timeout: 0.03 + 1/30 + 0.033 + 0.05 + 0.2 =
// 0.3463333 s. At rest S_p = 1.6·(0.3463333 + 0.5) + 0.208 + 0.02 + 0.01 = 1.5921333 m.
TEST(Ssm, ReactionTimeHasEveryLatency) {
  SsmParams params;  // the receiver's default timeout, 0.2 s
  params.frame_period_s = 1.0 / 30.0;
  params.source_latency_s = 0.033;
  const SsmTerms t = protective_distance(params, input(2.0F, 0.0F), 0.0F);
  EXPECT_NEAR(t.frame_age_s, 0.03, 1e-12);
  EXPECT_NEAR(t.frame_period_s, 0.0333333, 1e-7);
  EXPECT_NEAR(t.source_latency_s, 0.033, 1e-12);
  EXPECT_NEAR(t.controller_latency_s, 0.05, 1e-12);
  EXPECT_NEAR(t.receiver_timeout_s, 0.2, 1e-12);
  EXPECT_NEAR(t.reaction_time_s, 0.3463333, 1e-7);
  EXPECT_NEAR(t.s_h_m, 1.6 * 0.8463333, 1e-6);
  EXPECT_NEAR(t.protective_distance_m, 1.5921333, 1e-5);
  // Each part costs v_h · part at rest: the receiver's 0.2 s alone 0.32 m at 1.6 m/s.
  SsmParams without_receiver = params;
  without_receiver.receiver_timeout_s = 0.0;
  EXPECT_NEAR(t.protective_distance_m - protective_distance(without_receiver, input(2.0F, 0.0F), 0.0F).protective_distance_m,
              0.32, 1e-5);
}

// A table (speed → distance, time), linear between rows: 0.5 m/s → 0.10 m in 0.30 s,
// 1.0 → 0.30 m in 0.45 s, 1.5 → 0.60 m in 0.60 s.
SsmParams with_table() {
  SsmParams params = defaults();
  params.stopping_table = {{0.5F, 0.10F, 0.30}, {1.0F, 0.30F, 0.45}, {1.5F, 0.60F, 0.60}};
  params.stopping_data = StoppingData::table;
  return params;
}

TEST(Ssm, StoppingTableIsReadBetweenAndBeyondItsRows) {
  const SsmParams params = with_table();
  // At rest: no distance, the first row's time (the person walks while even a slow robot stops).
  EXPECT_NEAR(robot_stop(params, 0.0).distance_m, 0.0, 1e-12);
  EXPECT_NEAR(robot_stop(params, 0.0).time_s, 0.30, 1e-12);
  EXPECT_NEAR(robot_stop(params, 0.25).distance_m, 0.05, 1e-7);  // half the first row's distance
  EXPECT_NEAR(robot_stop(params, 0.25).time_s, 0.30, 1e-12);
  EXPECT_NEAR(robot_stop(params, 0.75).distance_m, 0.20, 1e-7);  // between rows 1 and 2
  EXPECT_NEAR(robot_stop(params, 0.75).time_s, 0.375, 1e-7);
  EXPECT_NEAR(robot_stop(params, 1.0).distance_m, 0.30, 1e-7);   // on a row
  // Beyond the last row, at its deceleration: 0.6·(2/1.5)² = 1.0666667 m in 0.6·2/1.5 = 0.8 s.
  EXPECT_NEAR(robot_stop(params, 2.0).distance_m, 1.0666667, 1e-6);
  EXPECT_NEAR(robot_stop(params, 2.0).time_s, 0.8, 1e-7);
  // S_p at 0.75 m/s: 1.6·(0.08 + 0.375) + 0.75·0.08 + 0.20 + 0.238 = 1.226 m.
  const SsmTerms t = protective_distance(params, input(2.0F, 0.75F), 0.75F);
  EXPECT_NEAR(t.stop_time_s, 0.375, 1e-7);
  EXPECT_NEAR(t.s_s_m, 0.20, 1e-6);
  EXPECT_NEAR(t.protective_distance_m, 1.226, 1e-5);
  // The allowed speed at 1.5 m, from 0.5 m/s now: between 1.0 and 1.5 m/s S_p(v) = 1.466 +
  // 1.16·(v − 1) (S_p(1) = 1.6·0.53 + 0.08 + 0.30 + 0.238), so v = 1 + 0.034 / 1.16.
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(1.5F, 0.5F)), 1.0 + 0.034 / 1.16, 1e-6);
}

// The robot's own stopping limits (its safety configuration): the same distance and time at
// any speed. S_p(v) = 1.6·(0.08 + 0.6) + 0.08·v + 0.4 + 0.238 = 1.726 + 0.08·v.
TEST(Ssm, StoppingLimitsHoldAtAnySpeed) {
  SsmParams params = defaults();
  params.stopping_limit_distance_m = 0.4F;
  params.stopping_limit_time_s = 0.6;
  params.stopping_data = StoppingData::limits;
  EXPECT_NEAR(protective_distance(params, input(3.0F, 0.0F), 0.0F).protective_distance_m, 1.726, 1e-5);
  EXPECT_NEAR(protective_distance(params, input(3.0F, 1.0F), 1.0F).protective_distance_m, 1.806, 1e-5);
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(1.75F, 0.1F)), 0.024 / 0.08, 1e-6);
  EXPECT_STREQ(stopping_data_name(params.stopping_data), "limits");
}

// The robot state 30 ms older than the frame, of which extrapolation covered 10 ms: the arm may
// have moved 3 m/s · 0.02 s = 0.06 m unseen, so Z_r = 0.01 + 0.06 = 0.07 m.
TEST(Ssm, RobotStateAgeBeyondExtrapolationWidensZr) {
  const SsmParams params = defaults();
  SsmInput in = input(2.0F, 0.0F);
  in.robot_state_gap_s = 0.02;
  const SsmTerms t = protective_distance(params, in, 0.0F);
  EXPECT_NEAR(t.z_r_state_m, 0.06, 1e-6);
  EXPECT_NEAR(t.z_r_m, 0.07, 1e-6);
  EXPECT_NEAR(t.protective_distance_m, 1.166 + 0.06, 1e-5);
}

// The scale's look-ahead, one frame period (1/30 s): T_r = 0.08 + 1/30 = 0.1133333 s, so
// S_p(v) = 1.6·(0.1133333 + 0.5) + 0.238 + v·(0.1133333 + 0.25) = 1.2193333 + 0.3633333·v. At
// 2 m the allowed speed is (2 − 1.2193333) / 0.3633333 = 2.1486239 m/s; the planned speed also
// leaves the next frame room for the person's (1.6 m/s) and the robot's approach over 1/30 s:
// 1.2193333 + 0.0533333 + (0.3633333 + 0.0333333)·v = 2, v = 1.8336134 m/s. A robot at 2 m/s
// (S_p(2) = 1.946 m ≤ 2 m: no stop) is slowed to 1.8336134 / 2 = 0.9168067.
TEST(Ssm, ThePlannedSpeedLeavesTheNextFrameRoom) {
  SsmParams params = defaults();
  params.frame_period_s = 1.0 / 30.0;
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(2.0F, 0.5F)), 2.1486239, 1e-6);
  EXPECT_NEAR(planned_robot_speed_mps(params, input(2.0F, 0.5F)), 1.8336134, 1e-6);
  EXPECT_NEAR(ssm_speed_scale(params, input(2.0F, 2.0F)), 0.9168067, 1e-6);
  // At 1.25 m a standing robot is outside S_p(0) = 1.2193 m, but not with the look-ahead's
  // 0.0533 m: the planned speed is 0. It stands, so its scale stays 1 (a scale of its present
  // speed, 0, means nothing); a robot at 0.05 m/s (S_p 1.2375 m) is slowed to 0.
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(1.25F, 0.0F)), (1.25 - 1.2193333) / 0.3633333, 1e-5);
  EXPECT_EQ(planned_robot_speed_mps(params, input(1.25F, 0.0F)), 0.0);
  EXPECT_EQ(ssm_speed_scale(params, input(1.25F, 0.0F)), 1.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(1.25F, 0.05F)), 0.0F);
  // The same by bisection over a table that is the closed form (0.25·v m in 0.5 s).
  SsmParams table = params;
  table.stopping_table = {{1.0F, 0.25F, 0.5}, {4.0F, 1.0F, 0.5}};
  EXPECT_NEAR(planned_robot_speed_mps(table, input(2.0F, 0.5F)), 1.8336134, 1e-5);
}

// Some v_a ≥ 0 fits exactly when the distance is at least S_p at the present speed: just
// above it the robot may keep (at least) its speed, just below it nothing does.
TEST(Ssm, NoSpeedFitsBelowTheProtectiveDistanceAtThePresentSpeed) {
  const SsmParams params = defaults();
  for (const float v_r : {0.0F, 0.3F, 0.8F, 1.5F}) {
    const float at_present = 1.166F + 0.33F * v_r;  // S_p(v_r) = 1.166 + v_r·(T_r + T_s/2)
    EXPECT_GE(allowed_robot_speed_mps(params, input(at_present + 1e-3F, v_r)), v_r) << v_r;
    EXPECT_LT(allowed_robot_speed_mps(params, input(at_present - 1e-3F, v_r)), 0.0) << v_r;
    EXPECT_EQ(ssm_speed_scale(params, input(at_present - 1e-3F, v_r)), 0.0F) << v_r;
  }
}

TEST(Ssm, NanIsNeverASpeed) {
  const SsmParams params = defaults();
  EXPECT_EQ(ssm_speed_scale(params, input(std::nanf(""), 0.5F)), 0.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(2.0F, std::nanf(""))), 0.0F);
  SsmInput age = input(2.0F, 0.5F);
  age.frame_age_s = std::nan("");
  EXPECT_EQ(ssm_speed_scale(params, age), 0.0F);
  EXPECT_TRUE(std::isnan(protective_distance(params, age, 0.5F).protective_distance_m));
}

}  // namespace
}  // namespace hrcsense
