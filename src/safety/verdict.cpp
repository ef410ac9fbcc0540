// SPDX-License-Identifier: Apache-2.0
// hrcsense — run / slow / stop from the closest distance; anything untrusted is a stop.

#include "hrcsense/safety.hpp"

#include <utility>

namespace hrcsense {

// The reasons of the per-frame verdicts stay within std::string's small-buffer size (15
// characters in libstdc++), so that producing a verdict every frame does not allocate.

Verdict verdict_for_contact(const SafetyParams& params, const Contact& contact) {
  Verdict verdict;
  if (!contact.valid) {
    // A valid frame with no foreground: nothing is in the cell near the robot.
    verdict.state = VerdictState::run;
    verdict.speed_scale = 1.0F;
    verdict.protective_distance_m = params.slow_distance_m;
    verdict.reason = "no foreground";
    return verdict;
  }
  const float d = contact.distance_m;
  if (d < params.stop_distance_m) {
    verdict.state = VerdictState::stop;
    verdict.speed_scale = 0.0F;
    verdict.protective_distance_m = params.stop_distance_m;
    verdict.reason = "in stop zone";
    return verdict;
  }
  if (d < params.slow_distance_m) {
    // Linear from 0 at stop_distance_m to 1 at slow_distance_m; the guard above makes the
    // span positive here.
    verdict.state = VerdictState::slow;
    verdict.speed_scale = (d - params.stop_distance_m) / (params.slow_distance_m - params.stop_distance_m);
    verdict.protective_distance_m = params.slow_distance_m;
    verdict.reason = "in slow zone";
    return verdict;
  }
  verdict.state = VerdictState::run;
  verdict.speed_scale = 1.0F;
  verdict.protective_distance_m = params.slow_distance_m;
  verdict.reason = "clear";
  return verdict;
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
