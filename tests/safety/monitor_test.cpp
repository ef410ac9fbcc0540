// SPDX-License-Identifier: Apache-2.0
// The SafetyMonitor: a measurement decided once, per link, at its age when it is decided, with
// the hold, the watchdog's stop and the stops a mailbox replaced; values worked by hand.

#include "hrcsense/mailbox.hpp"
#include "hrcsense/safety.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace hrcsense {
namespace {

// The ssm defaults: v_h 1.6 m/s beyond 0.5 m; controller latency 0.05 s; T_s 0.5 s without a
// deceleration (S_s = v·T_s/2); C = 8·(40 − 14) mm = 0.208 m; Z_r 0.01 m. At an age of 0 T_r is
// 0.05 s, so with Z_d 0.02 m S_p(v) = 1.6·0.55 + 0.208 + 0.02 + 0.01 + v·(0.05 + 0.25)
// = 1.118 + 0.3·v. The receiver's timeout, a part of T_r of its own, is 0 here (its table test
// is in ssm_test.cpp), and without a nominal rate there is no frame period in T_r.
SafetyParams ssm_mode() {
  SafetyParams p;
  p.mode = SafetyParams::Mode::ssm;
  p.ssm.receiver_timeout_s = 0.0;
  return p;
}

LinkContact link(int index, float distance_m, float speed_towards_mps) {
  LinkContact l;
  l.link = index;
  l.contact.valid = true;
  l.contact.distance_m = distance_m;
  l.contact.robot_link = index;
  l.contact.closest_base = {distance_m, 0.0F, 0.0F};
  l.contact.closest_robot_base = {0.0F, 0.0F, 0.0F};
  l.speed_towards_mps = speed_towards_mps;
  l.distance_uncertainty_m = 0.02F;
  return l;
}

// A valid measurement with the given links; the overall contact is the closest of them.
FrameResult measured(std::initializer_list<LinkContact> links) {
  FrameResult m;
  m.valid = true;
  m.foreground_points = 100;
  for (const LinkContact& l : links) {
    m.links.push_back(l);
    if (!m.contact.valid || l.contact.distance_m < m.contact.distance_m) m.contact = l.contact;
  }
  return m;
}

// The case: a still base closest (1.3 m) and a fast wrist a little farther (1.5 m,
// 1.5 m/s towards the person). Base: S_p = 1.118 m, cleared: run. Wrist: S_p at its present
// speed = 1.118 + 0.45 = 1.568 m > 1.5 m: it has not reacted yet, and no braking is shorter
// than its stop, so stop. The wrist governs; the overall pair stays the base's.
TEST(SafetyMonitor, AFastFartherLinkGovernsOverAStillCloserOne) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult r = measured({link(0, 1.3F, 0.0F), link(5, 1.5F, 1.5F)});
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::stop);
  EXPECT_EQ(r.verdict.code, ReasonCode::below_protective_distance);
  EXPECT_EQ(r.governing_link, 5);
  EXPECT_NEAR(r.verdict.protective_distance_m, 1.568, 1e-5);
  EXPECT_FLOAT_EQ(r.robot_speed_towards_mps, 1.5F);
  EXPECT_EQ(r.contact.robot_link, 0);  // distance_m and the closest pair stay the overall ones
  ASSERT_EQ(r.link_protective_distance_m.size(), 2U);
  EXPECT_NEAR(r.link_protective_distance_m[0], 1.118, 1e-5);
  EXPECT_NEAR(r.link_protective_distance_m[1], 1.568, 1e-5);
  ASSERT_TRUE(r.ssm.has_value());
  EXPECT_NEAR(r.ssm->s_r_m, 1.5 * 0.05, 1e-6);
}

// The same wrist already slowed to half its programmed 1.5 m/s (0.75 m/s, speed fraction 0.5):
// S_p(0.75) = 1.118 + 0.225 = 1.343 m ≤ 1.5 m, so it may go on, up to (1.5 − 1.118) / 0.3 =
// 1.27333 m/s: slow at 1.27333 / 1.5 = 0.848889 of the programmed speed.
FrameResult slowed_wrist() {
  FrameResult r = measured({link(0, 1.3F, 0.0F), link(5, 1.5F, 0.75F)});
  r.robot_state.speed_fraction = 0.5;
  return r;
}

