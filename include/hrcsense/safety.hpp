// SPDX-License-Identifier: Apache-2.0
// hrcsense — the safety verdict: run / slow / stop from the closest distance, and stop
// whenever the data cannot be trusted. No data is never "all clear".
#pragma once

#include "hrcsense/types.hpp"

#include <cstddef>
#include <string>

namespace hrcsense {

struct SafetyParams {
  float slow_distance_m = 1.0F;    ///< below this: slow
  float stop_distance_m = 0.5F;    ///< below this: stop
  double max_frame_age_s = 0.5;    ///< older data, or no frame for this long: stop
  /// Below this share of valid (non-zero) pixels after the filters the frame is a stop: the
  /// camera is covered, blinded or misconfigured (docs/CONFIG.md says why 0.2).
  float min_valid_share = 0.2F;
};

/// Verdict for a valid frame with `foreground_points` foreground points: run when there is no
/// foreground at all or the contact is at or beyond slow_distance_m; slow in between (speed
/// scaled linearly); stop below stop_distance_m, for a point inside the robot's capsules, for
/// foreground without a contact, and for a contact with a non-finite distance or point.
Verdict verdict_for_contact(const SafetyParams& params, const Contact& contact, size_t foreground_points);

/// A stop verdict with its code and a reason for people (empty: the code's name).
Verdict stop_verdict(ReasonCode code, std::string reason = {});

/// The stable snake_case name of a reason code ("in_stop_zone", "non_finite_input", ...).
const char* reason_code_name(ReasonCode code);

/// Name used in the output: "run", "slow", "stop".
const char* verdict_name(VerdictState state);

}  // namespace hrcsense
