// SPDX-License-Identifier: Apache-2.0
// hrcsense — run / slow / stop from the closest distance; anything untrusted is a stop.

#include "hrcsense/safety.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hrcsense {

// The reasons of the per-frame verdicts stay within std::string's small-buffer size (15
// characters in libstdc++), so that producing a verdict every frame does not allocate.

namespace {

Verdict make_verdict(VerdictState state, float speed_scale, float protective_distance_m, ReasonCode code,
                     const char* reason) {
  Verdict verdict;
  verdict.state = state;
  verdict.speed_scale = speed_scale;
  verdict.protective_distance_m = protective_distance_m;
  verdict.code = code;
  verdict.reason = reason;
  return verdict;
}

bool finite_point(const Eigen::Vector3f& p) { return p.allFinite(); }

}  // namespace

Verdict verdict_for_contact(const SafetyParams& params, const Contact& contact, size_t foreground_points) {
  const auto stop = [&](ReasonCode code, const char* reason) {
    return make_verdict(VerdictState::stop, 0.0F, params.stop_distance_m, code, reason);
  };
  const auto run = [&](ReasonCode code, const char* reason) {
    return make_verdict(VerdictState::run, 1.0F, params.slow_distance_m, code, reason);
  };
  if (!contact.valid) {
    // Foreground that the search could not place (non-finite points, a broken pose) is not
    // "nothing in the cell": only an empty foreground is.
    if (foreground_points > 0) return stop(ReasonCode::non_finite_input, "no contact");
    return run(ReasonCode::no_foreground, "no foreground");
  }
  const float d = contact.distance_m;
  // Every comparison below is written so that NaN falls through to stop.
  if (!std::isfinite(d) || d < 0.0F || !finite_point(contact.closest_base) ||
      !finite_point(contact.closest_robot_base)) {
    return stop(ReasonCode::non_finite_input, "invalid contact");
  }
  if (contact.inside) return stop(ReasonCode::inside_robot, "inside robot");
  if (!(d >= params.stop_distance_m)) return stop(ReasonCode::in_stop_zone, "in stop zone");
  if (!(d >= params.slow_distance_m)) {
    // Linear from 0 at stop_distance_m to 1 at slow_distance_m; config keeps slow > stop, and
    // the clamp keeps a degenerate span from giving a scale outside [0, 1] or NaN.
    const float span = params.slow_distance_m - params.stop_distance_m;
    const float scale = span > 0.0F ? (d - params.stop_distance_m) / span : 0.0F;
    return make_verdict(VerdictState::slow, std::clamp(scale, 0.0F, 1.0F), params.slow_distance_m,
                        ReasonCode::in_slow_zone, "in slow zone");
  }
  return run(ReasonCode::clear, "clear");
}