TEST(SafetyMonitor, ASlowedFartherLinkGovernsWithItsScale) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult r = slowed_wrist();
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::slow);
  EXPECT_EQ(r.verdict.code, ReasonCode::speed_limited);
  EXPECT_NEAR(r.verdict.speed_scale, 0.848889, 1e-5);
  EXPECT_EQ(r.governing_link, 5);
  EXPECT_NEAR(r.verdict.protective_distance_m, 1.343, 1e-5);
}

// When every link clears its S_p the verdict is run, and the link with the least slack
// (d_i − S_p,i) is named: base 1.3 − 1.118 = 0.182 m, wrist 1.8 − (1.118 + 0.15) = 0.532 m.
TEST(SafetyMonitor, TheLinkWithTheLeastSlackIsNamedWhenAllRun) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult r = measured({link(0, 1.3F, 0.0F), link(5, 1.8F, 0.5F)});
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::run);
  EXPECT_EQ(r.governing_link, 0);
  EXPECT_NEAR(r.verdict.protective_distance_m, 1.118, 1e-5);
}

// Zones mode: the closest link's distance decides (0.8 m: slow, scale (0.8 − 0.5) / 0.5 = 0.6).
TEST(SafetyMonitor, ZonesDecideOnTheClosestLink) {
  SafetyMonitor monitor(SafetyParams{});
  FrameResult r = measured({link(1, 1.2F, 3.0F), link(3, 0.8F, 0.0F)});
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::slow);
  EXPECT_NEAR(r.verdict.speed_scale, 0.6, 1e-6);
  EXPECT_EQ(r.governing_link, 3);
}

// A link whose speed could not be computed (NaN) is a stop in ssm mode, whatever the others say.
TEST(SafetyMonitor, ALinkWithoutASpeedStops) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult r = measured({link(0, 3.0F, 0.0F), link(4, 3.5F, std::numeric_limits<float>::quiet_NaN())});
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::stop);
  EXPECT_EQ(r.verdict.code, ReasonCode::non_finite_input);
  EXPECT_EQ(r.governing_link, 4);
}

TEST(SafetyMonitor, AWithheldMeasurementIsAStopWithItsReason) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult r;
  r.valid = false;
  r.withheld_code = ReasonCode::robot_state_stale;
  r.withheld_reason = "robot state stale (80.0 ms old)";
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::stop);
  EXPECT_EQ(r.verdict.code, ReasonCode::robot_state_stale);
  EXPECT_EQ(r.verdict.reason, "robot state stale (80.0 ms old)");
  EXPECT_EQ(r.governing_link, -1);
}

// The frame's age is taken when it is decided: seen at 0.9 s, decided at 1.1 s: 0.2 s old, so
// T_r = 0.25 s and S_p at rest = 1.6·(0.25 + 0.5) + 0.238 = 1.438 m: a person at 1.3 m, clear
// of S_p had the frame been decided at once (1.118 m), is now inside it.
TEST(SafetyMonitor, AgeCountsUntilTheDecision) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult r = measured({link(0, 1.3F, 0.0F)});
  r.clocked = true;
  r.delivered_ns = 950'000'000;
  r.seen_ns = 900'000'000;
  monitor.decide(r, 1'100'000'000);
  EXPECT_NEAR(r.frame_age_s, 0.2, 1e-12);
  ASSERT_TRUE(r.ssm.has_value());
  EXPECT_NEAR(r.ssm->reaction_time_s, 0.25, 1e-12);
  EXPECT_EQ(r.verdict.state, VerdictState::stop);
  EXPECT_EQ(r.verdict.code, ReasonCode::below_protective_distance);
  EXPECT_NEAR(r.verdict.protective_distance_m, 1.438, 1e-5);
}

