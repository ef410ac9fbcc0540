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

Verdict make_verdict(VerdictState state, float speed_scale, float protective_distance_m, const char* reason) {
  Verdict verdict;
  verdict.state = state;
  verdict.speed_scale = speed_scale;
  verdict.protective_distance_m = protective_distance_m;
  verdict.reason = reason;
  return verdict;
}

bool finite_point(const Eigen::Vector3f& p) { return p.allFinite(); }

}  // namespace

Verdict verdict_for_contact(const SafetyParams& params, const Contact& contact, size_t foreground_points) {
  if (!contact.valid) {
    // Foreground that the search could not place (non-finite points, a broken pose) is not
    // "nothing in the cell": only an empty foreground is.
    if (foreground_points > 0) return make_verdict(VerdictState::stop, 0.0F, params.stop_distance_m, "no contact");
    return make_verdict(VerdictState::run, 1.0F, params.slow_distance_m, "no foreground");
  }
  const float d = contact.distance_m;
  // Every comparison below is written so that NaN falls through to stop.
  if (!std::isfinite(d) || d < 0.0F || !finite_point(contact.closest_base) ||
      !finite_point(contact.closest_robot_base)) {
    return make_verdict(VerdictState::stop, 0.0F, params.stop_distance_m, "invalid contact");
  }
  if (contact.inside) return make_verdict(VerdictState::stop, 0.0F, params.stop_distance_m, "inside robot");
  if (!(d >= params.stop_distance_m)) {
    return make_verdict(VerdictState::stop, 0.0F, params.stop_distance_m, "in stop zone");
  }
  if (!(d >= params.slow_distance_m)) {
    // Linear from 0 at stop_distance_m to 1 at slow_distance_m; config keeps slow > stop, and
    // the clamp keeps a degenerate span from giving a scale outside [0, 1] or NaN.
    const float span = params.slow_distance_m - params.stop_distance_m;
    const float scale = span > 0.0F ? (d - params.stop_distance_m) / span : 0.0F;
    return make_verdict(VerdictState::slow, std::clamp(scale, 0.0F, 1.0F), params.slow_distance_m, "in slow zone");
  }
  return make_verdict(VerdictState::run, 1.0F, params.slow_distance_m, "clear");
}

Verdict stop_verdict(std::string reason) {
  Verdict verdict;
  verdict.state = VerdictState::stop;
  verdict.speed_scale = 0.0F;
  // A stop must always say why; an empty reason would hide a bug upstream.
  verdict.reason = reason.empty() ? std::string("stop") : std::move(reason);
  return verdict;
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
