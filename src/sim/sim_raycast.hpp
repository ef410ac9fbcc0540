// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator's ray caster: the nearest shape per pixel of a camera.
#pragma once

#include "hrcsense/sim/sim.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <vector>

namespace hrcsense::sim_detail {

/// Rigid transform in float for the per-pixel work.
struct PoseF {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
  Eigen::Vector3f apply(const Eigen::Vector3f& p) const { return R * p + t; }
  PoseF inverse() const {
    PoseF out;
    out.R = R.transpose();
    out.t = -(out.R * t);
    return out;
  }
};

/// Fills `rays` from deproject() at unit depth, unless they are already for `in`.
void ensure_rays(SimRays& rays, const Intrinsics& in);

/// Z-buffers every shape of `shapes_base` (base frame) into `z_m` (Z per pixel, kNoHit where
/// nothing is hit) and `ids` (shape_ids[k] where shape k is nearest, 0 where nothing is hit),
/// seen by the camera whose rays are `rays` and whose pose is `T_base_camera`. Writes every
/// pixel of both buffers (rays.x.size() of each); their previous contents do not matter.
void cast_shapes(const std::vector<Shape>& shapes_base, const std::vector<uint16_t>& shape_ids, const SimRays& rays,
                 const PoseF& T_base_camera, float* z_m, uint16_t* ids);

}  // namespace hrcsense::sim_detail
