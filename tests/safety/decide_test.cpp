// SPDX-License-Identifier: Apache-2.0
// The verdict of a processed frame (decide_verdict) in ssm mode, the unknown-space policy, the
// hold (VerdictHold) and Z_d of a contact, against values worked by hand.

#include "hrcsense/safety.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hrcsense {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The ssm defaults (v_h 1.6 m/s, 2.0 within 0.5 m; controller latency 0.05 s; T_s 0.5 s, no
// deceleration; C = 8·(40 − 14) mm = 0.208 m; Z_r 0.01 m), no hold. Each frame is 0.05 s old
// (T_r = 0.1 s) with Z_d 0.02 m. S_p at rest, farther than 0.5 m:
// 1.6·(0.1 + 0.5) + 0.208 + 0.02 + 0.01 = 1.198 m. A robot moving towards the person at v
// adds v·T_r + v·T_s/2 = 0.35·v. The receiver's timeout, a part of T_r of its own, is 0 here
// (its table test is in ssm_test.cpp).
SafetyParams ssm_params() {
  SafetyParams p;
  p.mode = SafetyParams::Mode::ssm;
  p.ssm.receiver_timeout_s = 0.0;
  return p;
}

VerdictInput frame(float distance_m, float robot_speed_mps) {
  VerdictInput in;
  in.contact.valid = true;
  in.contact.distance_m = distance_m;
  in.contact.closest_base = {1.0F, 0.0F, 0.0F};
  in.contact.closest_robot_base = {0.0F, 0.0F, 0.0F};
  in.foreground_points = 100;
  in.distance_uncertainty_m = 0.02F;
  in.robot_speed_towards_mps = robot_speed_mps;
  in.frame_age_s = 0.05;
  return in;
}

TEST(DecideVerdict, SsmStandingRobotRunsBeyondTheProtectiveDistanceAtRest) {
  const Decision d = decide_verdict(ssm_params(), frame(1.2F, 0.0F));
  EXPECT_EQ(d.verdict.state, VerdictState::run);
  EXPECT_EQ(d.verdict.code, ReasonCode::clear);
  EXPECT_EQ(d.verdict.speed_scale, 1.0F);
  ASSERT_TRUE(d.ssm.has_value());
  EXPECT_NEAR(d.ssm->protective_distance_m, 1.198, 1e-5);
  EXPECT_NEAR(d.verdict.protective_distance_m, 1.198, 1e-5);
  EXPECT_NEAR(d.ssm->s_h_m, 0.96, 1e-6);
  EXPECT_EQ(d.ssm->s_r_m, 0.0F);
}

TEST(DecideVerdict, SsmStopsBelowTheProtectiveDistanceAtRest) {
  const Decision d = decide_verdict(ssm_params(), frame(1.19F, 0.0F));
  EXPECT_EQ(d.verdict.state, VerdictState::stop);
  EXPECT_EQ(d.verdict.code, ReasonCode::below_protective_distance);
  EXPECT_EQ(d.verdict.speed_scale, 0.0F);
  // Within 0.5 m the faster hand speed counts: 2.0·0.6 + 0.238 = 1.438 m.
  const Decision near = decide_verdict(ssm_params(), frame(0.4F, 0.0F));
  EXPECT_EQ(near.verdict.state, VerdictState::stop);
  EXPECT_NEAR(near.ssm->protective_distance_m, 1.438, 1e-5);
}

TEST(DecideVerdict, SsmMovingRobotStopsBelowTheProtectiveDistanceAtItsPresentSpeed) {
  // At 1.373 m a robot at 1 m/s towards the person: S_p(1) = 1.198 + 0.35 = 1.548 m. The old
  // rule slowed it to (1.373 − 1.198) / 0.35 = 0.5 m/s; but it keeps 1 m/s for T_r, and braking
  // to 0.5 m/s then stopping is no shorter than stopping from 1 m/s: a stop.
  const Decision d = decide_verdict(ssm_params(), frame(1.373F, 1.0F));
  EXPECT_EQ(d.verdict.state, VerdictState::stop);
  EXPECT_EQ(d.verdict.code, ReasonCode::below_protective_distance);
  // The terms are at the present speed: S_r = 1·0.1, S_s = 1·0.5/2; S_p = 1.548 m.
  EXPECT_NEAR(d.ssm->s_r_m, 0.1, 1e-6);
  EXPECT_NEAR(d.ssm->s_s_m, 0.25, 1e-6);
  EXPECT_NEAR(d.verdict.protective_distance_m, 1.548, 1e-5);
  // Far enough for the full speed: 1.198 + 0.35 = 1.548 m.
  EXPECT_EQ(decide_verdict(ssm_params(), frame(1.55F, 1.0F)).verdict.state, VerdictState::run);
  // Moving away counts as standing still.
  EXPECT_EQ(decide_verdict(ssm_params(), frame(1.2F, -1.0F)).verdict.state, VerdictState::run);
}

