// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator's geometry: ray/shape intersections and analytic closest points.
#pragma once

#include "hrcsense/sim/sim.hpp"
#include "hrcsense/types.hpp"

#include <cmath>
#include <limits>
#include <utility>

namespace hrcsense::sim_detail {

inline constexpr float kNoHit = std::numeric_limits<float>::infinity();

// Every ray below is o + t·d with d = R·(x/z, y/z, 1): d is not normalised but has unit
// component along the optical axis, so the ray parameter t of a hit *is* its depth Z.
// Only hits with t > 0 count; a camera inside a shape sees the far side (nearest t > 0).

/// Smallest root t > 0 of a·t² + 2·half_b·t + c = 0, or kNoHit.
inline float smallest_positive_root(float a, float half_b, float c) {
  const float h = half_b * half_b - a * c;
  if (!(h >= 0.0F) || a == 0.0F) return kNoHit;
  const float s = std::sqrt(h);
  const float t0 = (-half_b - s) / a;
  if (t0 > 0.0F) return t0;
  const float t1 = (-half_b + s) / a;
  return t1 > 0.0F ? t1 : kNoHit;
}

/// Ray against the plane through `point` with normal `normal` (either side is solid surface).
inline float hit_plane(const Shape& s, const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  const float denom = s.normal.dot(d);
  if (denom == 0.0F) return kNoHit;  // parallel: the plane is seen edge-on, never hit
  const float t = s.normal.dot(s.point - o) / denom;
  return t > 0.0F ? t : kNoHit;
}

/// Ray against a sphere (centre `point`, radius `radius_m`).
inline float hit_sphere(const Eigen::Vector3f& centre, float radius_m, const Eigen::Vector3f& o,
                        const Eigen::Vector3f& d) {
  const Eigen::Vector3f oc = o - centre;
  return smallest_positive_root(d.dot(d), d.dot(oc), oc.dot(oc) - radius_m * radius_m);
}

/// Ray against an axis-aligned box, slab method. Division by a zero direction component gives
/// ±inf, which the min/max handle; a ray exactly in a face plane counts as a miss.
inline float hit_box(const Shape& s, const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  float t_near = -kNoHit;
  float t_far = kNoHit;
  for (int k = 0; k < 3; ++k) {
    const float inv = 1.0F / d[k];
    float t1 = (s.min[k] - o[k]) * inv;
    float t2 = (s.max[k] - o[k]) * inv;
    if (t1 > t2) std::swap(t1, t2);
    t_near = t1 > t_near ? t1 : t_near;
    t_far = t2 < t_far ? t2 : t_far;
  }
  if (!(t_near <= t_far) || !(t_far > 0.0F)) return kNoHit;
  return t_near > 0.0F ? t_near : t_far;
}

/// Ray against a capsule: the cylinder around segment ab where the foot of the hit lies inside
/// the segment, and the two end spheres; the nearest of them.
inline float hit_capsule(const Shape& s, const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  const Eigen::Vector3f ba = s.b - s.a;
  const Eigen::Vector3f oa = o - s.a;
  const float baba = ba.dot(ba);
  float best = kNoHit;
  if (baba > 0.0F) {
    // |oa + t·d|² − ((oa + t·d)·ba)²/|ba|² = r², multiplied by |ba|².
    const float bad = ba.dot(d);
    const float baoa = ba.dot(oa);
    const float a = baba * d.dot(d) - bad * bad;
    const float half_b = baba * d.dot(oa) - baoa * bad;
    const float c = baba * oa.dot(oa) - baoa * baoa - s.radius_m * s.radius_m * baba;
    const float t = smallest_positive_root(a, half_b, c);
    if (t < kNoHit) {
      const float foot = baoa + t * bad;
      if (foot >= 0.0F && foot <= baba) best = t;
    }
  }
  const float ta = hit_sphere(s.a, s.radius_m, o, d);
  const float tb = hit_sphere(s.b, s.radius_m, o, d);
  best = ta < best ? ta : best;
  return tb < best ? tb : best;
}

/// Closest pair between one scene shape and one robot capsule, both in the base frame.
struct ClosestPair {
  float distance_m = kNoHit;                     ///< surface to surface, 0 when they overlap
  Eigen::Vector3f on_shape = Eigen::Vector3f::Zero();  ///< point on the shape's surface
  Eigen::Vector3f on_robot = Eigen::Vector3f::Zero();  ///< point on the capsule's surface
};

/// Exact for planes, spheres and capsules. Boxes against a capsule with a non-degenerate
/// segment minimise the (convex) distance along the segment by golden-section search, exact
/// to about 1e-6 of the segment's length; against a robot point it is exact.
ClosestPair closest_shape_capsule(const Shape& shape, const Capsule& capsule);

/// The ground truth's contact over the rendered points: every point against every capsule, in
/// double precision, by a plain loop that shares nothing with src/proximity, whose searches the
/// tests hold against it. Ties keep the lowest point, then the lowest capsule. Invalid when
/// the cloud or the robot is empty.
Contact rendered_truth_contact(const PointCloud& points_base, const PointCloud& points_camera,
                               const RobotModel& robot);

}  // namespace hrcsense::sim_detail
