// SPDX-License-Identifier: Apache-2.0
// hrcsense — the one place a measurement becomes a verdict: per link, at the frame's real age,
// with the hold, the watchdog and the stops a mailbox would otherwise have dropped.

#include "hrcsense/safety.hpp"
#include "hrcsense/clock.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace hrcsense {
namespace {

// True when (state_a, scale_a) is stricter than (state_b, scale_b): a stricter state, or the
// same state with a lower speed scale.
bool stricter(VerdictState state_a, float scale_a, VerdictState state_b, float scale_b) {
  const int a = verdict_strictness(state_a);
  const int b = verdict_strictness(state_b);
  return a != b ? a > b : scale_a < scale_b;
}

// A measurement seen more than `stale_after_ns` before `now_ns` is stale: from its capture
// where the source put that on the host clock (live cameras), else from its delivery
// (recordings and the simulator, whose stamps are not host time).
bool is_stale(int64_t stale_after_ns, const Measurement& m, int64_t now_ns) {
  return m.clocked && now_ns - m.seen_ns > stale_after_ns;
}

double age_s(const Measurement& m, int64_t now_ns) {
  if (!m.clocked) return 0.0;
  return static_cast<double>(std::max<int64_t>(0, now_ns - m.seen_ns)) * 1e-9;
}

void set_stale(Verdict& verdict) {
  verdict.state = VerdictState::stop;
  verdict.speed_scale = 0.0F;
  verdict.code = ReasonCode::stale_frame;
  verdict.reason.assign("stale frame");
}

// Copies `from` into `to`, keeping `to`'s reason buffer (a move or swap would hand a buffer
// to a temporary, and the next long reason would allocate again).
void assign_verdict(Verdict& to, const Verdict& from) {
  to.state = from.state;
  to.speed_scale = from.speed_scale;
  to.protective_distance_m = from.protective_distance_m;
  to.code = from.code;
  to.reason.assign(from.reason);
}

// The replaced measurements' strictest verdict, when it is stricter than `verdict`, replaces it.
void merge_replaced(const ReplacedVerdicts& replaced, Verdict& verdict) {
  if (replaced.count <= 0 || !stricter(replaced.state, replaced.speed_scale, verdict.state, verdict.speed_scale)) return;
  verdict.state = replaced.state;
  verdict.speed_scale = replaced.speed_scale;
  verdict.code = replaced.code;
  verdict.reason.assign(replaced.reason);
}

}  // namespace

void decide_measurement(const SafetyParams& params, const Measurement& m, double frame_age_s, double scale_sent,
                        Decision& out, float distance_margin_m, std::vector<float>* link_protective_distance_m) {
  if (link_protective_distance_m != nullptr) link_protective_distance_m->clear();
  out.ssm.reset();
  out.governing_link = -1;
  out.distance_uncertainty_m = std::numeric_limits<float>::quiet_NaN();
  out.robot_speed_towards_mps = std::numeric_limits<float>::quiet_NaN();
  out.unknown_margin_m = std::numeric_limits<float>::quiet_NaN();
  Verdict& verdict = out.verdict;
  if (!m.valid) {
    verdict.state = VerdictState::stop;
    verdict.speed_scale = 0.0F;
    verdict.protective_distance_m = 0.0F;
    verdict.code = m.withheld_code;
    if (m.withheld_reason.empty()) {
      verdict.reason.assign(reason_code_name(m.withheld_code));
    } else {
      verdict.reason.assign(m.withheld_reason);
    }
    return;
  }
  if (!m.contact.valid || m.links.empty()) {
    // No contact: nothing in the cell (run), or foreground the search could not place (stop);
    // a valid contact without any link's would have no speed and no Z_d, which ssm stops on.
    const Decision d = decide_verdict(params, verdict_input(m, nullptr, frame_age_s, scale_sent), distance_margin_m);
    assign_verdict(verdict, d.verdict);
    out.ssm = d.ssm;
    out.unknown_margin_m = d.unknown_margin_m;
    return;
  }
  float governing_slack_m = 0.0F;
  for (const LinkContact& link : m.links) {
    VerdictInput input = verdict_input(m, &link, frame_age_s, scale_sent);
    input.unknown_distance_m = std::numeric_limits<float>::quiet_NaN();  // the policy applies once, below
    const Decision d = decide_verdict(params, input, distance_margin_m);
    if (link_protective_distance_m != nullptr) link_protective_distance_m->push_back(d.verdict.protective_distance_m);
    // d_i − S_p,i; NaN (no S_p) counts as the least slack, as NaN is a stop anyway.
    float slack_m = link.contact.distance_m - d.verdict.protective_distance_m;
    if (std::isnan(slack_m)) slack_m = -std::numeric_limits<float>::infinity();
    const bool first = out.governing_link < 0;
    const bool same = !first && d.verdict.state == verdict.state && d.verdict.speed_scale == verdict.speed_scale;
    if (first || stricter(d.verdict.state, d.verdict.speed_scale, verdict.state, verdict.speed_scale) ||
        (same && slack_m < governing_slack_m)) {
      assign_verdict(verdict, d.verdict);
      out.ssm = d.ssm;
      out.governing_link = link.link;
      out.distance_uncertainty_m = link.distance_uncertainty_m;
      out.robot_speed_towards_mps = link.speed_towards_mps;
      governing_slack_m = slack_m;
    }
  }
  out.unknown_margin_m = unknown_margin_m(params, m.unknown_distance_m, verdict);
  apply_unknown_policy(params, m.unknown_distance_m, distance_margin_m, verdict);
}

