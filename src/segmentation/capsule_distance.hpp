// SPDX-License-Identifier: Apache-2.0
// hrcsense segmentation (private) — how far a point lies from the robot's capsules: the learner's
// motion region and the reference check both ask it of pixels near the arm.
#pragma once

#include "hrcsense/types.hpp"

#include <algorithm>
#include <limits>

namespace hrcsense::segmentation_detail {

/// Distance from `p` to the surface of the nearest capsule of `robot` (negative inside), base
/// frame; +infinity without capsules.
inline float distance_to_capsules(const RobotModel& robot, const Eigen::Vector3f& p) {
  float best = std::numeric_limits<float>::infinity();
  for (const Capsule& c : robot.capsules) {
    const Eigen::Vector3f ab = c.b - c.a;
    const float length2 = ab.squaredNorm();
    const float t = length2 > 0.0F ? std::clamp((p - c.a).dot(ab) / length2, 0.0F, 1.0F) : 0.0F;
    best = std::min(best, (p - (c.a + t * ab)).norm() - c.radius_m);
  }
  return best;
}

}  // namespace hrcsense::segmentation_detail
