// SPDX-License-Identifier: Apache-2.0
// Benchmark inputs for proximity: a person-shaped cloud as a depth camera sees it, a robot
// point and an eight-capsule arm beside the person.
#pragma once

#include "hrcsense/types.hpp"

#include <cstddef>

namespace hrcsense::bench {

/// `n` points on the camera-facing surface of a person (capsules and spheres for torso, head,
/// arms, legs) standing ~2 m in front of the camera (camera frame = base frame), in depth-image
/// order (row by row), as the foreground stage emits them. Deterministic.
PointCloud person_cloud(size_t n);

/// The walk demo's robot point (-0.3, 0.3, 1.6) m, ~0.3-0.6 m from the person.
RobotModel robot_point();

/// An eight-capsule arm (links like a UR5's, radii 0.04-0.08 m) reaching toward the person.
RobotModel robot_arm8();

}  // namespace hrcsense::bench
