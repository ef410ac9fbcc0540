// SPDX-License-Identifier: Apache-2.0
// hrcsense proximity — the point-to-capsule distance every backend evaluates, the lower bounds
// the pruned searches skip with, and the tie rule; internal to src/proximity/.
#pragma once

#include "hrcsense/types.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace hrcsense::proximity_detail {

inline constexpr float kInf = std::numeric_limits<float>::infinity();

// A capsule's segment reduced to what the inner loops need. The reciprocal of |ab|² is 0 for a
// degenerate segment (a == b), which pins t to 0 and so makes the capsule a sphere around a.
struct Segment {
  float ax, ay, az;
  float abx, aby, abz;
  float inv_len2;
  float radius_m;
  bool is_point;  ///< a == b: the cheaper point kernel gives the same d2 bit for bit
};

inline Segment make_segment(const Capsule& capsule) {
  const Eigen::Vector3f ab = capsule.b - capsule.a;
  const float len2 = ab.squaredNorm();
  return {capsule.a.x(), capsule.a.y(), capsule.a.z(), ab.x(), ab.y(), ab.z(),
          len2 > 0.0F ? 1.0F / len2 : 0.0F, capsule.radius_m, len2 == 0.0F};
}

// Squared distance from (px, py, pz) to the capsule's segment (its axis). Every backend
// evaluates exactly this expression, so all of them see the same float distance per pair:
// no fast-math and no FMA contraction (see the proximity target's compile options).
inline float axis_distance_sq(const Segment& s, float px, float py, float pz) {
  const float apx = px - s.ax;
  const float apy = py - s.ay;
  const float apz = pz - s.az;
  float t = (apx * s.abx + apy * s.aby + apz * s.abz) * s.inv_len2;
  // Clamp t to [0, 1] with arithmetic instead of selects: GCC turns the selects into long
  // blend chains (or keeps the loop scalar) unless fast-math drops NaN handling. max(t, 0) is
  // exact; min(., 1) may move t by one float step near 0, which shifts the closest point
  // along the segment and changes d2 only to second order.
  t = 0.5F * (t + std::fabs(t));
  t = 1.0F - 0.5F * ((1.0F - t) + std::fabs(1.0F - t));
  const float dx = apx - t * s.abx;
  const float dy = apy - t * s.aby;
  const float dz = apz - t * s.abz;
  return dx * dx + dy * dy + dz * dz;
}

// The same value for a degenerate segment: with ab = 0, t * ab is +0 and apx - 0 is apx.
inline float point_distance_sq(const Segment& s, float px, float py, float pz) {
  const float dx = px - s.ax;
  const float dy = py - s.ay;
  const float dz = pz - s.az;
  return dx * dx + dy * dy + dz * dz;
}

// Surface distance from the squared axis distance: 0 inside. Monotone in d2 (sqrt is
// correctly rounded), so the minimum of d2 gives the minimum surface distance exactly. NaN
// stays NaN (std::max keeps its first argument when the comparison fails), so a point with a
// NaN coordinate never wins and never counts as inside.
inline float surface_distance(const Segment& s, float d2) {
  const float d = std::sqrt(d2) - s.radius_m;
  return std::max(d, 0.0F);
}

// Smallest squared axis distance over points [0, n). No sqrt in the loop (errno would keep it
// scalar); points with NaN coordinates never compare less and are ignored. +inf for none.
inline float min_axis_distance_sq(const Segment& s, const float* x, const float* y, const float* z,
                                  size_t n) {
  float best = kInf;
  if (s.is_point) {
#pragma omp simd reduction(min : best)
    for (size_t i = 0; i < n; ++i) {
      const float d2 = point_distance_sq(s, x[i], y[i], z[i]);
      best = d2 < best ? d2 : best;
    }
  } else {
#pragma omp simd reduction(min : best)
    for (size_t i = 0; i < n; ++i) {
      const float d2 = axis_distance_sq(s, x[i], y[i], z[i]);
      best = d2 < best ? d2 : best;
    }
  }
  return best;
}

// An axis-aligned box of points; empty (min > max) until a point is added.
struct Box {
  float min[3] = {kInf, kInf, kInf};
  float max[3] = {-kInf, -kInf, -kInf};

  void add(const Box& other) {
    for (int k = 0; k < 3; ++k) {
      min[k] = std::min(min[k], other.min[k]);
      max[k] = std::max(max[k], other.max[k]);
    }
  }
};

