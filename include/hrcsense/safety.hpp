// SPDX-License-Identifier: Apache-2.0
// hrcsense — the safety verdict: run / slow / stop from the closest distance, and stop
// whenever the data cannot be trusted. No data is never "all clear".
#pragma once

#include "hrcsense/ssm.hpp"
#include "hrcsense/types.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

namespace hrcsense {

struct SafetyParams {
  float slow_distance_m = 1.0F;    ///< below this: slow
  float stop_distance_m = 0.5F;    ///< below this: stop
  double max_frame_age_s = 0.5;    ///< older data, or no frame for this long: stop
  /// Below this share of valid (non-zero) pixels after the filters the frame is a stop: the
  /// camera is covered, blinded or misconfigured (docs/CONFIG.md says why 0.2).
  float min_valid_share = 0.2F;
  /// `safety.mode`: zones (slow_distance_m / stop_distance_m, the default: the thesis's rule,
  /// needing no stopping data) or ssm (the protective separation distance, `ssm` below).
  enum class Mode { zones, ssm } mode = Mode::zones;
  SsmParams ssm;  ///< the ssm mode's terms (docs/SAFETY.md)
  /// `safety.hysteresis_m`: a verdict relaxes (stop → slow → run) only once the distance clears
  /// its threshold by this much; entering a stricter state never waits. m, ≥ 0.
  float hysteresis_m = 0.0F;
  /// `safety.min_hold_s`: a stricter state is held at least this long after the last frame
  /// that asked for it. s, ≥ 0.
  double min_hold_s = 0.0;
  /// `safety.unknown_policy`: report (unknown_distance_m only) or stop_within_m.
  enum class UnknownPolicy { report, stop_within_m } unknown_policy = UnknownPolicy::report;
  float unknown_stop_within_m = 0.1F;  ///< `safety.unknown_stop_within_m`, m from the padded capsules
  /// `safety.max_frame_gap_periods`: no frame for this many nominal frame periods is a stop
  /// (`no_frame`); safety.max_frame_age_s stays the absolute ceiling.
  double max_frame_gap_periods = 2.0;
};

/// Verdict for a valid frame with `foreground_points` foreground points: run when there is no
/// foreground at all or the contact is at or beyond slow_distance_m; slow in between (speed
/// scaled linearly); stop below stop_distance_m, for a point inside the robot's capsules, for
/// foreground without a contact, and for a contact with a non-finite distance or point.
Verdict verdict_for_contact(const SafetyParams& params, const Contact& contact, size_t foreground_points);

/// What a processed frame's verdict is made of (the fields of its FrameResult).
struct VerdictInput {
  Contact contact;               ///< contact.valid false: no foreground
  size_t foreground_points = 0;
  /// Z_d of the contact (contact_uncertainty_m), m; ssm mode only (NaN: a stop).
  float distance_uncertainty_m = 0.0F;
  /// v_r: the robot's speed towards the contact at its closest point, m/s; ssm mode only.
  float robot_speed_towards_mps = 0.0F;
  float unknown_distance_m = std::numeric_limits<float>::quiet_NaN();  ///< NaN: no unknown space known
  /// The share of its programmed speed the robot runs at now (the controller's speed_scaling,
  /// slider times safety scaling, RTDE); 1 when the robot state does not say. The speed scale
  /// is a fraction of the programmed speed: v_r / robot_speed_scaling.
  double robot_speed_scaling = 1.0;
  double frame_age_s = 0.0;      ///< the frame's age at the verdict: host time to now
};

/// The VerdictInput of a processed frame's result, its age at the verdict `frame_age_s`.
VerdictInput verdict_input(const FrameResult& result, double frame_age_s);

/// The verdict and, in ssm mode with a contact, S_p's terms at the robot's present speed.
struct Decision {
  Verdict verdict;
  std::optional<SsmTerms> ssm;
};

/// The verdict of a valid frame in `params.mode`: zones (verdict_for_contact) or ssm (stop
/// below S_p at rest, `below_protective_distance`; slow with the speed scale below 1,
/// `speed_limited`; run otherwise), then the unknown-space policy. `distance_margin_m` is taken
/// off the contact's distance (the hysteresis test of VerdictHold).
Decision decide_verdict(const SafetyParams& params, const VerdictInput& input, float distance_margin_m = 0.0F);

/// The verdict's memory over a run: entering a stricter state (run → slow → stop) is
/// immediate; relaxing waits until min_hold_s has passed since the last frame that asked for
/// the stricter state and until the frame's verdict with the distance less hysteresis_m is
/// relaxed too (it then relaxes only as far as that one). A held verdict says `holding`.
class VerdictHold {
 public:
  /// Replaces `decision` (the frame's own, from decide_verdict(params, input)) with the held
  /// one for a frame of host time `time_ns` (frames in time order).
  void apply(const SafetyParams& params, const VerdictInput& input, int64_t time_ns, Decision& decision);
  /// A stop that no frame's verdict shows (the output's watchdog stop while no result came):
  /// held as if a frame of host time `time_ns` had asked for it, so that the frames after a
  /// silence relax no faster than after any other stop.
  void stop_at(int64_t time_ns) {
    have_ = true;
    held_ = VerdictState::stop;
    since_ns_ = time_ns;
    held_scale_ = 0.0F;
  }
  /// Forgets the past (a new run).
  void reset() { have_ = false; }

 private:
  bool have_ = false;
  VerdictState held_ = VerdictState::stop;
  int64_t since_ns_ = 0;   ///< the last time a frame asked for held_ (or stricter)
  float held_scale_ = 0.0F;
};

/// A stop verdict with its code and a reason for people (empty: the code's name).
Verdict stop_verdict(ReasonCode code, std::string reason = {});

/// The stable snake_case name of a reason code ("in_stop_zone", "non_finite_input", ...).
const char* reason_code_name(ReasonCode code);

/// Name used in the output: "run", "slow", "stop".
const char* verdict_name(VerdictState state);

}  // namespace hrcsense