// Delivered longer ago than the no-frame limit: stale. A live 30 frames/s source's limit is two
// periods, 66.7 ms; a frame delivered 70 ms ago is a stop, one delivered 60 ms ago is not.
TEST(SafetyMonitor, OlderThanTheWatchdogLimitIsStale) {
  SafetyMonitor monitor(SafetyParams{}, 30.0, true);
  EXPECT_EQ(monitor.watchdog_after_ns(), 66'666'667);
  for (const int64_t age_ms : {60, 70}) {
    FrameResult r = measured({link(0, 3.0F, 0.0F)});
    r.clocked = true;
    r.delivered_ns = r.seen_ns = 1'000'000'000;
    monitor.reset();
    monitor.decide(r, 1'000'000'000 + age_ms * 1'000'000);
    EXPECT_EQ(r.verdict.code == ReasonCode::stale_frame, age_ms == 70) << age_ms << " ms: " << r.verdict.reason;
  }
}

// A live camera's frame is stale from its capture (seen_ns, on the host clock), not from its
// delivery: captured 80 ms ago but delivered 10 ms ago, at 30 frames/s (limit 66.7 ms), it is a
// stop. A recording's or the simulator's frame has no capture time on the host clock (seen_ns is
// its delivery) and keeps the delivery rule.
TEST(SafetyMonitor, ALiveFrameIsStaleFromItsCapture) {
  SafetyMonitor monitor(SafetyParams{}, 30.0, true);
  FrameResult live = measured({link(0, 3.0F, 0.0F)});
  live.clocked = true;
  live.seen_ns = 1'000'000'000;
  live.delivered_ns = 1'070'000'000;
  monitor.decide(live, 1'080'000'000);
  EXPECT_EQ(live.verdict.code, ReasonCode::stale_frame) << live.verdict.reason;
  FrameResult recorded = measured({link(0, 3.0F, 0.0F)});
  recorded.clocked = true;
  recorded.seen_ns = recorded.delivered_ns = 1'070'000'000;
  monitor.reset();
  monitor.decide(recorded, 1'080'000'000);
  EXPECT_EQ(recorded.verdict.code, ReasonCode::clear) << recorded.verdict.reason;
}

// The robot state 40 ms older than its frame, 8 ms of it covered by extrapolation: Z_r grows by
// robot_max_speed_mps (3 m/s) · 0.032 s = 0.096 m, and so does S_p: 1.118 + 0.096 = 1.214 m.
TEST(SafetyMonitor, TheRobotStatesUncoveredAgeWidensZr) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult r = measured({link(0, 3.0F, 0.0F)});
  r.robot_state_age_ms = 40.0;
  r.robot_state.extrapolated_ns = 8'000'000;
  monitor.decide(r, 0);
  ASSERT_TRUE(r.ssm.has_value());
  EXPECT_NEAR(r.ssm->z_r_state_m, 0.096, 1e-6);
  EXPECT_NEAR(r.ssm->z_r_m, 0.106, 1e-6);
  EXPECT_NEAR(r.verdict.protective_distance_m, 1.214, 1e-5);
  // Fully extrapolated (8 ms old, 8 ms covered): nothing added.
  r.robot_state_age_ms = 8.0;
  monitor.decide(r, 0);
  EXPECT_NEAR(r.ssm->z_r_m, 0.01, 1e-7);
}

// The monitor adds one nominal frame period to T_r: at 30 frames/s, 1/30 s, so S_p at rest of
// a person at 3 m is 1.118 + 1.6/30 = 1.1713 m; `unknown_margin_m` is taken against it.
TEST(SafetyMonitor, ANominalRateAddsItsPeriodToTr) {
  SafetyMonitor monitor(ssm_mode(), 30.0);
  FrameResult r = measured({link(0, 3.0F, 0.0F)});
  r.unknown_distance_m = 1.5F;
  monitor.decide(r, 0);
  ASSERT_TRUE(r.ssm.has_value());
  EXPECT_NEAR(r.ssm->frame_period_s, 1.0 / 30.0, 1e-12);
  EXPECT_NEAR(r.ssm->reaction_time_s, 0.05 + 1.0 / 30.0, 1e-12);
  EXPECT_NEAR(r.verdict.protective_distance_m, 1.118 + 1.6 / 30.0, 1e-5);
  EXPECT_NEAR(r.unknown_margin_m, 1.5 - (1.118 + 1.6 / 30.0), 1e-5);
}

// A stop that a mailbox replaced before it was decided is carried: the run that replaced it is
// written as that stop, with its reason, and the replacement is counted.
TEST(SafetyMonitor, AReplacedStopIsCarriedIntoTheNextResult) {
  SafetyMonitor monitor(ssm_mode());
  const FrameResult stop = measured({link(2, 0.4F, 0.0F)});  // below S_p at rest: stop
  FrameResult next;  // nobody in the cell: run
  next.valid = true;
  carry_replaced(monitor, stop, 0, next);
  EXPECT_EQ(next.replaced.count, 1);
  monitor.decide(next, 0);
  EXPECT_EQ(next.verdict.state, VerdictState::stop);
  EXPECT_EQ(next.verdict.code, ReasonCode::below_protective_distance);

  // A run that replaced a slow: written as that slow, at its scale.
  SafetyMonitor second(ssm_mode());
  const FrameResult slow = slowed_wrist();  // scale 0.848889, as above
  FrameResult run;
  run.valid = true;
  carry_replaced(second, slow, 0, run);
  second.decide(run, 0);
  EXPECT_EQ(run.verdict.state, VerdictState::slow);
  EXPECT_NEAR(run.verdict.speed_scale, 0.848889, 1e-5);
}

// The strictest of several replaced measurements wins, whichever came first, and what a
// replaced one carried itself is carried on.
TEST(SafetyMonitor, TheStrictestOfSeveralReplacedWins) {
  SafetyMonitor monitor(ssm_mode());
  FrameResult first = measured({link(2, 0.4F, 0.0F)});  // stop
  FrameResult second;                                    // run, replaces first
  second.valid = true;
  carry_replaced(monitor, first, 0, second);
  FrameResult third = slowed_wrist();  // slow, replaces second
  carry_replaced(monitor, second, 0, third);
  EXPECT_EQ(third.replaced.count, 2);
  monitor.decide(third, 0);
  EXPECT_EQ(third.verdict.state, VerdictState::stop);
  EXPECT_EQ(third.verdict.code, ReasonCode::below_protective_distance);
}

// The mailbox hands the value it replaces to the merge, under its lock, and counts the drop.
TEST(SafetyMonitor, MailboxMergesWhatItReplaces) {
  Mailbox<FrameResult> box;
  SafetyMonitor monitor(ssm_mode());
  const auto carry = [&](const FrameResult& replaced, FrameResult& next) { carry_replaced(monitor, replaced, 0, next); };
  FrameResult a = measured({link(2, 0.4F, 0.0F)});
  FrameResult b;
  b.valid = true;
  ASSERT_TRUE(box.put(a, carry));
  ASSERT_TRUE(box.put(b, carry));
  EXPECT_EQ(box.dropped(), 1);
  FrameResult out;
  ASSERT_TRUE(box.take_for(out, 1.0));
  EXPECT_EQ(out.replaced.count, 1);
  monitor.decide(out, 0);
  EXPECT_EQ(out.verdict.state, VerdictState::stop);
}

// The watchdog's stop is held: with min_hold_s 0.1 s the frame after a silence, though clear,
// says `holding` stop; 0.1 s of frame time later it runs again.
TEST(SafetyMonitor, TheFrameAfterASilenceHoldsTheWatchdogsStop) {
  SafetyParams params = ssm_mode();
  params.min_hold_s = 0.1;
  SafetyMonitor monitor(params);
  const Verdict silence = monitor.silence(ReasonCode::no_frame, "no frame for 0.600 s (max_frame_age_s 0.500)");
  EXPECT_EQ(silence.state, VerdictState::stop);
  EXPECT_EQ(silence.code, ReasonCode::no_frame);
  FrameResult r = measured({link(0, 3.0F, 0.0F)});
  r.host_time_ns = 2'000'000'000;
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::stop);
  EXPECT_EQ(r.verdict.code, ReasonCode::holding);
  FrameResult later = measured({link(0, 3.0F, 0.0F)});
  later.host_time_ns = 2'100'000'000;
  monitor.decide(later, 0);
  EXPECT_EQ(later.verdict.state, VerdictState::run);
}

// The unknown-space policy applies once, to the decided verdict; the governing link is kept.
TEST(SafetyMonitor, UnknownSpaceStopsOnce) {
  SafetyParams params = ssm_mode();
  params.unknown_policy = SafetyParams::UnknownPolicy::stop_within_m;
  SafetyMonitor monitor(params);
  FrameResult r = measured({link(0, 3.0F, 0.0F), link(5, 3.2F, 0.2F)});
  r.unknown_distance_m = 0.05F;
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::stop);
  EXPECT_EQ(r.verdict.code, ReasonCode::unknown_space);
  EXPECT_GE(r.governing_link, 0);
}

