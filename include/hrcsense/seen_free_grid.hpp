// SPDX-License-Identifier: Apache-2.0
// hrcsense — the seen-free grid of a cell with several cameras (docs/MULTICAMERA.md, "Unknown
// space"): a box of the base frame cut into cubes; each camera marks the cubes it saw free this
// frame, the fuser takes the union, and the robot's distance to the nearest cube that no camera
// saw free is the cell's unknown distance. A cube is free only if some camera saw it free.
#pragma once

#include "hrcsense/segmentation.hpp"
#include "hrcsense/self_filter.hpp"
#include "hrcsense/types.hpp"
#include "hrcsense/unknown_space.hpp"

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
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

/// The cubes of a grid as one camera sees them, prepared once per spec, intrinsics and pose
/// (prepare_seen_free): each cube whose centre projects into the image, in front of the near
/// limit, with the pixel its centre falls in and the centre's depth along the camera's z. The
/// per-frame pass (mark_seen_free) is then one pixel lookup per cube. The cubes are sorted by
/// pixel, so that the pass reads the image's buffers front to back.
struct SeenFreeProjection {
  struct Cube {
    uint32_t cell = 0;   ///< index in the grid (x fastest)
    uint32_t pixel = 0;  ///< row-major index of the pixel the centre falls in
    float z_m = 0.0F;    ///< the centre's depth along the camera's z, m (≥ the near limit)
  };
  std::vector<Cube> cubes;  ///< in view only; every other cube is unknown to this camera
  size_t cell_count = 0;    ///< the spec's
  /// What it was prepared for (matches()); a changed pose, image or grid prepares it again.
  SeenFreeGridSpec spec;
  Intrinsics intrinsics;
  Pose T_base_camera = Pose::Identity();
  float near_m = 0.0F;
  bool matches(const SeenFreeGridSpec& spec, const Intrinsics& intrinsics, const Pose& T_base_camera,
               float near_m) const;
};

/// Projects the spec's cube centres (base frame) into the camera at T_base_camera (pinhole with
/// `intrinsics`: the depth stream has no distortion). A centre falls in pixel (round(u),
/// round(v)), whose ray is the one unknown_space() follows through that pixel centre; centres
/// outside the image or nearer than near_m (UnknownSpaceParams::near_m) are left out. Allocates:
/// call it when matches() says no, not every frame.
SeenFreeProjection prepare_seen_free(const SeenFreeGridSpec& spec, const Intrinsics& intrinsics,
                                     const Pose& T_base_camera, float near_m);

/// How far in front of a depth a cube centre must lie to be seen free, m: half the cube's
/// diagonal (voxel_m·√3/2), so that no part of a cube called free reaches past the measured
/// surface, whatever the cube's orientation to the ray. The same margin widens each unknown
/// segment at both ends.
float seen_free_margin_m(const SeenFreeGridSpec& spec);

/// Marks in `out` (reset to the spec's cell count first: every cube unknown) the cubes this
/// camera saw free in one filtered frame, with the inputs unknown_space() takes (`reliable`
/// prepared for `background`; `foreground_mask` may be empty: no foreground; `robot_pixels`
/// may be null: no envelope; `no_depth_frames` may be empty: every gap counts at once;
/// `stereo_baseline_m` 0: no stereo shadow). A cube in view is unknown only where its centre lies
/// on an unknown segment of its pixel's ray by unknown_space()'s rules, each segment widened by
/// seen_free_margin_m() at both ends (docs/SAFETY.md, "Unknown space with several cameras"):
/// behind foreground at depth d, from d − margin to the background + margin; without depth
/// over a reliable background (not a dropout, not the robot's stereo shadow), from near_m to
/// the background + margin; without depth and without any background (mean not > 0), all of
/// the ray. Everything else in view is seen free: in front of a measured depth, behind the
/// static background, the robot's envelope, its shadow, dropouts, a gap over a background that
/// was never reliable (taught that way, as unknown_space() counts it apart). Every cube is left
/// unknown when `projection` was prepared for another image size or the background or depth
/// sizes disagree. No allocation once `out` has its size.
void mark_seen_free(const SeenFreeProjection& projection, const DepthImage& depth, const BackgroundModel& background,
                    const ReliableBackground& reliable, const std::vector<uint8_t>& foreground_mask,
                    const RobotPixels* robot_pixels, float stereo_baseline_m, const std::vector<uint8_t>& no_depth_frames,
                    const UnknownSpaceParams& params, SeenFreeGrid& out);

/// ORs `other` into `into`: a cube is free when any camera saw it free. Throws
/// std::invalid_argument when the two were made for different cell counts (grids of different
/// specs cannot be combined; the fuser checks the count before it unites).
void unite(SeenFreeGrid& into, const SeenFreeGrid& other);

/// The buffers of unknown_cells_distance_m, reused between calls (no allocation once sized).
struct UnknownDistanceScratch {
  std::vector<uint8_t> block_has_unknown;                  ///< per block of 4×4×4 cubes
  std::vector<std::pair<float, uint32_t>> super_blocks;    ///< (lower bound m, index) of 4×4×4 blocks
};

/// The robot's smallest distance to a cube that no camera saw free: from the padded capsules'
/// surfaces (segment distance less the radius, as segment_capsule_distance) to the cube's
/// centre, m. Cubes whose centre lies inside a capsule are the robot's own volume and left out;
/// 0 only for a centre on a capsule's surface. NaN when no cube is left (every cube free, or
/// inside the robot), when the robot has no capsules, or when `union_bits` has another cell
/// count than the spec. Exact: blocks of 4×4×4 cubes and super-blocks of 4×4×4 blocks holding
/// an unknown cube get a lower bound each (a bounding sphere's distance to the capsules); they
/// are searched nearest bound first, and one whose bound is above the best distance found so
/// far is skipped, never measured cube by cube.
float unknown_cells_distance_m(const SeenFreeGridSpec& spec, const SeenFreeGrid& union_bits, const RobotModel& robot,
                               UnknownDistanceScratch& scratch);
/// The same with buffers of its own (allocates each call).
float unknown_cells_distance_m(const SeenFreeGridSpec& spec, const SeenFreeGrid& union_bits, const RobotModel& robot);

}  // namespace hrcsense
