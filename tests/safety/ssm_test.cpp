// SPDX-License-Identifier: Apache-2.0
// The protective separation distance, its terms and the speed scale against values worked by
// hand (docs/SAFETY.md's formula): a fixed and a moving robot, both human speeds, with and
// without a deceleration.

#include "hrcsense/ssm.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hrcsense {
namespace {

// The defaults: v_h 1.6 m/s (2.0 within 0.5 m), controller latency 0.05 s, stopping time
// 0.5 s without a deceleration, d = 40 mm (C = 8·(40 − 14) = 208 mm), Z_r 0.01 m. Every case
// has a frame age of 0.03 s (T_r = 0.08 s) and Z_d 0.02 m.
SsmInput input(float distance_m, float robot_speed_mps) {
  SsmInput in;
  in.distance_m = distance_m;
  in.frame_age_s = 0.03;
  in.robot_speed_mps = robot_speed_mps;
  in.distance_uncertainty_m = 0.02F;
  return in;
}

TEST(Ssm, FixedRobotFar) {
  const SsmParams params;
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
  const SsmParams params;
  const SsmTerms t = protective_distance(params, input(0.4F, 0.0F), 0.0F);
  EXPECT_NEAR(t.s_h_m, 2.0 * 0.58, 1e-6);  // 1.16
  EXPECT_NEAR(t.protective_distance_m, 1.16 + 0.208 + 0.02 + 0.01, 1e-5);
  EXPECT_EQ(ssm_speed_scale(params, input(0.4F, 0.0F)), 0.0F);
  // At exactly 0.5 m the near speed still holds; just beyond it the walking speed.
  EXPECT_NEAR(protective_distance(params, input(0.5F, 0.0F), 0.0F).s_h_m, 1.16, 1e-6);
  EXPECT_NEAR(protective_distance(params, input(0.5001F, 0.0F), 0.0F).s_h_m, 0.928, 1e-6);
}

TEST(Ssm, MovingRobotWithoutDeceleration) {
  const SsmParams params;
  // v_r 0.5 m/s: S_r = 0.5·0.08 = 0.04, S_s = 0.5·0.5/2 = 0.125; S_p = 1.166 + 0.165 = 1.331.
  const SsmTerms t = protective_distance(params, input(2.0F, 0.5F), 0.5F);
  EXPECT_NEAR(t.s_r_m, 0.04, 1e-6);
  EXPECT_NEAR(t.s_s_m, 0.125, 1e-6);
  EXPECT_NEAR(t.protective_distance_m, 1.331, 1e-5);
  EXPECT_EQ(ssm_speed_scale(params, input(2.0F, 0.5F)), 1.0F);
  // S_p(v) = 1.166 + v·(T_r + T_s/2) = 1.166 + 0.33·v: at 2 m, v up to 0.834 / 0.33.
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(2.0F, 0.5F)), 0.834 / 0.33, 1e-5);
  // v_r 1 m/s at 1.3 m: S_p(1) = 1.496 > 1.3, so slow to 0.134 / 0.33 = 0.40606 m/s.
  EXPECT_NEAR(ssm_speed_scale(params, input(1.3F, 1.0F)), 0.134 / 0.33, 1e-5);
  EXPECT_NEAR(protective_distance(params, input(1.3F, 1.0F), 1.0F).protective_distance_m, 1.496, 1e-5);
}

TEST(Ssm, MovingRobotWithDeceleration) {
  SsmParams params;
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
  const double v = (-0.98 + std::sqrt(0.98 * 0.98 + 0.974)) / 0.5;
  EXPECT_NEAR(allowed_robot_speed_mps(params, input(1.5F, 1.0F)), v, 1e-5);
  EXPECT_NEAR(ssm_speed_scale(params, input(1.5F, 1.0F)), v, 1e-5);
  EXPECT_NEAR(protective_distance(params, input(1.5F, 1.0F), static_cast<float>(v)).protective_distance_m, 1.5, 1e-5);
  // At rest the brake delay still counts: S_p(0) = 1.6·0.18 + 0.238 = 0.526.
  EXPECT_NEAR(protective_distance(params, input(1.5F, 0.0F), 0.0F).protective_distance_m, 0.526, 1e-5);
}

TEST(Ssm, DetectionCapabilityBelow14mmGivesNoIntrusionDistance) {
  SsmParams params;
  params.detection_mm = 10.0F;
  EXPECT_EQ(protective_distance(params, input(2.0F, 0.0F), 0.0F).c_m, 0.0F);
  params.detection_mm = 40.0F;  // the formula's last value: 8·26 mm
  EXPECT_NEAR(protective_distance(params, input(2.0F, 0.0F), 0.0F).c_m, 0.208, 1e-6);
  params.detection_mm = 70.0F;  // coarser than 40 mm: an arm reaches through, ISO 13855's 850 mm
  EXPECT_NEAR(protective_distance(params, input(2.0F, 0.0F), 0.0F).c_m, 0.85, 1e-6);
}

TEST(Ssm, MovingAwayCountsAsStandingStill) {
  const SsmParams params;
  EXPECT_EQ(protective_distance(params, input(2.0F, -0.7F), -0.7F).s_r_m, 0.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(2.0F, -0.7F)), 1.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(1.0F, -0.7F)), 0.0F);  // too close even at rest
}

TEST(Ssm, NanIsNeverASpeed) {
  const SsmParams params;
  EXPECT_EQ(ssm_speed_scale(params, input(std::nanf(""), 0.5F)), 0.0F);
  EXPECT_EQ(ssm_speed_scale(params, input(2.0F, std::nanf(""))), 0.0F);
  SsmInput age = input(2.0F, 0.5F);
  age.frame_age_s = std::nan("");
  EXPECT_EQ(ssm_speed_scale(params, age), 0.0F);
  EXPECT_TRUE(std::isnan(protective_distance(params, age, 0.5F).protective_distance_m));
}

}  // namespace
}  // namespace hrcsense
