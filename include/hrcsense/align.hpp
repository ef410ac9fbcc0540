// SPDX-License-Identifier: Apache-2.0
// hrcsense — alignment between the depth and colour cameras as the RealSense SDK's `align`
// block does it (specs/deprojection-and-alignment.md §6–§7): depth re-projected onto the
// colour grid, and colour sampled for every depth pixel.
#pragma once

#include "hrcsense/types.hpp"

#include <vector>

namespace hrcsense {

/// Maps a point from sensor A into sensor B with the extrinsics "from A to B", in float32
/// and in the SDK's operation order (P_B = R·P_A + t, rotation column-major).
Eigen::Vector3f transform_point(const Extrinsics& a_to_b, const Eigen::Vector3f& point_a);

/// The colour-image rectangle [x0, x1] × [y0, y1] a depth pixel covers (spec §6 steps 2–4).
/// Empty when the depth pixel cannot be mapped (a corner outside the colour image, behind the
/// colour camera, or a distortion model that cannot be deprojected).
struct ColorFootprint {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool empty() const { return x1 < x0 || y1 < y0; }
};

/// The normalised rays (x/z, y/z) of the depth image's pixel corners, (u ± 0.5, v ± 0.5),
/// computed once per depth intrinsics: the per-pixel part of the SDK's deprojection.
class DepthCornerRays {
 public:
  /// Rebuilds the table when `depth_intrinsics` differ from the last call; false when they
  /// cannot be deprojected (Modified Brown-Conrady) or have no pixels.
  bool prepare(const Intrinsics& depth_intrinsics);
  /// The footprint in the colour image of depth pixel (u, v) at depth z_m (> 0).
  ColorFootprint footprint(int u, int v, float z_m, const Intrinsics& color_intrinsics,
                           const Extrinsics& depth_to_color) const;

 private:
  Intrinsics intrinsics_;
  bool valid_ = false;
  std::vector<float> x_, y_;  ///< (width + 1) × (height + 1) corners, row-major
};

/// Depth → colour ("align to colour", spec §6): the depth image re-projected into the colour
/// camera's pixel grid. Every depth pixel writes its raw depth (Z in the depth camera, not
/// re-computed in the colour camera, as the SDK) into each colour pixel its footprint covers;
/// where footprints overlap the nearest depth wins (a z-buffer, so occluded surfaces vanish).
/// Colour pixels the depth camera does not see stay 0.
class AlignDepthToColor {
 public:
  /// Writes the aligned depth into `out` (colour width × height, the depth's depth_scale_m;
  /// its intrinsics are `color_intrinsics`). Reuses `out`'s buffer and the corner table, so
  /// nothing allocates after the first frame of a size. All-zero output (no depth: fail safe)
  /// when depth's size differs from depth_intrinsics' or they cannot be deprojected.
  void apply(const DepthImage& depth, const Intrinsics& depth_intrinsics, const Intrinsics& color_intrinsics,
             const Extrinsics& depth_to_color, DepthImage& out);

 private:
  DepthCornerRays rays_;
};

/// Colour → depth ("align to depth", spec §7): for every depth pixel with data, the colour of
/// the last colour pixel (bottom right) of its footprint; black where the depth is 0 or the
/// footprint is empty. No occlusion test (as the SDK): background pixels next to an object's
/// edge can take the object's colour.
class AlignColorToDepth {
 public:
  /// Writes an rgb8 image of the depth's width × height into `out`, reusing its buffer.
  /// All black when an image's size differs from its intrinsics' or depth_intrinsics cannot
  /// be deprojected.
  void apply(const DepthImage& depth, const Intrinsics& depth_intrinsics, const ColorImage& color,
             const Intrinsics& color_intrinsics, const Extrinsics& depth_to_color, ColorImage& out);

 private:
  DepthCornerRays rays_;
};

}  // namespace hrcsense