namespace {

int strictness(VerdictState state) { return verdict_strictness(state); }

Verdict ssm_verdict(const SafetyParams& params, const VerdictInput& input, float distance_m,
                    std::optional<SsmTerms>& terms) {
  SsmInput ssm;
  ssm.distance_m = distance_m;
  ssm.frame_age_s = input.frame_age_s;
  ssm.robot_speed_mps = input.robot_speed_towards_mps;
  ssm.distance_uncertainty_m = input.distance_uncertainty_m;
  ssm.robot_state_gap_s = input.robot_state_gap_s;
  terms = protective_distance(params.ssm, ssm, input.robot_speed_towards_mps);
  // NaN anywhere (an unknown speed or uncertainty) is a stop.
  if (!std::isfinite(terms->protective_distance_m) || !std::isfinite(input.robot_speed_towards_mps)) {
    return make_verdict(VerdictState::stop, 0.0F, terms->protective_distance_m, ReasonCode::non_finite_input,
                        "invalid ssm input");
  }
  // Below S_p at the present speed no speed helps: the robot has not reacted yet, and braking
  // to any lower speed is never shorter than stopping (docs/SAFETY.md).
  const double allowed = allowed_robot_speed_mps(params.ssm, ssm);
  if (!(allowed >= 0.0)) {
    return make_verdict(VerdictState::stop, 0.0F, terms->protective_distance_m,
                        ReasonCode::below_protective_distance, "below S_p");
  }
  // The speed the scale aims at (≤ allowed: slows before a stop), solved once; as
  // ssm_speed_scale, a robot standing still or moving away outside S_p(0) gets 1.
  const double planned = planned_robot_speed_mps(params.ssm, ssm);
  const double v_r = input.robot_speed_towards_mps;
  float scale = v_r > 0.0 ? static_cast<float>(std::min(1.0, planned / v_r)) : 1.0F;
  // The scale is of the programmed speed: the robot runs at robot_speed_scaling of it now (the
  // slider we set earlier times the controller's own reduction). Below 1 % (a robot we stopped,
  // or one paused) the present speed says nothing of the programmed one, and the arm's fastest,
  // robot_max_speed_mps, counts: told 1, it could resume at any speed.
  const double running = input.robot_speed_scaling;
  if (running > 0.01 && running < 1.0 && input.robot_speed_towards_mps > 0.0F) {
    const double programmed_mps = input.robot_speed_towards_mps / running;
    scale = static_cast<float>(std::clamp(planned / programmed_mps, 0.0, 1.0));
  } else if (!(running > 0.01)) {
    scale = static_cast<float>(std::clamp(planned / params.ssm.robot_max_speed_mps, 0.0, 1.0));
  }
  if (scale >= 1.0F) {
    return make_verdict(VerdictState::run, 1.0F, terms->protective_distance_m, ReasonCode::clear, "clear");
  }
  return make_verdict(VerdictState::slow, scale, terms->protective_distance_m, ReasonCode::speed_limited,
                      "speed limited");
}

}  // namespace

double robot_speed_fraction(const Measurement& m, double scale_sent) {
  // What the robot says of its speed, else what it was told last (a robot that obeys runs at
  // the last scale sent; one that does not runs faster, and the scale then comes out lower).
  const double read = m.robot_state.speed_fraction;
  if (read >= 0.0 && read <= 1.0) return read;
  return scale_sent >= 0.0 && scale_sent <= 1.0 ? scale_sent : 1.0;
}

VerdictInput verdict_input(const Measurement& m, const LinkContact* link, double frame_age_s, double scale_sent) {
  VerdictInput input;
  input.contact = link != nullptr ? link->contact : m.contact;
  input.foreground_points = m.foreground_points;
  if (link != nullptr) {
    input.distance_uncertainty_m = link->distance_uncertainty_m;
    input.robot_speed_towards_mps = link->speed_towards_mps;
  } else {
    // The overall pair alone says nothing of the robot's speed or the contact's uncertainty:
    // NaN, which the ssm mode turns into a stop.
    input.distance_uncertainty_m = std::numeric_limits<float>::quiet_NaN();
    input.robot_speed_towards_mps = std::numeric_limits<float>::quiet_NaN();
  }
  input.unknown_distance_m = m.unknown_distance_m;
  input.frame_age_s = frame_age_s;
  input.robot_speed_scaling = robot_speed_fraction(m, scale_sent);
  input.robot_state_gap_s = robot_state_gap_s(m);
  return input;
}

double robot_state_gap_s(const Measurement& m) {
  const double gap_s = m.robot_state_age_ms * 1e-3 - static_cast<double>(m.robot_state.extrapolated_ns) * 1e-9;
  return gap_s > 0.0 ? gap_s : 0.0;
}