TEST(DecideVerdict, SsmScaleIsOfTheProgrammedSpeed) {
  // At 1.3765 m the robot may approach at up to (1.3765 − 1.198) / 0.35 = 0.51 m/s. It moves at
  // 0.5 m/s now (S_p(0.5) = 1.373 m: it may go on), but at half its programmed speed
  // (speed_scaling 0.5: a slider set earlier): programmed 1 m/s, so the scale is 0.51 of the
  // programmed speed, not the 1.0 the present speed alone would give.
  VerdictInput in = frame(1.3765F, 0.5F);
  EXPECT_EQ(decide_verdict(ssm_params(), in).verdict.state, VerdictState::run);  // scaling unknown
  in.robot_speed_scaling = 0.5;
  const Decision d = decide_verdict(ssm_params(), in);
  EXPECT_EQ(d.verdict.state, VerdictState::slow);
  EXPECT_NEAR(d.verdict.speed_scale, 0.51, 1e-4);
  // Far enough for the programmed speed too (1.198 + 0.35·1.0 = 1.548 m): run.
  in.contact.distance_m = 1.56F;
  EXPECT_EQ(decide_verdict(ssm_params(), in).verdict.state, VerdictState::run);
  // Nearer than S_p at the present speed (1.373 m): no scale helps, a stop.
  in.contact.distance_m = 1.37F;
  EXPECT_EQ(decide_verdict(ssm_params(), in).verdict.code, ReasonCode::below_protective_distance);
}

TEST(DecideVerdict, SsmUnknownSpeedOrUncertaintyStops) {
  EXPECT_EQ(decide_verdict(ssm_params(), frame(3.0F, kNaN)).verdict.code, ReasonCode::non_finite_input);
  VerdictInput in = frame(3.0F, 0.0F);
  in.distance_uncertainty_m = kNaN;
  EXPECT_EQ(decide_verdict(ssm_params(), in).verdict.state, VerdictState::stop);
}

TEST(DecideVerdict, SsmKeepsTheContactChecks) {
  VerdictInput none = frame(0.0F, 0.0F);
  none.contact.valid = false;
  none.foreground_points = 0;
  const Decision empty = decide_verdict(ssm_params(), none);
  EXPECT_EQ(empty.verdict.state, VerdictState::run);
  EXPECT_EQ(empty.verdict.code, ReasonCode::no_foreground);
  EXPECT_FALSE(empty.ssm.has_value());
  VerdictInput inside = frame(0.0F, 0.0F);
  inside.contact.inside = true;
  const Decision in = decide_verdict(ssm_params(), inside);
  EXPECT_EQ(in.verdict.state, VerdictState::stop);
  EXPECT_EQ(in.verdict.code, ReasonCode::inside_robot);
  // Compared against S_p of a person at 0 m (2.0·0.6 + 0.238 = 1.438 m), not a zone's distance.
  EXPECT_NEAR(in.verdict.protective_distance_m, 1.438, 1e-5);
  ASSERT_TRUE(in.ssm.has_value());
  EXPECT_NEAR(in.ssm->protective_distance_m, 1.438, 1e-5);
}

TEST(DecideVerdict, ZonesModeIsTheThesisRule) {
  const Decision d = decide_verdict(SafetyParams{}, frame(0.7F, 1.0F));
  EXPECT_EQ(d.verdict.state, VerdictState::slow);
  EXPECT_NEAR(d.verdict.speed_scale, 0.4, 1e-6);  // (0.7 − 0.5) / (1.0 − 0.5)
  EXPECT_FALSE(d.ssm.has_value());
}