// Tight box of points [0, n), vectorised. NaN coordinates are skipped by the comparisons.
inline Box bounding_box(const float* x, const float* y, const float* z, size_t n) {
  float x0 = kInf, y0 = kInf, z0 = kInf, x1 = -kInf, y1 = -kInf, z1 = -kInf;
#pragma omp simd reduction(min : x0, y0, z0) reduction(max : x1, y1, z1)
  for (size_t i = 0; i < n; ++i) {
    x0 = x[i] < x0 ? x[i] : x0;
    y0 = y[i] < y0 ? y[i] : y0;
    z0 = z[i] < z0 ? z[i] : z0;
    x1 = x[i] > x1 ? x[i] : x1;
    y1 = y[i] > y1 ? y[i] : y1;
    z1 = z[i] > z1 ? z[i] : z1;
  }
  Box box;
  box.min[0] = x0, box.min[1] = y0, box.min[2] = z0;
  box.max[0] = x1, box.max[1] = y1, box.max[2] = z1;
  return box;
}

// A capsule prepared for box lower bounds: its segment and the segment's own box.
struct CapsuleBound {
  Segment segment;
  Box axis_box;
};

inline CapsuleBound make_bound(const Capsule& capsule) {
  CapsuleBound b{make_segment(capsule), Box{}};
  for (int k = 0; k < 3; ++k) {
    b.axis_box.min[k] = std::min(capsule.a[k], capsule.b[k]);
    b.axis_box.max[k] = std::max(capsule.a[k], capsule.b[k]);
  }
  return b;
}

// A lower bound (before rounding slack) of the surface distance from any point in `box` to the
// capsule: the larger of the box-to-segment-box gap and (centre to axis) - half diagonal, each
// minus the radius. Both follow from the triangle inequality; may be negative.
inline float lower_bound_m(const CapsuleBound& c, const Box& box) {
  float gap2 = 0.0F;
  float half_diag2 = 0.0F;
  float centre[3];
  for (int k = 0; k < 3; ++k) {
    const float gap = std::max({0.0F, c.axis_box.min[k] - box.max[k], box.min[k] - c.axis_box.max[k]});
    gap2 += gap * gap;
    centre[k] = 0.5F * (box.min[k] + box.max[k]);
    const float half = 0.5F * (box.max[k] - box.min[k]);
    half_diag2 += half * half;
  }
  const float by_centre = std::sqrt(axis_distance_sq(c.segment, centre[0], centre[1], centre[2])) -
                          std::sqrt(half_diag2);
  return std::max(std::sqrt(gap2), by_centre) - c.segment.radius_m;
}

// The smallest of lower_bound_m over every capsule: no point in `box` is nearer to the arm.
inline float min_lower_bound_m(const std::vector<CapsuleBound>& capsules, const Box& box) {
  float lb = kInf;
  for (const CapsuleBound& c : capsules) lb = std::min(lb, lower_bound_m(c, box));
  return lb;
}

// How far a float lower bound may lie above the float distance it bounds: rounding in the
// bound and in axis_distance_sq, relative to the distances and the capsule's size. Generous by
// orders of magnitude for coordinates within ±100 m, so a pruned box never holds a point at (or
// tied with) the best distance.
inline float bound_slack_m(float best_m, float radius_m) { return 1e-5F + 1e-4F * (best_m + radius_m); }

// True when a box whose lower bound is `lb_m` cannot hold a point at distance <= best_m.
inline bool prunable(float lb_m, float best_m, float radius_m) {
  return lb_m > best_m + bound_slack_m(best_m, radius_m);
}

// The running best contact and the tie rule shared by every backend: smallest float surface
// distance, then the lowest point index, then the lowest capsule index.
struct Best {
  float distance_m = kInf;
  size_t point = std::numeric_limits<size_t>::max();
  size_t capsule = std::numeric_limits<size_t>::max();

  bool found() const { return point != std::numeric_limits<size_t>::max(); }
  bool better(float d, size_t i, size_t c) const {
    if (d != distance_m) return d < distance_m;
    return i != point ? i < point : c < capsule;
  }
  void offer(float d, size_t i, size_t c) {
    if (better(d, i, c)) *this = {d, i, c};
  }
};

// The contact for a best pair: points, robot point on the surface, link, pixel.
Contact make_contact(const Best& best, const PointCloud& points_base, const PointCloud& points_camera,
                     const RobotModel& robot);

}  // namespace hrcsense::proximity_detail