SafetyMonitor::SafetyMonitor(SafetyParams params, double nominal_fps, bool frames_at_a_rate)
    : params_(std::move(params)) {
  // T_r counts one nominal frame period: an intrusion can begin just after a capture.
  if (nominal_fps > 0.0) params_.ssm.frame_period_s = 1.0 / nominal_fps;
  watchdog_after_ns_ = seconds_to_ns(params_.max_frame_age_s);
  std::snprintf(watchdog_rule_, sizeof watchdog_rule_, "max_frame_age_s %.3f", params_.max_frame_age_s);
  if (frames_at_a_rate && nominal_fps > 0.0) {
    const int64_t gap_ns = seconds_to_ns(params_.max_frame_gap_periods / nominal_fps);
    if (gap_ns < watchdog_after_ns_) {
      watchdog_after_ns_ = gap_ns;
      std::snprintf(watchdog_rule_, sizeof watchdog_rule_, "max_frame_gap_periods %g at %g frames/s",
                    params_.max_frame_gap_periods, nominal_fps);
    }
  }
}

void SafetyMonitor::decide(FrameResult& result, int64_t now_ns) {
  const double frame_age_s = age_s(result, now_ns);
  result.frame_age_s = frame_age_s;
  Decision& decision = decision_;
  const double scale_sent = scale_sent_.load(std::memory_order_relaxed);
  decide_measurement(params_, result, frame_age_s, scale_sent, decision, 0.0F, &result.link_protective_distance_m);
  if (is_stale(watchdog_after_ns_, result, now_ns)) set_stale(decision.verdict);
  merge_replaced(result.replaced, decision.verdict);
  if (silence_pending_) {
    hold_.stop_at(result.host_time_ns);
    silence_pending_ = false;
  }
  // The hold relaxes only as far as the frame's decision with the distance less the hysteresis
  // (without a hysteresis that is the decision itself: not made twice).
  const Decision* with_margin = &decision;
  if (params_.hysteresis_m > 0.0F) {
    decide_measurement(params_, result, frame_age_s, scale_sent, with_margin_, params_.hysteresis_m);
    with_margin = &with_margin_;
  }
  hold_.apply(params_, *with_margin, result.host_time_ns, decision);
  assign_verdict(result.verdict, decision.verdict);
  result.ssm = decision.ssm;
  result.governing_link = decision.governing_link;
  result.distance_uncertainty_m = decision.distance_uncertainty_m;
  result.robot_speed_towards_mps = decision.robot_speed_towards_mps;
  result.unknown_margin_m = decision.unknown_margin_m;
  result.robot_speed_fraction = robot_speed_fraction(result, scale_sent);
  scale_sent_.store(result.verdict.speed_scale, std::memory_order_relaxed);  // what every link sends now
}

Verdict SafetyMonitor::silence(ReasonCode code, const std::string& reason) {
  silence_pending_ = true;
  scale_sent_.store(0.0F, std::memory_order_relaxed);
  return stop_verdict(code, reason);
}

void SafetyMonitor::reset() {
  hold_.reset();
  silence_pending_ = false;
  scale_sent_.store(1.0F, std::memory_order_relaxed);
}

void carry_replaced(const SafetyMonitor& monitor, const FrameResult& replaced, int64_t now_ns, FrameResult& next) {
  Decision decision;
  decide_measurement(monitor.params(), replaced, age_s(replaced, now_ns), monitor.scale_sent(), decision);
  if (is_stale(monitor.watchdog_after_ns(), replaced, now_ns)) set_stale(decision.verdict);
  merge_replaced(replaced.replaced, decision.verdict);  // what the replaced one itself carried
  ReplacedVerdicts& carried = next.replaced;
  const bool first = carried.count <= 0;
  carried.count = (first ? 0 : carried.count) + 1 + std::max<int64_t>(0, replaced.replaced.count);
  if (first || stricter(decision.verdict.state, decision.verdict.speed_scale, carried.state, carried.speed_scale)) {
    carried.state = decision.verdict.state;
    carried.speed_scale = decision.verdict.speed_scale;
    carried.code = decision.verdict.code;
    carried.reason.assign(decision.verdict.reason);
  }
}

}  // namespace hrcsense