TEST(DecideVerdict, UnknownSpaceStopsWithinItsDistanceUnderThePolicy) {
  SafetyParams p = ssm_params();
  VerdictInput in = frame(3.0F, 0.0F);
  in.unknown_distance_m = 0.2F;
  EXPECT_EQ(decide_verdict(p, in).verdict.state, VerdictState::run);  // report: only reported
  p.unknown_policy = SafetyParams::UnknownPolicy::stop_within_m;
  p.unknown_stop_within_m = 0.3F;
  EXPECT_EQ(decide_verdict(p, in).verdict.code, ReasonCode::unknown_space);
  in.unknown_distance_m = 0.4F;
  EXPECT_EQ(decide_verdict(p, in).verdict.state, VerdictState::run);
  in.unknown_distance_m = kNaN;  // none known
  EXPECT_EQ(decide_verdict(p, in).verdict.state, VerdictState::run);
}

// unknown_margin_m = unknown distance − S_p of the verdict (ssm) or the stop distance (zones).
// A standing robot, a person at 3 m: S_p = 1.198 m. Unknown space 1.5 m from the robot: margin
// 0.302 m, so stop_within_protective runs; at 1.1 m the margin is −0.098 m: a stop. The same
// unknown space at 0.2 m is beyond stop_within_m's 0.1 m: stop_within_m would run there.
TEST(DecideVerdict, UnknownSpaceAgainstTheProtectiveDistance) {
  SafetyParams p = ssm_params();
  VerdictInput in = frame(3.0F, 0.0F);
  in.unknown_distance_m = 1.5F;
  Decision d = decide_verdict(p, in);
  EXPECT_EQ(d.verdict.state, VerdictState::run);  // report: only reported
  EXPECT_NEAR(d.unknown_margin_m, 0.302, 1e-5);
  p.unknown_policy = SafetyParams::UnknownPolicy::stop_within_protective;
  EXPECT_EQ(decide_verdict(p, in).verdict.state, VerdictState::run);
  in.unknown_distance_m = 1.1F;
  d = decide_verdict(p, in);
  EXPECT_NEAR(d.unknown_margin_m, -0.098, 1e-5);
  EXPECT_EQ(d.verdict.state, VerdictState::stop);
  EXPECT_EQ(d.verdict.code, ReasonCode::unknown_space);
  EXPECT_NEAR(d.verdict.protective_distance_m, 1.198, 1e-5);  // the stop keeps the S_p it was judged by
  // A robot moving at 1 m/s towards the contact at 3 m: S_p = 1.548 m; the same 1.5 m of
  // unknown space is now within it.
  VerdictInput moving = frame(3.0F, 1.0F);
  moving.unknown_distance_m = 1.5F;
  d = decide_verdict(p, moving);
  EXPECT_NEAR(d.unknown_margin_m, -0.048, 1e-5);
  EXPECT_EQ(d.verdict.code, ReasonCode::unknown_space);
  // With the hysteresis as the margin (VerdictHold's test): 1.6 m (margin 0.052 m) clears
  // 0.05 m, 1.59 m (0.042 m) does not.
  moving.unknown_distance_m = 1.6F;
  EXPECT_EQ(decide_verdict(p, moving, 0.05F).verdict.code, ReasonCode::clear);
  moving.unknown_distance_m = 1.59F;  // margin 0.042 m < 0.05 m
  EXPECT_EQ(decide_verdict(p, moving, 0.05F).verdict.code, ReasonCode::unknown_space);
  // No unknown space: no margin, no stop.
  moving.unknown_distance_m = kNaN;
  d = decide_verdict(p, moving);
  EXPECT_TRUE(std::isnan(d.unknown_margin_m));
  EXPECT_EQ(d.verdict.state, VerdictState::run);
  // Nobody in the cell: S_p at rest for a person at walking speed (1.198 m with Z_d 0: 1.178 m).
  VerdictInput empty = frame(0.0F, 0.0F);
  empty.contact.valid = false;
  empty.foreground_points = 0;
  empty.unknown_distance_m = 1.0F;
  d = decide_verdict(p, empty);
  EXPECT_NEAR(d.unknown_margin_m, 1.0 - 1.178, 1e-5);
  EXPECT_EQ(d.verdict.code, ReasonCode::unknown_space);
  // Zones mode: against the stop distance, 0.5 m.
  SafetyParams zones;
  zones.unknown_policy = SafetyParams::UnknownPolicy::stop_within_protective;
  VerdictInput far = frame(3.0F, 0.0F);
  far.unknown_distance_m = 0.45F;
  d = decide_verdict(zones, far);
  EXPECT_NEAR(d.unknown_margin_m, -0.05, 1e-6);
  EXPECT_EQ(d.verdict.code, ReasonCode::unknown_space);
}

