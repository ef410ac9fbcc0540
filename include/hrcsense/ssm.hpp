// SPDX-License-Identifier: Apache-2.0
// hrcsense — speed and separation monitoring: the protective separation distance of
// ISO/TS 15066 (now in ISO 10218-2:2025) for one frame, its terms, and the speed scale that
// keeps the separation at or above it. Plain functions of plain values (docs/SAFETY.md).
// hrcsense is not a safety-rated device: these numbers are an aid to a rated system or a
// careful integrator, not a safety function.
#pragma once

#include <limits>
#include <vector>

namespace hrcsense {

/// One row of `safety.stopping_table`: from `speed_mps` (towards the person, at the point that
/// moves fastest) the robot stops within `distance_m` and `time_s` (its stopping data for the
/// stop category it is stopped with, at the cell's payload and extension).
struct StoppingRow {
  float speed_mps = 0.0F;
  float distance_m = 0.0F;
  double time_s = 0.0;
};

/// Where S_s and T_s come from (the header's `stopping_data`).
enum class StoppingData {
  default_time,  ///< "default": the closed form of robot_stop_time_s and robot_decel_mps2
  table,         ///< "table": safety.stopping_table
  limits,        ///< "limits": safety.stopping_limits, the robot's configured stopping limits
};
const char* stopping_data_name(StoppingData data);  ///< "default", "table", "limits"

/// `safety.*` of the `ssm` mode. Defaults and their sources: docs/SAFETY.md.
struct SsmParams {
  float human_speed_mps = 1.6F;       ///< v_h farther than human_near_m (ISO 13855's walking speed)
  float human_speed_near_mps = 2.0F;  ///< v_h within human_near_m (ISO 13855's hand speed)
  float human_near_m = 0.5F;          ///< where the nearer, faster v_h starts
  double controller_latency_s = 0.05; ///< added to the frame's age: the controller's reaction, s
  /// T_s: with robot_decel_mps2 0, the robot's stopping time (constant deceleration over it);
  /// with a deceleration, the time before braking starts. Applies at zero speed too.
  double robot_stop_time_s = 0.5;
  /// > 0: the robot brakes at this rate after robot_stop_time_s (m/s², from its stopping
  /// data); 0: stopping takes robot_stop_time_s whatever the speed.
  float robot_decel_mps2 = 0.0F;
  float detection_mm = 40.0F;         ///< d, the detection capability; C = 8·(d − 14) mm, ≥ 0, up to 40 mm; 850 mm beyond
  /// `safety.detection_range_m`: the camera distance (m, along its axis) up to which detection_mm
  /// holds for this camera and filter chain (docs/SAFETY.md, "C and the detection capability");
  /// 0: not stated. A statement for the integrator; S_p does not use it.
  float detection_range_m = 0.0F;
  float robot_uncertainty_m = 0.01F;  ///< Z_r, the robot's position uncertainty
  /// `safety.stopping_table`: rows in increasing speed; when not empty it gives S_s and T_s
  /// (robot_stop_time_s and robot_decel_mps2 are then not used). Linear between rows; below
  /// the first row the distance falls linearly to 0 at rest and the time stays the first
  /// row's; beyond the last row a constant deceleration: distance × (v/v_last)², time × v/v_last.
  std::vector<StoppingRow> stopping_table;
  /// `safety.stopping_limits`: the robot's own stopping distance and time limits (its safety
  /// configuration), which it keeps at any speed; used when > 0 and there is no table.
  float stopping_limit_distance_m = 0.0F;
  double stopping_limit_time_s = 0.0;
  StoppingData stopping_data = StoppingData::default_time;  ///< which of the above S_s comes from
  /// `safety.stopping_data_confirmed`: the integrator has checked the closed form against the
  /// robot; a live cell then starts without a table or limits.
  bool stopping_data_confirmed = false;
  /// T_r's parts beside the frame's age and controller_latency_s:
  /// one nominal frame period (an intrusion can begin just after a capture), set from the
  /// source's nominal rate by the SafetyMonitor; 0: not known.
  double frame_period_s = 0.0;
  /// `source.latency_s`: how long before its stamp the camera saw the scene (exposure,
  /// readout); default per source type (docs/SAFETY.md).
  double source_latency_s = 0.0;
  /// `safety.receiver_timeout_s`: how long the receiver of the verdict keeps the last one in
  /// force after the link goes silent (a `run` stays a `run` until then).
  double receiver_timeout_s = 0.2;
  /// `safety.robot_max_speed_mps`: the fastest any point of the arm can move (its safety
  /// configuration's TCP and elbow speed limits); Z_r grows by it over the robot state's age
  /// that extrapolation did not cover.
  float robot_max_speed_mps = 3.0F;
};

/// What one frame gives the formula.
struct SsmInput {
  float distance_m = 0.0F;        ///< the measured separation (the contact's distance)
  double frame_age_s = 0.0;       ///< the frame's age at the verdict (host time to now)
  /// v_r: the robot's speed towards the person at its closest point (m/s); negative or 0 when
  /// it moves away or stands still, which then counts as 0.
  float robot_speed_mps = 0.0F;
  float distance_uncertainty_m = 0.0F;  ///< Z_d of the contact, ≥ 0
  /// How much older the robot state is than the frame beyond what extrapolation with its
  /// joint velocities covered, s (≥ 0): the arm may have moved by robot_max_speed_mps × this.
  double robot_state_gap_s = 0.0;
};

/// How the robot stops from one speed: its stopping distance and time.
struct StopProfile {
  double distance_m = 0.0;  ///< S_s
  double time_s = 0.0;      ///< T_s
};

/// The robot's stop from `speed_mps` (≥ 0) by params' stopping data (stopping_data).
StopProfile robot_stop(const SsmParams& params, double speed_mps);

/// The protective separation distance S_p = S_h + S_r + S_s + C + Z_d + Z_r and its terms
/// (`ssm` in the output), for the robot at the speed given.
struct SsmTerms {
  float s_h_m = 0.0F;  ///< v_h · (T_r + T_s): the person's approach while the robot reacts and stops
  float s_r_m = 0.0F;  ///< v_r · T_r: the robot's travel before it reacts
  float s_s_m = 0.0F;  ///< the robot's stopping distance
  float c_m = 0.0F;    ///< intrusion distance of the detection capability
  float z_d_m = 0.0F;  ///< measurement uncertainty of the contact
  float z_r_m = 0.0F;  ///< robot position uncertainty: robot_uncertainty_m + z_r_state_m
  float z_r_state_m = 0.0F;  ///< of Z_r, the arm's possible travel over the robot state's uncovered age
  float protective_distance_m = 0.0F;  ///< their sum
  /// T_r = frame_age_s + frame_period_s + source_latency_s + controller_latency_s + receiver_timeout_s.
  double reaction_time_s = 0.0;
  double frame_age_s = 0.0;            ///< T_r's parts, s
  double frame_period_s = 0.0;
  double source_latency_s = 0.0;
  double controller_latency_s = 0.0;
  double receiver_timeout_s = 0.0;
  double stop_time_s = 0.0;            ///< T_s at this speed
};

/// S_p and its terms for `input` with the robot at `robot_speed_mps` (≥ 0; negative counts as
/// 0). NaN in, NaN out: the caller's verdict turns it into a stop.
SsmTerms protective_distance(const SsmParams& params, const SsmInput& input, float robot_speed_mps);

/// The highest robot speed v_a (m/s, towards the person) the robot may be given, or −1 when
/// none: the robot keeps its present speed v_r = input.robot_speed_mps for T_r, then brakes
/// to v_a and must still be able to stop from there. Braking to v_a and stopping from it is one
/// braking on the robot's stopping profile, which is never shorter than a stop from v_r, so
/// some v_a ≥ 0 fits only when distance ≥ S_p(v_r) (docs/SAFETY.md, "S_r at the present
/// speed"); then v_a is the largest v with S_p(v) ≤ distance, which is ≥ v_r. NaN for NaN input.
double allowed_robot_speed_mps(const SsmParams& params, const SsmInput& input);

/// The speed the scale aims at: the largest v ≤ allowed_robot_speed_mps at which the next
/// frame, one frame_period_s later, would still find the separation at S_p(v) with the person
/// v_h·period and the robot v·period nearer: S_p(v) + (v_h + v)·period ≤ distance. It slows
/// the robot before the separation reaches S_p at its present speed (which is a stop), so that
/// a robot following the scale is slowed rather than stopped. Not a safety term: the stop rule
/// is allowed_robot_speed_mps's. 0 when even v = 0 does not fit; allowed_robot_speed_mps itself
/// without a frame period or when that is negative or NaN.
double planned_robot_speed_mps(const SsmParams& params, const SsmInput& input);

/// The fraction of the robot's present speed towards the person (taken as its programmed
/// speed) that takes it to planned_robot_speed_mps, in [0, 1]: 1 when the present speed is
/// already within it, 0 when no speed keeps S_p (allowed_robot_speed_mps < 0). A robot that
/// stands still or moves away gets 1 outside S_p(0) (the scale of no speed says nothing). 0 for
/// NaN input.
float ssm_speed_scale(const SsmParams& params, const SsmInput& input);

/// What Z_d of one contact is made of (contact_uncertainty_m).
struct ContactUncertaintyInput {
  float depth_m = 0.0F;        ///< the contact's depth along the camera's z axis
  /// σ_z / z² of the camera's depth noise (1/m): subpixel RMS / (fx · baseline) for a stereo
  /// camera, else the learnt noise floor.
  float noise_per_z2 = 0.0F;
  float fx_px = 0.0F;          ///< focal length of the image the contact was found in (after decimation)
  /// The filters' lag (s): how long ago the scene the filtered depth shows is on average (the
  /// temporal filter's smoothing); 0 without a temporal filter.
  double filter_lag_s = 0.0;
  /// The contact's measured speed (m/s; NaN when not known: counts as the human speed).
  float contact_speed_mps = std::numeric_limits<float>::quiet_NaN();
};

/// How many σ of the depth noise Z_d covers. One-sided: only a contact measured farther than
/// it is matters, and the closest of many noisy points already leans towards the robot.
inline constexpr float kDepthNoiseSigmas = 2.0F;

/// Z_d, the measurement uncertainty of a contact (m): kDepthNoiseSigmas · σ_z(z), plus the
/// pixel footprint (half a pixel's diagonal at the contact's depth: the true closest point may
/// lie between two samples), plus the filter lag times the contact's speed, capped at the
/// human speed. NaN input gives NaN (a stop).
float contact_uncertainty_m(const SsmParams& params, const ContactUncertaintyInput& input);

/// In `ssm` mode `foreground.min_object_mm` may be at most this share of `safety.detection_mm`:
/// a test piece of d measures down to about 0.88·d, and smaller blobs are removed as speckle
/// (docs/SAFETY.md, "C and the detection capability"). At start (load_config) and live.
inline constexpr float kSpeckleShareOfDetection = 0.8F;

}  // namespace hrcsense
