// SPDX-License-Identifier: Apache-2.0
// hrcsense — a scripted arm motion through waypoints (robot.trajectory): the simulator's arm
// and the `sim` robot state source both read their joints from joints_at().
#include "hrcsense/robot.hpp"

#include <cmath>

namespace hrcsense {
namespace {

TrajectorySample held(const TrajectoryWaypoint& waypoint) {
  TrajectorySample out;
  out.q_rad = waypoint.q_rad;  // qd stays zero
  return out;
}

/// Velocity of the cubic at waypoint k: zero at the ends, else the central difference.
double cubic_tangent(const std::vector<TrajectoryWaypoint>& w, size_t k, size_t joint) {
  if (k == 0 || k + 1 >= w.size()) return 0.0;
  return (w[k + 1].q_rad[joint] - w[k - 1].q_rad[joint]) / (w[k + 1].t_s - w[k - 1].t_s);
}

}  // namespace

TrajectorySample joints_at(const RobotTrajectory& trajectory, double t_s) {
  const std::vector<TrajectoryWaypoint>& w = trajectory.waypoints;
  if (w.empty()) return {};
  if (w.size() == 1 || !std::isfinite(t_s)) return held(w.front());
  const double t0 = w.front().t_s;
  const double period_s = w.back().t_s - t0;
  if (trajectory.loop && period_s > 0.0) {
    double phase = std::fmod(t_s - t0, period_s);
    if (phase < 0.0) phase += period_s;  // fmod keeps the sign of a time before the first waypoint
    t_s = t0 + phase;
  }
  if (t_s < t0) return held(w.front());  // at t0 itself: the first segment's start
  if (t_s >= w.back().t_s) return held(w.back());
  size_t k = 1;  // the segment [w[k-1], w[k]) holding t_s; few waypoints, so a linear scan
  while (t_s >= w[k].t_s) ++k;
  const TrajectoryWaypoint& a = w[k - 1];
  const TrajectoryWaypoint& b = w[k];
  const double h = b.t_s - a.t_s;
  const double s = (t_s - a.t_s) / h;
  TrajectorySample out;
  for (size_t j = 0; j < static_cast<size_t>(kJointCount); ++j) {
    const double qa = a.q_rad[j];
    const double qb = b.q_rad[j];
    if (trajectory.interpolation == TrajectoryInterpolation::linear) {
      out.q_rad[j] = qa + s * (qb - qa);
      out.qd_rad_s[j] = (qb - qa) / h;
      continue;
    }
    // Cubic Hermite basis on s in [0, 1]; the tangents are scaled by the segment's length h.
    const double ma = cubic_tangent(w, k - 1, j) * h;
    const double mb = cubic_tangent(w, k, j) * h;
    const double s2 = s * s;
    const double s3 = s2 * s;
    out.q_rad[j] = (2 * s3 - 3 * s2 + 1) * qa + (s3 - 2 * s2 + s) * ma + (-2 * s3 + 3 * s2) * qb + (s3 - s2) * mb;
    out.qd_rad_s[j] =
        ((6 * s2 - 6 * s) * qa + (3 * s2 - 4 * s + 1) * ma + (-6 * s2 + 6 * s) * qb + (3 * s2 - 2 * s) * mb) / h;
  }
  return out;
}

}  // namespace hrcsense
