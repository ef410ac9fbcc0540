// SPDX-License-Identifier: Apache-2.0
// hrcsense — the safety verdict: run / slow / stop from each robot link's closest pair (`zones`
// distances or the `ssm` protective separation distance), decided once per frame by the
// output thread's SafetyMonitor, and stop whenever the data cannot be trusted. No data is
// never "all clear".
#pragma once

#include "hrcsense/ssm.hpp"
#include "hrcsense/types.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

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
  /// `safety.unknown_policy`: report (unknown_distance_m and unknown_margin_m only),
  /// stop_within_m (unknown space within unknown_stop_within_m of the robot) or
  /// stop_within_protective (unknown space nearer the robot than the governing S_p).
  enum class UnknownPolicy { report, stop_within_m, stop_within_protective } unknown_policy = UnknownPolicy::report;
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
  /// The share of its programmed speed the robot runs at now: the robot state's speed_fraction
  /// (RTDE speed_scaling × target_speed_fraction, udp_json speed_fraction, the simulator's
  /// rate), else the last speed scale hrcsense sent. The speed scale is a share of the
  /// programmed speed, v_r / robot_speed_scaling.
  double robot_speed_scaling = 1.0;
  double frame_age_s = 0.0;      ///< the frame's age at the verdict: host time to now
  /// The robot state's age beyond what extrapolation covered, s (robot_state_gap_s).
  double robot_state_gap_s = 0.0;
};

/// How much older the robot state of `m` is than its frame beyond what extrapolation with the
/// joint velocities covered, s, ≥ 0 (SsmInput::robot_state_gap_s).
double robot_state_gap_s(const Measurement& m);

/// The share of its programmed speed the robot runs at for measurement `m`: its state's
/// speed_fraction when that is a reading in 0..1, else `scale_sent` (the speed scale hrcsense
/// sent last, which a robot that obeys runs at), else 1.
double robot_speed_fraction(const Measurement& m, double scale_sent);

/// The VerdictInput of one link of a measurement (`link` null: the overall contact, with no
/// speed or Z_d known), its age at the verdict `frame_age_s`. `scale_sent` (0..1) is the speed
/// scale hrcsense sent last: the robot's speed fraction when its state does not read one.
VerdictInput verdict_input(const Measurement& m, const LinkContact* link, double frame_age_s, double scale_sent);

/// The verdict and, in ssm mode with a contact, S_p's terms at the robot's present speed.
/// For a measurement (decide_measurement): those of the governing link, and which it is.
struct Decision {
  Verdict verdict;
  std::optional<SsmTerms> ssm;
  int governing_link = -1;  ///< Capsule::link of the governing link; -1 without a contact
  float distance_uncertainty_m = std::numeric_limits<float>::quiet_NaN();  ///< the governing link's Z_d
  float robot_speed_towards_mps = std::numeric_limits<float>::quiet_NaN(); ///< the governing link's v_r
  /// unknown_distance_m less the governing S_p (ssm) or safety.stop_distance_m (zones); NaN
  /// without unknown space.
  float unknown_margin_m = std::numeric_limits<float>::quiet_NaN();
};

/// The verdict of a valid frame in `params.mode`: zones (verdict_for_contact) or ssm (stop
/// below S_p at rest, `below_protective_distance`; slow with the speed scale below 1,
/// `speed_limited`; run otherwise), then the unknown-space policy. `distance_margin_m` is taken
/// off the contact's distance (the hysteresis test of VerdictHold).
Decision decide_verdict(const SafetyParams& params, const VerdictInput& input, float distance_margin_m = 0.0F);

/// The unknown distance less the protective distance of `verdict` (ssm mode: the governing
/// link's S_p; zones mode: safety.stop_distance_m); NaN without unknown space.
float unknown_margin_m(const SafetyParams& params, float unknown_distance_m, const Verdict& verdict);

/// `safety.unknown_policy`: stop_within_m turns `verdict` into a stop (`unknown_space`) when
/// unknown space lies within safety.unknown_stop_within_m (+ the margin) of the robot,
/// stop_within_protective when the unknown margin (unknown_margin_m) is below the margin.
void apply_unknown_policy(const SafetyParams& params, float unknown_distance_m, float distance_margin_m,
                          Verdict& verdict);

/// The decision on a measurement at age `frame_age_s` (s, host time to now), with no memory:
/// a withheld measurement is a stop with its own reason; otherwise every link with a contact is
/// decided on its own contact, speed towards it and Z_d (decide_verdict), and the strictest
/// link governs: stop before slow before run, then the lowest speed scale, then the smallest
/// d_i − S_p,i. The unknown-space policy applies once, after. `link_protective_distance_m`
/// (optional) receives each link's S_p at its present speed, in the order of m.links.
/// `scale_sent`: as for verdict_input. `out`'s buffers are reused.
void decide_measurement(const SafetyParams& params, const Measurement& m, double frame_age_s, double scale_sent,
                        Decision& out, float distance_margin_m = 0.0F,
                        std::vector<float>* link_protective_distance_m = nullptr);

