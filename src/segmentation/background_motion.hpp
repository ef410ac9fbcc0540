// SPDX-License-Identifier: Apache-2.0
// hrcsense — what counts as motion while the background is learnt (BackgroundLearner). A
// camera it was never tuned for flickers at depth edges and quantises depth in steps that grow
// with z²; neither is a person. Flicker between the two sides of an edge is told apart from
// motion, and only motion the size of a person or an object restarts learning.
#pragma once

#include "hrcsense/segmentation.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::segmentation_detail {

/// What a learning batch knows per pixel, for the motion tests.
struct BatchView {
  const BackgroundModel& model;   ///< the batch's mean, spread and valid ratio
  const uint16_t* nearest_raw;    ///< nearest valid sample per pixel, raw units; 0: none
  const uint16_t* farthest_raw;   ///< farthest valid sample per pixel, raw units; 0: none
  float depth_scale_m;
  float min_valid_ratio;
};

/// The spread a pixel at `mean_m` may have without moving: max(k_noise · mean², min_spread_m).
double motion_limit_m(double mean_m, double k_noise, double min_spread_m);

/// A moving pixel at a depth edge whose every sample lies between the depths of the still
/// pixels around it (the reliable ones within `radius_px` that did not move), widened by the
/// motion limit, flickers between the edge's two sides: it is marked in `flicker` (and left in
/// `moving`: the caller clears it). A person or an object in front of the edge is nearer than
/// both sides and is no flicker. Returns the number of flickering pixels.
size_t mark_edge_flicker(const BatchView& batch, double k_noise, double min_spread_m, int radius_px,
                         const uint8_t* moving, uint8_t* flicker);

/// The depth noise σ / z² (1/m) pooled over the reliable pixels that did not move or flicker:
/// the root mean square of spread / mean² with each spread made unbiased (· n / (n − 1)).
/// Unlike the median, a camera that quantises depth (most pixels of a few frames read one
/// value, some flip by a whole step) gets the noise its flips make. 0 without such pixels.
double pooled_noise_per_z2(const BatchView& batch, const uint32_t* valid_count, const uint8_t* moving,
                           const uint8_t* flicker);

/// A blob of motion (8-connected moving pixels) and where it is.
struct MotionBlob {
  size_t pixels = 0;
  int u_min = 0, u_max = 0, v_min = 0, v_max = 0;
  double depth_m = 0.0;  ///< mean of its pixels' nearest samples (what moved, not the wall behind)
  double size_mm = 0.0;  ///< diameter of the disc of its area at depth_m (the speckle filter's rule)
};

/// Motion that could be a person or an object: the blobs of `moving` that hold at least one
/// pixel of `wide` (motion at least motion_min_width_px across) and measure at least
/// `min_object_mm` (foreground.min_object_mm: what the foreground would keep). `counted` is the
/// number of `wide` pixels in them; `largest` the largest of them.
struct ObjectMotion {
  size_t counted = 0;
  MotionBlob largest;
};
ObjectMotion object_motion(const BatchView& batch, const uint8_t* moving, const uint8_t* wide, float fx_px,
                           float min_object_mm, std::vector<int32_t>& stack, std::vector<uint8_t>& seen);

/// "the largest moving blob: pixels u 120-180, v 40-210, 2.3 m away, 410 mm across".
std::string describe_blob(const MotionBlob& blob);

}  // namespace hrcsense::segmentation_detail
