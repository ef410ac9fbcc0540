// SPDX-License-Identifier: Apache-2.0
// hrcsense — speed and separation monitoring (ssm.hpp).

#include "hrcsense/ssm.hpp"

#include <algorithm>
#include <cmath>

namespace hrcsense {
namespace {

// NaN stays NaN (std::max would turn a NaN first argument into the second).
double non_negative(double v) { return v < 0.0 ? 0.0 : v; }

// C of ISO 13855 for detection capability d: 8·(d − 14) mm up to d = 40 mm (a hand or finger
// reaching through), not below 0; beyond 40 mm an arm reaches through, C = 850 mm.
double intrusion_distance_m(const SsmParams& params) {
  const double d = params.detection_mm;
  if (d > 40.0) return 0.85;
  return std::max(0.0, 8.0 * (d - 14.0)) * 1e-3;
}

double human_speed(const SsmParams& params, double distance_m) {
  return distance_m <= params.human_near_m ? params.human_speed_near_mps : params.human_speed_mps;
}

// S_p(v) = a + b·v + c·v²: the part that does not depend on the robot's speed, and the
// coefficients of the part that does.
struct Quadratic {
  double a = 0.0, b = 0.0, c = 0.0;
};

Quadratic protective_polynomial(const SsmParams& params, const SsmInput& input) {
  const double v_h = human_speed(params, input.distance_m);
  const double t_r = non_negative(input.frame_age_s) + params.controller_latency_s;
  const double t_0 = params.robot_stop_time_s;
  const double c_m = intrusion_distance_m(params);
  Quadratic q;
  q.a = v_h * (t_r + t_0) + c_m + non_negative(input.distance_uncertainty_m) + params.robot_uncertainty_m;
  if (params.robot_decel_mps2 > 0.0F) {
    // Braking starts after t_0 and lasts v / decel: T_s = t_0 + v/decel, S_s = v·t_0 + v²/(2·decel).
    const double decel = params.robot_decel_mps2;
    q.b = t_r + t_0 + v_h / decel;
    q.c = 0.5 / decel;
  } else {
    // Constant deceleration over the stopping time: S_s = v·t_0 / 2.
    q.b = t_r + 0.5 * t_0;
  }
  return q;
}

}  // namespace

SsmTerms protective_distance(const SsmParams& params, const SsmInput& input, float robot_speed_mps) {
  const double v_r = non_negative(robot_speed_mps);
  const double v_h = human_speed(params, input.distance_m);
  SsmTerms t;
  t.reaction_time_s = non_negative(input.frame_age_s) + params.controller_latency_s;
  const double t_0 = params.robot_stop_time_s;
  double s_s = 0.0;
  if (params.robot_decel_mps2 > 0.0F) {
    t.stop_time_s = t_0 + v_r / params.robot_decel_mps2;
    s_s = v_r * t_0 + v_r * v_r / (2.0 * params.robot_decel_mps2);
  } else {
    t.stop_time_s = t_0;
    s_s = 0.5 * v_r * t_0;
  }
  t.s_h_m = static_cast<float>(v_h * (t.reaction_time_s + t.stop_time_s));
  t.s_r_m = static_cast<float>(v_r * t.reaction_time_s);
  t.s_s_m = static_cast<float>(s_s);
  t.c_m = static_cast<float>(intrusion_distance_m(params));
  t.z_d_m = static_cast<float>(non_negative(input.distance_uncertainty_m));
  t.z_r_m = params.robot_uncertainty_m;
  t.protective_distance_m = t.s_h_m + t.s_r_m + t.s_s_m + t.c_m + t.z_d_m + t.z_r_m;
  return t;
}

double allowed_robot_speed_mps(const SsmParams& params, const SsmInput& input) {
  const Quadratic q = protective_polynomial(params, input);
  const double room = static_cast<double>(input.distance_m) - q.a;  // what is left for the robot's own terms
  if (!(room >= 0.0)) return std::isnan(room) ? room : room / q.b;  // too close even at rest: negative
  if (q.c == 0.0) return room / q.b;
  // c·v² + b·v − room = 0, the positive root, written to avoid cancellation.
  return 2.0 * room / (q.b + std::sqrt(q.b * q.b + 4.0 * q.c * room));
}

float ssm_speed_scale(const SsmParams& params, const SsmInput& input) {
  const double allowed = allowed_robot_speed_mps(params, input);
  if (!(allowed >= 0.0)) return 0.0F;  // too close at rest, or NaN
  const double v_r = input.robot_speed_mps;
  if (std::isnan(v_r)) return 0.0F;  // an unknown speed is no proof of a slow robot
  if (!(v_r > 0.0)) return 1.0F;     // standing still or moving away, and far enough at rest
  return static_cast<float>(std::min(1.0, allowed / v_r));
}

float contact_uncertainty_m(const SsmParams& params, const ContactUncertaintyInput& input) {
  const double z = input.depth_m;
  const double noise_m = kDepthNoiseSigmas * static_cast<double>(input.noise_per_z2) * z * z;
  const double footprint_m = input.fx_px > 0.0F ? 0.5 * std::sqrt(2.0) * z / input.fx_px : z;  // no focal length: a metre per metre
  const double v_h = human_speed(params, 0.0);  // the cap: the faster of the two speeds
  const double speed = std::isnan(input.contact_speed_mps) ? v_h : std::min<double>(input.contact_speed_mps, v_h);
  const double lag_m = non_negative(input.filter_lag_s) * non_negative(speed);
  return static_cast<float>(noise_m + footprint_m + lag_m);
}

}  // namespace hrcsense
