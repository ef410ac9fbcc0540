// SPDX-License-Identifier: Apache-2.0
// Tests of the run / slow / stop verdict against the thresholds in SafetyParams.

#include "hrcsense/safety.hpp"

#include <gtest/gtest.h>

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
  const Verdict v = verdict_for_contact(params(), Contact{});
  EXPECT_EQ(v.state, VerdictState::run);
  EXPECT_EQ(v.speed_scale, 1.0F);
}

TEST(Verdict, ThresholdsAtAndAroundTheBoundaries) {
  const SafetyParams p = params();
  EXPECT_EQ(verdict_for_contact(p, contact_at(5.0F)).state, VerdictState::run);
  // At slow_distance_m: "at or beyond" runs.
  EXPECT_EQ(verdict_for_contact(p, contact_at(1.2F)).state, VerdictState::run);
  EXPECT_EQ(verdict_for_contact(p, contact_at(1.19F)).state, VerdictState::slow);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.41F)).state, VerdictState::slow);
  // At stop_distance_m: not below, so still slow (at speed 0).
  const Verdict at_stop = verdict_for_contact(p, contact_at(0.4F));
  EXPECT_EQ(at_stop.state, VerdictState::slow);
  EXPECT_EQ(at_stop.speed_scale, 0.0F);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.39F)).state, VerdictState::stop);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.0F)).state, VerdictState::stop);
}

TEST(Verdict, SpeedScaleIsLinearInTheSlowZone) {
  const SafetyParams p = params();
  // Span 0.8 m from 0.4 to 1.2: 0.6 m is a quarter of the way, 1.0 m three quarters.
  EXPECT_NEAR(verdict_for_contact(p, contact_at(0.6F)).speed_scale, 0.25F, 1e-6F);
  EXPECT_NEAR(verdict_for_contact(p, contact_at(0.8F)).speed_scale, 0.5F, 1e-6F);
  EXPECT_NEAR(verdict_for_contact(p, contact_at(1.0F)).speed_scale, 0.75F, 1e-6F);
  // Equal steps in distance give equal steps in speed.
  const float s1 = verdict_for_contact(p, contact_at(0.5F)).speed_scale;
  const float s2 = verdict_for_contact(p, contact_at(0.7F)).speed_scale;
  const float s3 = verdict_for_contact(p, contact_at(0.9F)).speed_scale;
  EXPECT_NEAR(s2 - s1, s3 - s2, 1e-6F);
  EXPECT_EQ(verdict_for_contact(p, contact_at(1.5F)).speed_scale, 1.0F);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.1F)).speed_scale, 0.0F);
}

TEST(Verdict, StopReasonsAreNeverEmpty) {
  const Verdict close = verdict_for_contact(params(), contact_at(0.1F));
  EXPECT_FALSE(close.reason.empty());
  const Verdict stale = stop_verdict("stale frame");
  EXPECT_EQ(stale.state, VerdictState::stop);
  EXPECT_EQ(stale.speed_scale, 0.0F);
  EXPECT_EQ(stale.reason, "stale frame");
  EXPECT_FALSE(stop_verdict("").reason.empty());
}

TEST(Verdict, EqualThresholdsHaveNoSlowZone) {
  SafetyParams p;
  p.slow_distance_m = 0.5F;
  p.stop_distance_m = 0.5F;
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.49F)).state, VerdictState::stop);
  EXPECT_EQ(verdict_for_contact(p, contact_at(0.5F)).state, VerdictState::run);
}

TEST(Verdict, Names) {
  EXPECT_STREQ(verdict_name(VerdictState::run), "run");
  EXPECT_STREQ(verdict_name(VerdictState::slow), "slow");
  EXPECT_STREQ(verdict_name(VerdictState::stop), "stop");
}

}  // namespace
}  // namespace hrcsense