// Zones mode (stop 0.5 m, slow 1.0 m) with a hysteresis of 0.05 m and a hold of 0.5 s; one
// frame at each time, the hold's verdict checked against the sequence worked by hand.
TEST(VerdictHold, RelaxesOnlyAfterTheHoldAndBeyondTheHysteresis) {
  SafetyParams p;
  p.hysteresis_m = 0.05F;
  p.min_hold_s = 0.5;
  VerdictHold hold;
  const auto step = [&](double t_s, float distance_m) {
    const VerdictInput in = frame(distance_m, 0.0F);
    Decision d = decide_verdict(p, in);
    hold.apply(p, in, static_cast<int64_t>(t_s * 1e9), d);
    return d.verdict;
  };
  EXPECT_EQ(step(0.0, 0.4F).state, VerdictState::stop);
  Verdict v = step(0.1, 0.6F);  // the frame says slow, 0.1 s after the stop: held
  EXPECT_EQ(v.state, VerdictState::stop);
  EXPECT_EQ(v.code, ReasonCode::holding);
  EXPECT_EQ(step(0.6, 0.52F).state, VerdictState::stop);  // held long enough, but 0.52 − 0.05 < 0.5
  v = step(0.7, 0.56F);  // 0.51 clears the stop distance: slow at the frame's own scale
  EXPECT_EQ(v.state, VerdictState::slow);
  EXPECT_EQ(v.code, ReasonCode::in_slow_zone);
  EXPECT_NEAR(v.speed_scale, 0.12, 1e-5);
  v = step(0.8, 1.2F);  // run asked 0.1 s after relaxing to slow: slow held at its scale
  EXPECT_EQ(v.state, VerdictState::slow);
  EXPECT_EQ(v.code, ReasonCode::holding);
  EXPECT_NEAR(v.speed_scale, 0.12, 1e-5);
  EXPECT_EQ(step(1.3, 1.2F).state, VerdictState::run);  // 0.6 s of slow, 1.15 clears 1.0
  EXPECT_EQ(step(1.4, 0.3F).state, VerdictState::stop);  // stricter: at once
}

TEST(VerdictHold, ReliefGoesOnlyAsFarAsTheHysteresisAllows) {
  SafetyParams p;
  p.hysteresis_m = 0.05F;
  p.min_hold_s = 0.0;
  VerdictHold hold;
  VerdictInput in = frame(0.4F, 0.0F);
  Decision d = decide_verdict(p, in);
  hold.apply(p, in, 0, d);
  // From stop, a frame at 1.02 m says run; less the hysteresis (0.97 m) it is slow, so slow
  // at the scale of 0.97 m: (0.97 − 0.5) / 0.5 = 0.94.
  in = frame(1.02F, 0.0F);
  d = decide_verdict(p, in);
  hold.apply(p, in, 100'000'000, d);
  EXPECT_EQ(d.verdict.state, VerdictState::slow);
  EXPECT_EQ(d.verdict.code, ReasonCode::holding);
  EXPECT_NEAR(d.verdict.speed_scale, 0.94, 1e-5);
}

TEST(ContactUncertainty, NoiseFootprintAndLagAddUp) {
  const SsmParams params;
  ContactUncertaintyInput in;
  in.depth_m = 2.0F;
  in.noise_per_z2 = 0.08F / (424.0F * 0.05F);  // a D435 at 848x480 decimated by 2: fx 424 px, B 50 mm
  in.fx_px = 424.0F;
  in.filter_lag_s = 0.05;  // α 0.4 at 30 frames/s: 1.5 frames
  in.contact_speed_mps = 0.3F;
  // 2·σ_z = 2·4·0.08/21.2 = 0.030189 m; footprint √2/2·2/424 = 0.003335 m; lag 0.05·0.3 = 0.015 m.
  EXPECT_NEAR(contact_uncertainty_m(params, in), 0.030189 + 0.003335 + 0.015, 1e-5);
  in.contact_speed_mps = 5.0F;  // capped at the faster human speed, 2.0 m/s
  EXPECT_NEAR(contact_uncertainty_m(params, in), 0.030189 + 0.003335 + 0.1, 1e-5);
  in.contact_speed_mps = kNaN;  // unknown: the cap too
  EXPECT_NEAR(contact_uncertainty_m(params, in), 0.030189 + 0.003335 + 0.1, 1e-5);
  in.depth_m = kNaN;
  EXPECT_TRUE(std::isnan(contact_uncertainty_m(params, in)));
}

}  // namespace
}  // namespace hrcsense
