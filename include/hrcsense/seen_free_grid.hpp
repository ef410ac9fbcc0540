// SPDX-License-Identifier: Apache-2.0
// hrcsense — the seen-free grid of a cell with several cameras (docs/MULTICAMERA.md, "Unknown
// space"): a box of the base frame cut into cubes; each camera marks the cubes it saw free this
// frame, the fuser takes the union, and the robot's distance to the nearest cube that no camera
// saw free is the cell's unknown distance. A cube is free only if some camera saw it free.
#pragma once

#include "hrcsense/segmentation.hpp"
#include "hrcsense/self_filter.hpp"
#include "hrcsense/types.hpp"

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace hrcsense {

/// The shared grid: `cell.workspace_base` cut into cubes of `cell.voxel_m`, x fastest, then y,
/// then z. Every process of a cell must use the same spec (the measurement carries its cell
/// count, and the fuser refuses another).
struct SeenFreeGridSpec {
  bool enabled = false;  ///< false: no grid is computed (a camera alone, `hrcsense run`)
  Eigen::AlignedBox3f box_base{Eigen::Vector3f(-1.5F, -1.5F, 0.0F), Eigen::Vector3f(1.5F, 1.5F, 2.0F)};
  float voxel_m = 0.05F;
  /// Cubes along x, y, z: ceil(box size / voxel_m) each.
  Eigen::Vector3i dims() const;
  size_t cell_count() const;  ///< dims().prod(); 0 when disabled
  /// The centre of cube `index` (x fastest), base frame.
  Eigen::Vector3f centre(size_t index) const;
};

}  // namespace hrcsense
