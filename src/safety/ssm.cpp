// SPDX-License-Identifier: Apache-2.0
// hrcsense — speed and separation monitoring (ssm.hpp).

#include "hrcsense/ssm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

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

// The stopping table at `v` (rows in increasing speed, checked by the configuration).
StopProfile table_stop(const std::vector<StoppingRow>& table, double v) {
  const StoppingRow& first = table.front();
  const StoppingRow& last = table.back();
  if (v <= first.speed_mps) {
    // Towards rest the distance falls to 0; the time stays the first row's (the person keeps
    // walking while even a slow robot stops).
    const double share = first.speed_mps > 0.0F ? v / first.speed_mps : 0.0;
    return {first.distance_m * share, first.time_s};
  }
  if (v >= last.speed_mps) {
    // Beyond the data: braking at the last row's deceleration, never a shorter stop.
    const double ratio = v / last.speed_mps;
    return {last.distance_m * ratio * ratio, last.time_s * ratio};
  }
  size_t hi = 1;
  while (table[hi].speed_mps < v) ++hi;
  const StoppingRow& a = table[hi - 1];
  const StoppingRow& b = table[hi];
  const double w = (v - a.speed_mps) / (b.speed_mps - a.speed_mps);
  return {a.distance_m + w * (b.distance_m - a.distance_m), a.time_s + w * (b.time_s - a.time_s)};
}

// T_r and its parts (everything the verdict waits for before the robot begins to react).
void reaction_time(const SsmParams& params, const SsmInput& input, SsmTerms& t) {
  t.frame_age_s = non_negative(input.frame_age_s);
  t.frame_period_s = params.frame_period_s;
  t.source_latency_s = params.source_latency_s;
  t.controller_latency_s = params.controller_latency_s;
  t.receiver_timeout_s = params.receiver_timeout_s;
  t.reaction_time_s =
      t.frame_age_s + t.frame_period_s + t.source_latency_s + t.controller_latency_s + t.receiver_timeout_s;
}

// S_p with the robot at `v` (≥ 0) before it reacts and stopping from there, without the terms'
// breakdown: what the allowed speed is solved for.
double protective_at(const SsmParams& params, const SsmInput& input, const SsmTerms& fixed, double v) {
  const StopProfile stop = robot_stop(params, v);
  const double v_h = human_speed(params, input.distance_m);
  return v_h * (fixed.reaction_time_s + stop.time_s) + v * fixed.reaction_time_s + stop.distance_m + fixed.c_m +
         fixed.z_d_m + fixed.z_r_m;
}

// S_p(v) = a + b·v + c·v² where the stopping data make it one (the closed form, the limits);
// nullopt for a table, which is piecewise.
struct Quadratic {
  double a = 0.0, b = 0.0, c = 0.0;
};

std::optional<Quadratic> protective_polynomial(const SsmParams& params, const SsmInput& input, const SsmTerms& fixed) {
  if (!params.stopping_table.empty()) return std::nullopt;
  const double v_h = human_speed(params, input.distance_m);
  const double t_r = fixed.reaction_time_s;
  const double rest_m = static_cast<double>(fixed.c_m) + fixed.z_d_m + fixed.z_r_m;
  const StopProfile at_rest = robot_stop(params, 0.0);
  Quadratic q;
  q.a = v_h * (t_r + at_rest.time_s) + at_rest.distance_m + rest_m;
  if (params.stopping_limit_distance_m > 0.0F) {
    q.b = t_r;  // the limits do not grow with speed
  } else if (params.robot_decel_mps2 > 0.0F) {
    const double decel = params.robot_decel_mps2;
    q.b = t_r + params.robot_stop_time_s + v_h / decel;  // S_r, the delay's travel, v_h · v / decel
    q.c = 0.5 / decel;
  } else {
    q.b = t_r + 0.5 * params.robot_stop_time_s;
  }
  return q;
}

