// SPDX-License-Identifier: Apache-2.0
// Tests of the run / slow / stop verdict against the thresholds in SafetyParams.

#include "hrcsense/safety.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <set>
#include <utility>
#include <vector>
#include <string>

namespace hrcsense {
namespace {

Contact contact_at(float distance_m) {
  Contact c;
  c.valid = true;
  c.distance_m = distance_m;
  return c;
}

SafetyParams params() {
  SafetyParams p;
  p.slow_distance_m = 1.2F;
  p.stop_distance_m = 0.4F;
  return p;
}

TEST(Verdict, NoContactRuns) {
  const Verdict v = verdict_for_contact(params(), Contact{}, 0);
  EXPECT_EQ(v.state, VerdictState::run);
  EXPECT_EQ(v.speed_scale, 1.0F);
}

TEST(Verdict, ThresholdsAtAndAroundTheBoundaries) {
  const SafetyParams p = params();
  EXPECT_EQ(verdict_for_contact(p, contact_at(5.0F), 1).state, VerdictState::run);
  // At slow_distance_m: "at or beyond" runs.
  EXPECT_EQ(verdict_for_contact(p, contact_at(1.2F), 1).state, VerdictState::run);
  EXPECT_EQ(verdict_for_contact(p, contact_at(1.19F), 1).state, VerdictState::slow);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.41F), 1).state, VerdictState::slow);
  // At stop_distance_m: not below, so still slow (at speed 0).
  const Verdict at_stop = verdict_for_contact(p, contact_at(0.4F), 1);
  EXPECT_EQ(at_stop.state, VerdictState::slow);
  EXPECT_EQ(at_stop.speed_scale, 0.0F);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.39F), 1).state, VerdictState::stop);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.0F), 1).state, VerdictState::stop);
}

TEST(Verdict, SpeedScaleIsLinearInTheSlowZone) {
  const SafetyParams p = params();
  // Span 0.8 m from 0.4 to 1.2: 0.6 m is a quarter of the way, 1.0 m three quarters.
  EXPECT_NEAR(verdict_for_contact(p, contact_at(0.6F), 1).speed_scale, 0.25F, 1e-6F);
  EXPECT_NEAR(verdict_for_contact(p, contact_at(0.8F), 1).speed_scale, 0.5F, 1e-6F);
  EXPECT_NEAR(verdict_for_contact(p, contact_at(1.0F), 1).speed_scale, 0.75F, 1e-6F);
  // Equal steps in distance give equal steps in speed.
  const float s1 = verdict_for_contact(p, contact_at(0.5F), 1).speed_scale;
  const float s2 = verdict_for_contact(p, contact_at(0.7F), 1).speed_scale;
  const float s3 = verdict_for_contact(p, contact_at(0.9F), 1).speed_scale;
  EXPECT_NEAR(s2 - s1, s3 - s2, 1e-6F);
  EXPECT_EQ(verdict_for_contact(p, contact_at(1.5F), 1).speed_scale, 1.0F);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.1F), 1).speed_scale, 0.0F);
}

TEST(Verdict, StopReasonsAreNeverEmpty) {
  const Verdict close = verdict_for_contact(params(), contact_at(0.1F), 1);
  EXPECT_FALSE(close.reason.empty());
  const Verdict stale = stop_verdict(ReasonCode::stale_frame, "stale frame");
  EXPECT_EQ(stale.state, VerdictState::stop);
  EXPECT_EQ(stale.speed_scale, 0.0F);
  EXPECT_EQ(stale.reason, "stale frame");
  EXPECT_EQ(stale.code, ReasonCode::stale_frame);
  EXPECT_EQ(stop_verdict(ReasonCode::no_frame).reason, "no_frame");  // no details: the code's name
}

TEST(Verdict, EqualThresholdsHaveNoSlowZone) {
  SafetyParams p;
  p.slow_distance_m = 0.5F;
  p.stop_distance_m = 0.5F;
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.49F), 1).state, VerdictState::stop);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.5F), 1).state, VerdictState::run);
}

// R1 item 1: foreground that the search could not turn into a contact (non-finite points from
// an overflowed pose, say) must never read as an empty cell.
TEST(Verdict, ForegroundWithoutContactStops) {
  const Verdict v = verdict_for_contact(params(), Contact{}, 86568);
  EXPECT_EQ(v.state, VerdictState::stop);
  EXPECT_EQ(v.speed_scale, 0.0F);
  EXPECT_EQ(v.reason, "no contact");
}