// ---- The speed scale against the programmed speed (S1, defect 2)
//
// A link 1.268 m away: S_p(v) = 1.118 + 0.3·v, so the allowed speed is (1.268 − 1.118) / 0.3 =
// 0.5 m/s. The scale is a share of the *programmed* speed, which is the present speed divided
// by the share the robot runs at (its speed fraction).

SafetyParams no_hold() {
  SafetyParams params = ssm_mode();
  params.hysteresis_m = 0.0F;
  params.min_hold_s = 0.0;
  return params;
}

FrameResult moving_at(float present_mps, double speed_fraction) {
  FrameResult r = measured({link(5, 1.268F, present_mps)});
  r.robot_state.speed_fraction = speed_fraction;
  return r;
}

// The robot reads 0.5 of its programmed speed and moves at 0.5 m/s: programmed 1 m/s, so the
// scale is 0.5 / 1 = 0.5. Taking the present speed for the programmed one (0.5 / 0.5 = 1, run)
// was the defect: the robot, back at full speed, would then run at 1 m/s > 0.5 m/s.
TEST(SafetyMonitor, TheScaleIsOfTheProgrammedSpeedTheStateReads) {
  SafetyMonitor monitor(no_hold());
  FrameResult r = moving_at(0.5F, 0.5);
  monitor.decide(r, 0);
  EXPECT_EQ(r.verdict.state, VerdictState::slow);
  EXPECT_NEAR(r.verdict.speed_scale, 0.5, 1e-5);
  EXPECT_EQ(r.robot_speed_fraction, 0.5);
}

