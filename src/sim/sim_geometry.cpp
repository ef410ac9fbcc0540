// SPDX-License-Identifier: Apache-2.0
// hrcsense — analytic closest points between the simulator's shapes and robot capsules.

#include "sim_geometry.hpp"

#include "hrcsense/proximity.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hrcsense::sim_detail {
namespace {

/// Two rounded cores (segment or point plus radius): closest surface points.
ClosestPair closest_rounded(const Eigen::Vector3f& shape_a, const Eigen::Vector3f& shape_b, float shape_r,
                            const Capsule& capsule) {
  float s = 0.0F;
  float t = 0.0F;
  closest_segment_params(shape_a, shape_b, capsule.a, capsule.b, s, t);
  const Eigen::Vector3f on_shape_core = shape_a + s * (shape_b - shape_a);
  const Eigen::Vector3f on_robot_core = capsule.a + t * (capsule.b - capsule.a);
  const Eigen::Vector3f v = on_robot_core - on_shape_core;
  const float len = v.norm();
  ClosestPair pair;
  pair.distance_m = std::max(0.0F, len - shape_r - capsule.radius_m);
  const Eigen::Vector3f dir = len > 0.0F ? Eigen::Vector3f(v / len) : Eigen::Vector3f::Zero();
  pair.on_shape = on_shape_core + shape_r * dir;
  pair.on_robot = on_robot_core - capsule.radius_m * dir;
  return pair;
}

float box_distance(const Shape& box, const Eigen::Vector3f& q) {
  return (q - q.cwiseMax(box.min).cwiseMin(box.max)).norm();
}

/// Whether segment a + t·ab, t in [0, 1], meets the box; `t_in` receives the first such t.
bool segment_meets_box(const Shape& box, const Eigen::Vector3f& a, const Eigen::Vector3f& ab, float& t_in) {
  float lo = 0.0F;
  float hi = 1.0F;
  for (int k = 0; k < 3; ++k) {
    if (ab[k] == 0.0F) {
      if (a[k] < box.min[k] || a[k] > box.max[k]) return false;
      continue;
    }
    float t1 = (box.min[k] - a[k]) / ab[k];
    float t2 = (box.max[k] - a[k]) / ab[k];
    if (t1 > t2) std::swap(t1, t2);
    lo = std::max(lo, t1);
    hi = std::min(hi, t2);
    if (lo > hi) return false;
  }
  t_in = lo;
  return true;
}

ClosestPair closest_box(const Shape& box, const Capsule& capsule) {
  const Eigen::Vector3f ab = capsule.b - capsule.a;
  float t = 0.0F;
  float t_in = 0.0F;
  if (segment_meets_box(box, capsule.a, ab, t_in)) {
    // Overlap: the search below would stop a rounding error short of the box.
    ClosestPair pair;
    pair.distance_m = 0.0F;
    pair.on_shape = capsule.a + t_in * ab;
    pair.on_robot = pair.on_shape;
    return pair;
  }
  if (ab.squaredNorm() > 0.0F) {
    // The distance from a point to a convex set is convex, and so is its composition with
    // the affine segment, so golden-section search finds the global minimum.
    constexpr float kInvPhi = 0.618033988749895F;
    float lo = 0.0F;
    float hi = 1.0F;
    for (int i = 0; i < 40; ++i) {
      const float m1 = hi - kInvPhi * (hi - lo);
      const float m2 = lo + kInvPhi * (hi - lo);
      if (box_distance(box, capsule.a + m1 * ab) <= box_distance(box, capsule.a + m2 * ab)) {
        hi = m2;
      } else {
        lo = m1;
      }
    }
    t = 0.5F * (lo + hi);
    // The ends are candidates too: the search never evaluates exactly t = 0 or 1.
    for (const float end : {0.0F, 1.0F}) {
      if (box_distance(box, capsule.a + end * ab) < box_distance(box, capsule.a + t * ab)) t = end;
    }
  }
  const Eigen::Vector3f q = capsule.a + t * ab;
  const Eigen::Vector3f p = q.cwiseMax(box.min).cwiseMin(box.max);
  const Eigen::Vector3f v = q - p;
  const float len = v.norm();
  ClosestPair pair;
  pair.distance_m = std::max(0.0F, len - capsule.radius_m);
  pair.on_shape = p;  // q itself when q is inside the box
  pair.on_robot = len > 0.0F ? Eigen::Vector3f(q - capsule.radius_m * v / len) : q;
  return pair;
}

ClosestPair closest_plane(const Shape& plane, const Capsule& capsule) {
  const Eigen::Vector3f n = plane.normal.normalized();
  const float sa = n.dot(capsule.a - plane.point);
  const float sb = n.dot(capsule.b - plane.point);
  ClosestPair pair;
  if ((sa <= 0.0F && sb >= 0.0F) || (sa >= 0.0F && sb <= 0.0F)) {
    // The segment crosses the plane: contact where it does.
    const float t = sa == sb ? 0.0F : sa / (sa - sb);
    pair.on_shape = capsule.a + t * (capsule.b - capsule.a);
    pair.on_robot = pair.on_shape;
    pair.distance_m = 0.0F;
    return pair;
  }
  const bool a_closer = std::abs(sa) <= std::abs(sb);
  const Eigen::Vector3f q = a_closer ? capsule.a : capsule.b;
  const float sq = a_closer ? sa : sb;
  pair.on_shape = q - sq * n;
  pair.on_robot = q - std::copysign(capsule.radius_m, sq) * n;
  pair.distance_m = std::max(0.0F, std::abs(sq) - capsule.radius_m);
  return pair;
}

}  // namespace