Decision decide_verdict(const SafetyParams& params, const VerdictInput& input, float distance_margin_m) {
  Decision decision;
  Contact contact = input.contact;
  if (contact.valid) contact.distance_m = std::max(0.0F, contact.distance_m - distance_margin_m);
  // The checks of the contact itself (none, invalid, inside) are the same in both modes.
  decision.verdict = verdict_for_contact(params, contact, input.foreground_points);
  const bool measured = contact.valid && decision.verdict.code != ReasonCode::non_finite_input &&
                        decision.verdict.code != ReasonCode::inside_robot;
  if (params.mode == SafetyParams::Mode::ssm && measured) {
    decision.verdict = ssm_verdict(params, input, contact.distance_m, decision.ssm);
  } else if (params.mode == SafetyParams::Mode::ssm && decision.verdict.code == ReasonCode::inside_robot) {
    // A stop either way; it reports S_p of a person at 0 m, not the zones' stop distance.
    decision.verdict.protective_distance_m = ssm_verdict(params, input, 0.0F, decision.ssm).protective_distance_m;
  } else if (params.mode == SafetyParams::Mode::ssm && !contact.valid) {
    // Nobody there: S_p at rest for a person at walking speed, where one who appears stops the robot.
    SsmInput far;
    far.distance_m = std::numeric_limits<float>::infinity();
    far.frame_age_s = input.frame_age_s;
    far.robot_state_gap_s = input.robot_state_gap_s;
    decision.verdict.protective_distance_m = protective_distance(params.ssm, far, 0.0F).protective_distance_m;
  }
  decision.unknown_margin_m = unknown_margin_m(params, input.unknown_distance_m, decision.verdict);
  apply_unknown_policy(params, input.unknown_distance_m, distance_margin_m, decision.verdict);
  return decision;
}

float unknown_margin_m(const SafetyParams& params, float unknown_distance_m, const Verdict& verdict) {
  const float protective_m =
      params.mode == SafetyParams::Mode::ssm ? verdict.protective_distance_m : params.stop_distance_m;
  return unknown_distance_m - protective_m;  // NaN without unknown space
}

void apply_unknown_policy(const SafetyParams& params, float unknown_distance_m, float distance_margin_m,
                          Verdict& verdict) {
  if (verdict.state == VerdictState::stop) return;
  bool stop = false;
  if (params.unknown_policy == SafetyParams::UnknownPolicy::stop_within_m) {
    stop = unknown_distance_m <= params.unknown_stop_within_m + distance_margin_m;
  } else if (params.unknown_policy == SafetyParams::UnknownPolicy::stop_within_protective) {
    // NaN (no unknown space) fails the comparison: nothing hidden, no stop.
    stop = unknown_margin_m(params, unknown_distance_m, verdict) < distance_margin_m;
  }
  if (stop) {
    verdict = make_verdict(VerdictState::stop, 0.0F, verdict.protective_distance_m, ReasonCode::unknown_space,
                           "unknown space");
  }
}

void VerdictHold::apply(const SafetyParams& params, const VerdictInput& input, int64_t time_ns, Decision& decision) {
  // The margin's decision is needed only to relax; made here for the single-contact callers.
  apply(params, decide_verdict(params, input, params.hysteresis_m), time_ns, decision);
}

void VerdictHold::apply(const SafetyParams& params, const Decision& with_margin, int64_t time_ns, Decision& decision) {
  Verdict& verdict = decision.verdict;
  if (!have_ || strictness(verdict.state) >= strictness(held_)) {
    // As strict or stricter: taken at once, and the hold starts again from this frame.
    have_ = true;
    held_ = verdict.state;
    since_ns_ = time_ns;
    held_scale_ = verdict.speed_scale;
    return;
  }
  // More relaxed. It must have been so for min_hold_s, and hold with the distance less the
  // hysteresis; it relaxes only as far as that stricter reading allows.
  const double held_s = static_cast<double>(time_ns - since_ns_) * 1e-9;
  const VerdictState target = strictness(with_margin.verdict.state) > strictness(verdict.state)
                                  ? with_margin.verdict.state
                                  : verdict.state;
  if (held_s >= params.min_hold_s && strictness(target) < strictness(held_)) {
    held_ = target;
    since_ns_ = time_ns;
    if (target != verdict.state) {  // only as far as the hysteresis allows
      held_scale_ = with_margin.verdict.speed_scale;
      verdict.state = target;
      verdict.speed_scale = held_scale_;
      verdict.code = ReasonCode::holding;
      verdict.reason = "holding";
    } else {
      held_scale_ = verdict.speed_scale;
    }
    return;
  }
  // Held: the stricter state stays, at its last speed scale (never above the frame's own).
  verdict.state = held_;
  verdict.speed_scale = held_ == VerdictState::stop ? 0.0F : std::min(held_scale_, verdict.speed_scale);
  verdict.code = ReasonCode::holding;
  verdict.reason = "holding";
}