/// The verdict's memory over a run: entering a stricter state (run → slow → stop) is
/// immediate; relaxing waits until min_hold_s has passed since the last frame that asked for
/// the stricter state and until the frame's verdict with the distance less hysteresis_m is
/// relaxed too (it then relaxes only as far as that one). A held verdict says `holding`.
class VerdictHold {
 public:
  /// Replaces `decision` (the frame's own, from decide_verdict(params, input)) with the held
  /// one for a frame of host time `time_ns` (frames in time order).
  void apply(const SafetyParams& params, const VerdictInput& input, int64_t time_ns, Decision& decision);
  /// The same with the frame's decision with the distance less hysteresis_m already made
  /// (`with_margin`; a measurement's: decide_measurement with the margin).
  /// `with_margin` may be `decision` itself (no hysteresis).
  void apply(const SafetyParams& params, const Decision& with_margin, int64_t time_ns, Decision& decision);
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

/// Turns each measurement into the verdict, the speed scale and S_p, once, where the result is
/// written (run_pipeline's output thread, immediately before the sinks): the frame's age is
/// taken at that moment, so a measurement that waited in a mailbox or through a stalled process
/// is judged at its real age. Owns the verdict's hold and the no-frame watchdog. One monitor
/// per run; not thread-safe. (Multi-camera fusion, still to come, is meant to hand the cameras'
/// measurements to one monitor.)
class SafetyMonitor {
 public:
  /// `nominal_fps` and `frames_at_a_rate` (a live or paced source) set the no-frame watchdog:
  /// safety.max_frame_age_s, or safety.max_frame_gap_periods nominal periods when shorter.
  /// `nominal_fps` > 0 also puts one nominal frame period into T_r (SsmParams::frame_period_s).
  explicit SafetyMonitor(SafetyParams params, double nominal_fps = 0.0, bool frames_at_a_rate = false);
  const SafetyParams& params() const { return params_; }
  /// Decides `result` at run-clock time `now_ns`: a stop (`stale_frame`) when it was seen
  /// (captured, for a live camera; else delivered) more than watchdog_after_ns() before (a
  /// frame older than the no-frame limit is no fresher than no frame); T_r from its seen time
  /// (Measurement::seen_ns; an age of 0 when not clocked); merged with the strictest of the
  /// measurements it replaced (FrameResult::replaced); then held (VerdictHold) on the frame's
  /// host time. Fills verdict, ssm, governing_link, the governing Z_d and v_r, frame_age_s.
  void decide(FrameResult& result, int64_t now_ns);
  /// How long the output may wait for a result before a no-frame stop (ns), and the rule that
  /// says so (e.g. "max_frame_gap_periods 2 at 30 frames/s").
  int64_t watchdog_after_ns() const { return watchdog_after_ns_; }
  const char* watchdog_rule() const { return watchdog_rule_; }
  /// The stop written when no result came for watchdog_after_ns() (reason `code`: no_frame or
  /// camera_disconnected, with `reason`); the next frame's verdict holds it (VerdictHold::stop_at
  /// at that frame's own time, later than the silence began: the cautious side).
  Verdict silence(ReasonCode code, const std::string& reason);
  /// Forgets the past (a new run).
  void reset();
  /// The speed scale of the last verdict written (1 before the first, 0 after a silence): what
  /// the links sent last, which the robot is taken to run at when its state reads no speed
  /// fraction. Safe to read from another thread (carry_replaced).
  float scale_sent() const { return scale_sent_.load(std::memory_order_relaxed); }

 private:
  SafetyParams params_;
  VerdictHold hold_;
  bool silence_pending_ = false;
  int64_t watchdog_after_ns_ = 0;
  char watchdog_rule_[64] = {};
  Decision decision_;     ///< scratch: the frame's decision (buffers circulate with the results')
  Decision with_margin_;  ///< scratch: the frame's decision with the hysteresis margin
  std::atomic<float> scale_sent_{1.0F};
};

/// Carries `replaced` (a measurement a mailbox is about to drop before anyone decided it) into
/// `next` (the one that replaces it): decided by `monitor`'s rules without its memory at
/// `now_ns` on the run's clock (stale included), and kept in next.replaced if it is the
/// strictest so far (stop before slow before run, then the lowest scale). Called by the
/// mailbox's producer under its lock; it reads only `monitor`'s constant settings, so it may
/// run on another thread than the monitor's decide().
void carry_replaced(const SafetyMonitor& monitor, const FrameResult& replaced, int64_t now_ns, FrameResult& next);

/// A stop verdict with its code and a reason for people (empty: the code's name).
Verdict stop_verdict(ReasonCode code, std::string reason = {});

/// The stable snake_case name of a reason code ("in_stop_zone", "non_finite_input", ...).
const char* reason_code_name(ReasonCode code);

/// 0 run, 1 slow, 2 stop: a larger number is the stricter state.
int verdict_strictness(VerdictState state);

/// `safety.unknown_policy`'s names: "report", "stop_within_m", "stop_within_protective".
const char* unknown_policy_name(SafetyParams::UnknownPolicy policy);

/// Name used in the output: "run", "slow", "stop".
const char* verdict_name(VerdictState state);

}  // namespace hrcsense
