// SPDX-License-Identifier: Apache-2.0
// hrcsense — run / slow / stop from the closest distance; anything untrusted is a stop.

#include "hrcsense/safety.hpp"

#include <algorithm>
#include <cmath>
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
  }
  return "unknown";
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
