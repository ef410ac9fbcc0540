// SPDX-License-Identifier: Apache-2.0
// hrcsense — a synthetic person-shaped point cloud of any size, as a depth camera sees it, with
// a robot point and an eight-capsule arm beside the person: the input of the proximity
// benchmarks and of `hrcsense eval`'s Table 4.4 study, which needs clouds up to 10^6 points
// (more than the simulator's 921,600 pixels).
#pragma once

#include "hrcsense/types.hpp"

#include <cstddef>

namespace hrcsense {

/// `n` points on the camera-facing surface of a person (capsules and spheres for torso, head,
/// arms, legs) standing ~2 m in front of the camera (camera frame = base frame), in depth-image
/// order (row by row), as the foreground stage emits them. Deterministic.
PointCloud person_cloud(size_t n);

/// The walk demo's robot point (-0.3, 0.3, 1.6) m, 0.27 m from the person's forward left hand.
RobotModel person_cloud_robot_point();

/// An eight-capsule arm (links like a UR5's, radii 0.04-0.08 m) reaching toward the person.
RobotModel person_cloud_robot_arm8();

}  // namespace hrcsense