Verdict stop_verdict(ReasonCode code, std::string reason) {
  Verdict verdict;
  verdict.state = VerdictState::stop;
  verdict.speed_scale = 0.0F;
  verdict.code = code;
  // A stop must always say why: without details, the code's name says it.
  verdict.reason = reason.empty() ? std::string(reason_code_name(code)) : std::move(reason);
  return verdict;
}

const char* reason_code_name(ReasonCode code) {
  switch (code) {
    case ReasonCode::clear: return "clear";
    case ReasonCode::no_foreground: return "no_foreground";
    case ReasonCode::in_slow_zone: return "in_slow_zone";
    case ReasonCode::in_stop_zone: return "in_stop_zone";
    case ReasonCode::inside_robot: return "inside_robot";
    case ReasonCode::non_finite_input: return "non_finite_input";
    case ReasonCode::learning_background: return "learning_background";
    case ReasonCode::checking_background: return "checking_background";
    case ReasonCode::no_valid_depth: return "no_valid_depth";
    case ReasonCode::low_valid_share: return "low_valid_share";
    case ReasonCode::background_mismatch: return "background_mismatch";
    case ReasonCode::no_robot_model: return "no_robot_model";
    case ReasonCode::no_robot_state: return "no_robot_state";
    case ReasonCode::robot_state_stale: return "robot_state_stale";
    case ReasonCode::foreground_failed: return "foreground_failed";
    case ReasonCode::stale_frame: return "stale_frame";
    case ReasonCode::no_frame: return "no_frame";
    case ReasonCode::source_ended: return "source_ended";
    case ReasonCode::frame_limit_reached: return "frame_limit_reached";
    case ReasonCode::stop_requested: return "stop_requested";
    case ReasonCode::source_error: return "source_error";
    case ReasonCode::processing_error: return "processing_error";
    case ReasonCode::output_error: return "output_error";
    case ReasonCode::camera_disconnected: return "camera_disconnected";
    case ReasonCode::unknown_space: return "unknown_space";
    case ReasonCode::envelope_invalid: return "envelope_invalid";
    case ReasonCode::camera_blocked: return "camera_blocked";
    case ReasonCode::camera_moved: return "camera_moved";
    case ReasonCode::below_protective_distance: return "below_protective_distance";
    case ReasonCode::speed_limited: return "speed_limited";
    case ReasonCode::holding: return "holding";
    case ReasonCode::background_not_empty: return "background_not_empty";
    case ReasonCode::camera_stale: return "camera_stale";
    case ReasonCode::camera_pose_mismatch: return "camera_pose_mismatch";
  }
  return "unknown";
}

int verdict_strictness(VerdictState state) {
  switch (state) {
    case VerdictState::run: return 0;
    case VerdictState::slow: return 1;
    case VerdictState::stop: return 2;
  }
  return 2;
}

const char* unknown_policy_name(SafetyParams::UnknownPolicy policy) {
  switch (policy) {
    case SafetyParams::UnknownPolicy::report: return "report";
    case SafetyParams::UnknownPolicy::stop_within_m: return "stop_within_m";
    case SafetyParams::UnknownPolicy::stop_within_protective: return "stop_within_protective";
  }
  return "report";
}

const char* verdict_name(VerdictState state) {
  switch (state) {
    case VerdictState::run: return "run";
    case VerdictState::slow: return "slow";
    case VerdictState::stop: return "stop";
  }
  return "stop";
}

}  // namespace hrcsense