// A NaN distance fails every "<" test; the verdict must still be stop, and so must a distance
// or a point that is infinite or a negative distance.
TEST(Verdict, NonFiniteContactStops) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (float d : {nan, inf, -inf, -0.1F}) {
    EXPECT_EQ(verdict_for_contact(params(), contact_at(d), 1).state, VerdictState::stop) << d;
  }
  Contact far_but_broken = contact_at(5.0F);
  far_but_broken.closest_base.x() = nan;
  EXPECT_EQ(verdict_for_contact(params(), far_but_broken, 1).state, VerdictState::stop);
  Contact robot_point_broken = contact_at(5.0F);
  robot_point_broken.closest_robot_base.z() = inf;
  EXPECT_EQ(verdict_for_contact(params(), robot_point_broken, 1).state, VerdictState::stop);
}

// R1 item 3: a point inside the robot's padded capsule is a stop, whatever the zones say
// (even with both distances 0, which config refuses, the verdict stays stop).
TEST(Verdict, InsideTheRobotAlwaysStops) {
  SafetyParams zero;
  zero.slow_distance_m = 0.0F;
  zero.stop_distance_m = 0.0F;
  Contact inside = contact_at(0.0F);
  inside.inside = true;
  EXPECT_EQ(verdict_for_contact(zero, inside, 1).state, VerdictState::stop);
  EXPECT_EQ(verdict_for_contact(params(), inside, 1).reason, "inside robot");
}

// Each verdict of the zones carries its code (A3): control flow and consumers read the code.
TEST(Verdict, EveryOutcomeHasItsCode) {
  const SafetyParams p = params();
  EXPECT_EQ(verdict_for_contact(p, Contact{}, 0).code, ReasonCode::no_foreground);
  EXPECT_EQ(verdict_for_contact(p, contact_at(5.0F), 1).code, ReasonCode::clear);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.8F), 1).code, ReasonCode::in_slow_zone);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.1F), 1).code, ReasonCode::in_stop_zone);
  EXPECT_EQ(verdict_for_contact(p, Contact{}, 3).code, ReasonCode::non_finite_input);
  Contact inside = contact_at(0.0F);
  inside.inside = true;
  EXPECT_EQ(verdict_for_contact(p, inside, 1).code, ReasonCode::inside_robot);
  for (float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    const Verdict v = verdict_for_contact(p, contact_at(bad), 1);
    EXPECT_EQ(v.state, VerdictState::stop);
    EXPECT_EQ(v.code, ReasonCode::non_finite_input);
  }
}

// The codes' names are the stable identifiers of docs/OUTPUT.md: snake_case and distinct.
TEST(Verdict, ReasonCodeNamesAreDistinctSnakeCase) {
  const std::vector<std::pair<ReasonCode, std::string>> expected = {
      {ReasonCode::clear, "clear"}, {ReasonCode::no_foreground, "no_foreground"},
      {ReasonCode::in_slow_zone, "in_slow_zone"}, {ReasonCode::in_stop_zone, "in_stop_zone"},
      {ReasonCode::inside_robot, "inside_robot"}, {ReasonCode::non_finite_input, "non_finite_input"},
      {ReasonCode::learning_background, "learning_background"},
      {ReasonCode::checking_background, "checking_background"}, {ReasonCode::no_valid_depth, "no_valid_depth"},
      {ReasonCode::low_valid_share, "low_valid_share"}, {ReasonCode::background_mismatch, "background_mismatch"},
      {ReasonCode::no_robot_model, "no_robot_model"}, {ReasonCode::no_robot_state, "no_robot_state"},
      {ReasonCode::robot_state_stale, "robot_state_stale"}, {ReasonCode::foreground_failed, "foreground_failed"},
      {ReasonCode::stale_frame, "stale_frame"}, {ReasonCode::no_frame, "no_frame"},
      {ReasonCode::source_ended, "source_ended"}, {ReasonCode::frame_limit_reached, "frame_limit_reached"},
      {ReasonCode::stop_requested, "stop_requested"}, {ReasonCode::source_error, "source_error"},
      {ReasonCode::processing_error, "processing_error"}, {ReasonCode::output_error, "output_error"},
      {ReasonCode::camera_disconnected, "camera_disconnected"}};
  std::set<std::string> seen;
  for (const auto& [code, name] : expected) {
    EXPECT_EQ(reason_code_name(code), name);
    EXPECT_TRUE(seen.insert(name).second) << name;
  }
  // The last enumerator is camera_disconnected: a new code without a name here fails this count.
  EXPECT_EQ(static_cast<size_t>(ReasonCode::camera_disconnected) + 1, expected.size());
}

TEST(Verdict, Names) {
  EXPECT_STREQ(verdict_name(VerdictState::run), "run");
  EXPECT_STREQ(verdict_name(VerdictState::slow), "slow");
  EXPECT_STREQ(verdict_name(VerdictState::stop), "stop");
}

}  // namespace
}  // namespace hrcsense
