// SPDX-License-Identifier: Apache-2.0
// hrcsense — speed and separation monitoring: the protective separation distance of
// ISO/TS 15066 (now in ISO 10218-2:2025) for one frame, its terms, and the speed scale that
// keeps the separation at or above it. Plain functions of plain values (docs/SAFETY.md).
// hrcsense is not a safety-rated device: these numbers are an aid to a rated system or a
// careful integrator, not a safety function.
#pragma once

#include <limits>

namespace hrcsense {

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
};

/// What one frame gives the formula.
struct SsmInput {
  float distance_m = 0.0F;        ///< the measured separation (the contact's distance)
  double frame_age_s = 0.0;       ///< the frame's age at the verdict (host time to now)
  /// v_r: the robot's speed towards the person at its closest point (m/s); negative or 0 when
  /// it moves away or stands still, which then counts as 0.
  float robot_speed_mps = 0.0F;
  float distance_uncertainty_m = 0.0F;  ///< Z_d of the contact, ≥ 0
};

/// The protective separation distance S_p = S_h + S_r + S_s + C + Z_d + Z_r and its terms
/// (`ssm` in the output), for the robot at the speed given.
struct SsmTerms {
  float s_h_m = 0.0F;  ///< v_h · (T_r + T_s): the person's approach while the robot reacts and stops
  float s_r_m = 0.0F;  ///< v_r · T_r: the robot's travel before it reacts
  float s_s_m = 0.0F;  ///< the robot's stopping distance
  float c_m = 0.0F;    ///< intrusion distance of the detection capability
  float z_d_m = 0.0F;  ///< measurement uncertainty of the contact
  float z_r_m = 0.0F;  ///< robot position uncertainty
  float protective_distance_m = 0.0F;  ///< their sum
  double reaction_time_s = 0.0;        ///< T_r: frame age + controller latency
  double stop_time_s = 0.0;            ///< T_s at this speed
};

/// S_p and its terms for `input` with the robot at `robot_speed_mps` (≥ 0; negative counts as
/// 0). NaN in, NaN out: the caller's verdict turns it into a stop.
SsmTerms protective_distance(const SsmParams& params, const SsmInput& input, float robot_speed_mps);

/// The highest robot speed (m/s, towards the person) at which input.distance_m is still at
/// least S_p: the root of S_p(v) = distance (linear without a deceleration, quadratic with
/// one). Negative when even a standing robot is too close; NaN for NaN input.
double allowed_robot_speed_mps(const SsmParams& params, const SsmInput& input);

/// The fraction of the robot's present speed towards the person (taken as its programmed
/// speed) that keeps the separation at or above S_p, in [0, 1]: 1 when the present speed
/// already does; for a robot that stands still or moves away, 1 when the separation is at
/// least S_p at zero speed, else 0. 0 for NaN input.
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