ClosestPair closest_shape_capsule(const Shape& shape, const Capsule& capsule) {
  switch (shape.type) {
    case Shape::Type::plane:
      return closest_plane(shape, capsule);
    case Shape::Type::box:
      return closest_box(shape, capsule);
    case Shape::Type::sphere:
      return closest_rounded(shape.point, shape.point, shape.radius_m, capsule);
    case Shape::Type::capsule:
      return closest_rounded(shape.a, shape.b, shape.radius_m, capsule);
  }
  return {};
}

Contact rendered_truth_contact(const PointCloud& points_base, const PointCloud& points_camera,
                               const RobotModel& robot) {
  Contact best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < points_base.size(); ++i) {
    const Eigen::Vector3d p = points_base.point(i).cast<double>();
    for (const Capsule& capsule : robot.capsules) {
      const Eigen::Vector3d a = capsule.a.cast<double>();
      const Eigen::Vector3d ab = capsule.b.cast<double>() - a;
      const double length2 = ab.squaredNorm();
      const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
      const Eigen::Vector3d on_axis = a + t * ab;
      const double axis_distance = (p - on_axis).norm();
      const double distance = std::max(axis_distance - static_cast<double>(capsule.radius_m), 0.0);
      if (!(distance < best_distance)) continue;
      best_distance = distance;
      best.valid = true;
      best.distance_m = static_cast<float>(distance);
      best.inside = distance == 0.0;
      best.closest_base = points_base.point(i);
      // The robot's surface point towards p; inside the capsule, the point itself.
      const Eigen::Vector3d on_surface =
          best.inside ? p : on_axis + (p - on_axis) * (static_cast<double>(capsule.radius_m) / axis_distance);
      best.closest_robot_base = on_surface.cast<float>();
      best.robot_link = capsule.link;
      best.closest_camera = points_camera.size() == points_base.size() ? points_camera.point(i) : Eigen::Vector3f::Zero();
      best.pixel = points_base.pixel.size() == points_base.size() ? static_cast<int>(points_base.pixel[i]) : -1;
    }
  }
  return best;
}

}  // namespace hrcsense::sim_detail