// No reading (udp_json without speed_fraction): the robot is taken to run at the scale sent
// last. Frame 1 reads 0.5 and moves at 0.4 m/s: programmed 0.8 m/s, scale 0.5 / 0.8 = 0.625.
// Frame 2 reads nothing and moves at 0.5 m/s (S_p(0.5) = 1.268 m: it may go on): against the
// 0.625 sent, programmed 0.8 m/s → the scale stays 0.625 (taking 0.5 m/s as programmed would say
// run, and the robot would return to 0.8 m/s).
TEST(SafetyMonitor, WithoutAReadingTheLastScaleSentCounts) {
  SafetyMonitor monitor(no_hold());
  FrameResult first = moving_at(0.4F, 0.5);
  monitor.decide(first, 0);
  EXPECT_EQ(first.verdict.state, VerdictState::slow);
  EXPECT_NEAR(first.verdict.speed_scale, 0.625, 1e-5);
  EXPECT_NEAR(monitor.scale_sent(), 0.625, 1e-6);
  FrameResult second = moving_at(0.5F, std::numeric_limits<double>::quiet_NaN());
  second.host_time_ns = 33'000'000;
  monitor.decide(second, 0);
  EXPECT_EQ(second.verdict.state, VerdictState::slow);
  EXPECT_NEAR(second.verdict.speed_scale, 0.625, 1e-4);
  EXPECT_NEAR(second.robot_speed_fraction, 0.625, 1e-6);
}

// A reading wins over what was sent: the scale sent was 0.625 but the robot reads 1 (someone
// set the slider back) and moves at 0.45 m/s: programmed 0.45 m/s, within the 0.5 m/s allowed:
// run (against the scale sent it would have been 0.5 / (0.45 / 0.625) = 0.694).
TEST(SafetyMonitor, AReadingWinsOverTheScaleSent) {
  SafetyMonitor monitor(no_hold());
  FrameResult first = moving_at(0.4F, 0.5);
  monitor.decide(first, 0);
  ASSERT_NEAR(monitor.scale_sent(), 0.625, 1e-6);
  FrameResult second = moving_at(0.45F, 1.0);
  monitor.decide(second, 0);
  EXPECT_EQ(second.verdict.state, VerdictState::run);
  EXPECT_EQ(second.robot_speed_fraction, 1.0);
  // After a silence the links sent a stop: 0.
  monitor.silence(ReasonCode::no_frame, "no frame");
  EXPECT_EQ(monitor.scale_sent(), 0.0F);
}

}  // namespace
}  // namespace hrcsense