// The largest v ≥ `fits_from` (a speed known to fit) with S_p(v) + (v_h + v)·look_ahead_s ≤ d:
// the positive root where S_p is a polynomial, else bisection (S_p grows with v).
double largest_fitting_speed(const SsmParams& params, const SsmInput& input, const SsmTerms& fixed,
                             double look_ahead_s, double fits_from) {
  const double d = input.distance_m;
  const double v_h = human_speed(params, input.distance_m);
  if (const std::optional<Quadratic> q = protective_polynomial(params, input, fixed)) {
    const double room = d - q->a - v_h * look_ahead_s;  // ≥ 0: fits_from fits
    const double b = q->b + look_ahead_s;
    if (q->c == 0.0) return b > 0.0 ? std::max(fits_from, room / b) : std::numeric_limits<double>::infinity();
    // c·v² + b·v − room = 0, the positive root, written to avoid cancellation.
    return std::max(fits_from, 2.0 * room / (b + std::sqrt(b * b + 4.0 * q->c * room)));
  }
  const auto fits = [&](double v) { return protective_at(params, input, fixed, v) + (v_h + v) * look_ahead_s <= d; };
  double lo = fits_from;
  double hi = std::max(1.0, 2.0 * fits_from);
  for (int k = 0; k < 16 && fits(hi); ++k) hi *= 2.0;
  if (fits(hi)) return hi;  // beyond any arm's speed
  for (int k = 0; k < 100 && hi - lo > 1e-12 * hi; ++k) {
    const double mid = 0.5 * (lo + hi);
    (fits(mid) ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace

const char* stopping_data_name(StoppingData data) {
  switch (data) {
    case StoppingData::default_time: return "default";
    case StoppingData::table: return "table";
    case StoppingData::limits: return "limits";
  }
  return "default";
}

StopProfile robot_stop(const SsmParams& params, double speed_mps) {
  const double v = non_negative(speed_mps);
  if (std::isnan(v)) return {v, v};
  if (!params.stopping_table.empty()) return table_stop(params.stopping_table, v);
  if (params.stopping_limit_distance_m > 0.0F) {
    // The robot's safety system stops it within these whatever its speed.
    return {params.stopping_limit_distance_m, params.stopping_limit_time_s};
  }
  const double t_0 = params.robot_stop_time_s;
  if (params.robot_decel_mps2 > 0.0F) {
    // Braking starts after t_0 and lasts v / decel.
    const double decel = params.robot_decel_mps2;
    return {v * t_0 + v * v / (2.0 * decel), t_0 + v / decel};
  }
  // Constant deceleration over the stopping time.
  return {0.5 * v * t_0, t_0};
}

SsmTerms protective_distance(const SsmParams& params, const SsmInput& input, float robot_speed_mps) {
  const double v_r = non_negative(robot_speed_mps);
  const double v_h = human_speed(params, input.distance_m);
  SsmTerms t;
  reaction_time(params, input, t);
  const StopProfile stop = robot_stop(params, v_r);
  t.stop_time_s = stop.time_s;
  t.s_h_m = static_cast<float>(v_h * (t.reaction_time_s + t.stop_time_s));
  t.s_r_m = static_cast<float>(v_r * t.reaction_time_s);
  t.s_s_m = static_cast<float>(stop.distance_m);
  t.c_m = static_cast<float>(intrusion_distance_m(params));
  t.z_d_m = static_cast<float>(non_negative(input.distance_uncertainty_m));
  t.z_r_state_m = static_cast<float>(params.robot_max_speed_mps * non_negative(input.robot_state_gap_s));
  t.z_r_m = params.robot_uncertainty_m + t.z_r_state_m;
  t.protective_distance_m = t.s_h_m + t.s_r_m + t.s_s_m + t.c_m + t.z_d_m + t.z_r_m;
  return t;
}

double allowed_robot_speed_mps(const SsmParams& params, const SsmInput& input) {
  const double d = input.distance_m;
  const double v_r = non_negative(input.robot_speed_mps);
  const SsmTerms at_present = protective_distance(params, input, static_cast<float>(v_r));
  if (std::isnan(d) || std::isnan(at_present.protective_distance_m)) return std::numeric_limits<double>::quiet_NaN();
  // Braking from v_r to any v_a and stopping from v_a is one braking on the robot's profile,
  // never shorter than the stop from v_r itself: below S_p(v_r) no speed helps.
  if (!(d >= at_present.protective_distance_m)) return -1.0;
  return largest_fitting_speed(params, input, at_present, 0.0, v_r);
}

double planned_robot_speed_mps(const SsmParams& params, const SsmInput& input) {
  const double allowed = allowed_robot_speed_mps(params, input);
  const double period_s = params.frame_period_s;
  if (!(allowed >= 0.0) || !(period_s > 0.0)) return allowed;
  // The next frame must find the robot at v clear of S_p(v) after the person came v_h·period
  // nearer and the robot v·period: S_p(v) + (v_h + v)·period ≤ d, which grows with v.
  const SsmTerms fixed = protective_distance(params, input, 0.0F);
  const double v_h = human_speed(params, input.distance_m);
  if (!(protective_at(params, input, fixed, 0.0) + v_h * period_s <= input.distance_m)) return 0.0;
  return std::min(allowed, largest_fitting_speed(params, input, fixed, period_s, 0.0));
}

float ssm_speed_scale(const SsmParams& params, const SsmInput& input) {
  const double allowed = planned_robot_speed_mps(params, input);
  if (!(allowed >= 0.0)) return 0.0F;  // no speed keeps S_p, or NaN
  const double v_r = input.robot_speed_mps;
  if (std::isnan(v_r)) return 0.0F;  // an unknown speed is no proof of a slow robot
  if (!(v_r > 0.0)) return 1.0F;     // standing still or moving away, and outside S_p(0)
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
