// SPDX-License-Identifier: Apache-2.0
// hrcsense — the safety verdict: run / slow / stop from the closest distance, and stop
// whenever the data cannot be trusted. No data is never "all clear".
#pragma once

#include "hrcsense/types.hpp"

#include <string>

namespace hrcsense {

struct SafetyParams {
  float slow_distance_m = 1.0F;    ///< below this: slow
  float stop_distance_m = 0.5F;    ///< below this: stop
  double max_frame_age_s = 0.5;    ///< older data, or no frame for this long: stop
};

/// Verdict for a valid frame: run when nothing is in the cell (no contact) or the contact
/// is at or beyond slow_distance_m; slow in between (speed scaled linearly); stop below
/// stop_distance_m.
Verdict verdict_for_contact(const SafetyParams& params, const Contact& contact);

/// A stop verdict with a reason (invalid frame, source failed or ended, stale data, ...).
Verdict stop_verdict(std::string reason);

/// Name used in the output: "run", "slow", "stop".
const char* verdict_name(VerdictState state);

}  // namespace hrcsense
