// SPDX-License-Identifier: Apache-2.0
// hrcsense — proximity: the foreground point closest to the robot.
#pragma once

#include "hrcsense/types.hpp"

namespace hrcsense {

/// Distance from point p to a capsule's surface (0 when inside); `closest_on_capsule`
/// receives the nearest point of the capsule's surface (p itself when inside).
float point_capsule_distance(const Eigen::Vector3f& p, const Capsule& capsule,
                             Eigen::Vector3f* closest_on_capsule = nullptr);

/// Exact closest contact by brute force over every point and capsule.
/// `points_base` in the base frame; `points_camera` (same order) fills Contact::closest_camera
/// and may be empty. Ties: the lowest point index wins, then the lowest capsule index.
/// Returns an invalid contact when the cloud or the robot is empty.
Contact closest_contact_brute(const PointCloud& points_base, const PointCloud& points_camera,
                              const RobotModel& robot);

}  // namespace hrcsense
