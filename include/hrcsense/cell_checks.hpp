// SPDX-License-Identifier: Apache-2.0
// hrcsense — the watchdogs that look at the image itself (docs/SAFETY.md, "Watchdogs"): a
// camera blocked by a near surface, invalid depth where the robot is, and a camera that moved
// away from the pose its background was learnt at. Plain functions of one filtered frame and
// the background; the pipeline turns a failed check into a stop with its reason code.
#pragma once

#include "hrcsense/segmentation.hpp"
#include "hrcsense/self_filter.hpp"
#include "hrcsense/types.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hrcsense {

/// `safety.*` of the image watchdogs (defaults and why: docs/SAFETY.md).
struct CellCheckParams {
  /// A pixel nearer than this (m) where the background is farther counts as blocking.
  float blocked_depth_m = 0.25F;
  /// `safety.blocked_share`: this share of all pixels blocking is camera_blocked.
  float blocked_share = 0.3F;
  /// `safety.max_envelope_invalid_share`: above this share of invalid pixels inside the
  /// robot's projected envelope (where the background was valid) is envelope_invalid.
  float max_envelope_invalid_share = 0.5F;
  /// `safety.moved_share`: this share of the reference pixels measured farther than the
  /// background is camera_moved (a person or object only ever makes pixels nearer).
  float moved_share = 0.25F;
  int moved_grid_px = 8;          ///< one reference pixel per cell of this grid
  float moved_min_margin_m = 0.05F;  ///< "farther" means beyond max(k_sigma·spread, this)
  float moved_k_sigma = 4.0F;
  size_t moved_min_valid = 30;    ///< fewer valid reference pixels: no verdict from this check
};

/// Share of all pixels of `depth` that are valid, nearer than blocked_depth_m and nearer than
/// the background there (or where it is unknown), 0..1.
float blocked_share(const CellCheckParams& params, const DepthImage& depth, const BackgroundModel& background);

/// Invalid (zero) pixels of `depth` inside the robot's envelope `robot` (RobotPixels: its
/// rendered, dilated projection) where the background was valid, and the envelope's pixels
/// with a valid background. Both 0 without a robot.
struct EnvelopeCount {
  size_t invalid = 0;
  size_t pixels = 0;
  float share() const { return pixels > 0 ? static_cast<float>(invalid) / static_cast<float>(pixels) : 0.0F; }
};
EnvelopeCount envelope_invalid(const DepthImage& depth, const BackgroundModel& background, const RobotPixels* robot);

/// The sparse reference set of the camera-moved check: in each moved_grid_px cell the pixel
/// with the smallest spread among those always valid while learning (valid_ratio 1); none in
/// cells without one. Indices into the image, ascending.
std::vector<uint32_t> moved_reference_pixels(const CellCheckParams& params, const BackgroundModel& background);

/// Of the reference pixels valid in `depth`, how many are farther than the background by more
/// than max(moved_k_sigma · spread, moved_min_margin_m).
struct MovedCount {
  size_t farther = 0;
  size_t valid = 0;
  float share() const { return valid > 0 ? static_cast<float>(farther) / static_cast<float>(valid) : 0.0F; }
};
MovedCount moved_count(const CellCheckParams& params, const DepthImage& depth, const BackgroundModel& background,
                       const std::vector<uint32_t>& reference);

}  // namespace hrcsense
