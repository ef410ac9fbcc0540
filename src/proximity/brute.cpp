// SPDX-License-Identifier: Apache-2.0
// hrcsense — exact closest contact between a foreground cloud and robot capsules, brute force.

#include "hrcsense/proximity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

namespace hrcsense {
namespace {

// A capsule's segment reduced to what the inner loop needs. The reciprocal of |ab|² is 0 for a
// degenerate segment (a == b), which pins t to 0 and so makes the capsule a sphere around a.
struct Segment {
  float ax, ay, az;
  float abx, aby, abz;
  float inv_len2;
  float radius_m;
};

Segment make_segment(const Capsule& capsule) {
  const Eigen::Vector3f ab = capsule.b - capsule.a;
  const float len2 = ab.squaredNorm();
  return {capsule.a.x(), capsule.a.y(), capsule.a.z(), ab.x(), ab.y(), ab.z(),
          len2 > 0.0F ? 1.0F / len2 : 0.0F, capsule.radius_m};
}

// Squared distance from (px, py, pz) to the capsule's segment (its axis). The vectorised and
// the scalar pass both evaluate this expression and must agree bit for bit: no fast-math and
// no FMA contraction (see the proximity target's compile options).
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

// Surface distance from the squared axis distance: 0 inside. Monotone in d2 (sqrt is
// correctly rounded), so the minimum of d2 gives the minimum surface distance exactly.
inline float surface_distance(const Segment& s, float d2) {
  const float d = std::sqrt(d2) - s.radius_m;
  return d > 0.0F ? d : 0.0F;
}

// Smallest squared axis distance of any point. The loop has no sqrt (which would keep it
// scalar because of errno) and no fast-math: points with NaN coordinates never compare less
// and are ignored. +inf when there is no finite point.
float min_axis_distance_sq(const Segment& s, const float* x, const float* y, const float* z,
                           size_t n) {
  float best = std::numeric_limits<float>::infinity();
#pragma omp simd reduction(min : best)
  for (size_t i = 0; i < n; ++i) {
    const float d2 = axis_distance_sq(s, x[i], y[i], z[i]);
    best = d2 < best ? d2 : best;
  }
  return best;
}

// Lowest point index whose surface distance equals `target_m` exactly; n when none does.
// Several points can share the reported (float) distance, e.g. all points inside the capsule
// at 0. Blocks whose smallest d2 is clearly beyond the target (by a slack far above float
// rounding) are skipped with the vectorised loop; only the block with the hit is scanned.
size_t first_index_at(const Segment& s, const float* x, const float* y, const float* z, size_t n,
                      float target_m) {
  constexpr size_t kBlock = 256;
  const float reach_m = target_m + s.radius_m;
  const float bound_sq = reach_m * reach_m * 1.0001F + 1e-12F;
  for (size_t begin = 0; begin < n; begin += kBlock) {
    const size_t end = std::min(n, begin + kBlock);
    if (!(min_axis_distance_sq(s, x + begin, y + begin, z + begin, end - begin) <= bound_sq)) continue;
    for (size_t i = begin; i < end; ++i) {
      const float d2 = axis_distance_sq(s, x[i], y[i], z[i]);
      if (d2 <= bound_sq && surface_distance(s, d2) == target_m) return i;
    }
  }
  return n;
}

}  // namespace

float point_capsule_distance(const Eigen::Vector3f& p, const Capsule& capsule,
                             Eigen::Vector3f* closest_on_capsule) {
  const Segment s = make_segment(capsule);
  const float distance_m = surface_distance(s, axis_distance_sq(s, p.x(), p.y(), p.z()));
  if (closest_on_capsule != nullptr) {
    const Eigen::Vector3f ab = capsule.b - capsule.a;
    float t = (p - capsule.a).dot(ab) * s.inv_len2;
    t = std::clamp(t, 0.0F, 1.0F);
    const Eigen::Vector3f on_axis = capsule.a + t * ab;
    const Eigen::Vector3f out = p - on_axis;
    const float out_norm = out.norm();
    // Inside (or exactly on the axis of a zero-radius capsule): the point itself is the contact.
    if (distance_m <= 0.0F || out_norm <= 0.0F) {
      *closest_on_capsule = distance_m <= 0.0F ? p : on_axis;
    } else {
      *closest_on_capsule = on_axis + out * (capsule.radius_m / out_norm);
    }
  }
  return distance_m;
}

Contact closest_contact_brute(const PointCloud& points_base, const PointCloud& points_camera,
                              const RobotModel& robot) {
  Contact contact;
  const size_t n = points_base.size();
  if (n == 0 || robot.capsules.empty()) return contact;
  const float* x = points_base.x.data();
  const float* y = points_base.y.data();
  const float* z = points_base.z.data();

  // Pass 1, vectorised: the minimum over all points for each capsule, then over capsules.
  // The first kMaxRemembered capsule minima are kept so that pass 2 skips capsules that do
  // not reach the overall minimum; a fixed array, so that the search never allocates.
  constexpr size_t kMaxRemembered = 64;
  std::array<float, kMaxRemembered> capsule_min_m{};
  const float inf = std::numeric_limits<float>::infinity();
  float best_m = inf;
  for (size_t c = 0; c < robot.capsules.size(); ++c) {
    const Segment s = make_segment(robot.capsules[c]);
    const float d2 = min_axis_distance_sq(s, x, y, z, n);
    const float m = d2 < inf ? surface_distance(s, d2) : inf;
    if (c < kMaxRemembered) capsule_min_m[c] = m;
    best_m = std::min(best_m, m);
  }
  if (!(best_m < std::numeric_limits<float>::infinity())) return contact;  // no finite point

  // Pass 2, the arg-min: lowest point index attaining the minimum, then lowest capsule index.
  // Only capsules whose minimum equals best_m are searched again, each up to its first hit.
  size_t best_point = n;
  size_t best_capsule = 0;
  for (size_t c = 0; c < robot.capsules.size(); ++c) {
    if (c < kMaxRemembered && capsule_min_m[c] != best_m) continue;
    const Segment s = make_segment(robot.capsules[c]);
    const size_t i = first_index_at(s, x, y, z, std::min(n, best_point + 1), best_m);
    if (i < best_point) {
      best_point = i;
      best_capsule = c;
    }
  }
  if (best_point == n) return contact;  // unreachable: pass 1 found this value

  const Capsule& capsule = robot.capsules[best_capsule];
  contact.valid = true;
  contact.distance_m = best_m;
  contact.closest_base = points_base.point(best_point);
  point_capsule_distance(contact.closest_base, capsule, &contact.closest_robot_base);
  contact.robot_link = capsule.link;
  if (points_camera.size() == n) contact.closest_camera = points_camera.point(best_point);
  if (points_base.pixel.size() == n) contact.pixel = static_cast<int>(points_base.pixel[best_point]);
  return contact;
}

}  // namespace hrcsense
