// SPDX-License-Identifier: Apache-2.0
// hrcsense — motion while learning the background: edge flicker, pooled noise, object-sized
// blobs (background_motion.hpp).
#include "background_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace hrcsense::segmentation_detail {
namespace {

bool reliable(const BatchView& batch, size_t i) {
  const float ratio = batch.model.valid_ratio[i];
  return ratio > 0.0F && ratio >= batch.min_valid_ratio;
}

}  // namespace

double motion_limit_m(double mean_m, double k_noise, double min_spread_m) {
  return std::max(k_noise * mean_m * mean_m, min_spread_m);
}

size_t mark_edge_flicker(const BatchView& batch, double k_noise, double min_spread_m, int radius_px,
                         const uint8_t* moving, uint8_t* flicker) {
  const BackgroundModel& model = batch.model;
  const int width = model.width;
  const int height = model.height;
  const double scale = batch.depth_scale_m;
  const size_t n = model.mean_m.size();
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    flicker[i] = 0;
    if (moving[i] == 0 || batch.nearest_raw[i] == 0) continue;
    const int u = static_cast<int>(i % static_cast<size_t>(width));
    const int v = static_cast<int>(i / static_cast<size_t>(width));
    double near_side = std::numeric_limits<double>::infinity();
    double far_side = 0.0;
    for (int nv = std::max(v - radius_px, 0); nv <= std::min(v + radius_px, height - 1); ++nv) {
      for (int nu = std::max(u - radius_px, 0); nu <= std::min(u + radius_px, width - 1); ++nu) {
        const size_t j = static_cast<size_t>(nv) * width + nu;
        if (moving[j] != 0 || !reliable(batch, j)) continue;
        near_side = std::min(near_side, static_cast<double>(model.mean_m[j]));
        far_side = std::max(far_side, static_cast<double>(model.mean_m[j]));
      }
    }
    if (!(far_side > 0.0)) continue;  // no still pixel around: nothing says what the sides are
    const double near_m = batch.nearest_raw[i] * scale;
    const double far_m = batch.farthest_raw[i] * scale;
    // Is there an edge at all, and do the samples stay within its two sides?
    const bool edge = far_side - near_side > motion_limit_m(near_side, k_noise, min_spread_m);
    if (edge && near_m >= near_side - motion_limit_m(near_side, k_noise, min_spread_m) &&
        far_m <= far_side + motion_limit_m(far_side, k_noise, min_spread_m)) {
      flicker[i] = 1;
      ++count;
    }
  }
  return count;
}

double pooled_noise_per_z2(const BatchView& batch, const uint32_t* valid_count, const uint8_t* moving,
                           const uint8_t* flicker) {
  double sum = 0.0;
  size_t used = 0;
  for (size_t i = 0; i < batch.model.mean_m.size(); ++i) {
    const uint32_t samples = valid_count[i];
    if (samples < 2 || moving[i] != 0 || flicker[i] != 0 || !reliable(batch, i)) continue;
    const double mean_m = batch.model.mean_m[i];
    const double spread_m = batch.model.spread_m[i];
    const double variance = spread_m * spread_m * samples / (samples - 1.0);
    sum += variance / (mean_m * mean_m * mean_m * mean_m);
    ++used;
  }
  return used == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(used));
}

ObjectMotion object_motion(const BatchView& batch, const uint8_t* moving, const uint8_t* wide, float fx_px,
                           float min_object_mm, std::vector<int32_t>& stack, std::vector<uint8_t>& seen) {
  const BackgroundModel& model = batch.model;
  const int width = model.width;
  const int height = model.height;
  const size_t n = model.mean_m.size();
  std::fill(seen.begin(), seen.end(), uint8_t{0});
  ObjectMotion out;
  for (size_t start = 0; start < n; ++start) {
    if (moving[start] == 0 || seen[start] != 0) continue;
    MotionBlob blob;
    blob.u_min = blob.u_max = static_cast<int>(start % static_cast<size_t>(width));
    blob.v_min = blob.v_max = static_cast<int>(start / static_cast<size_t>(width));
    size_t wide_pixels = 0;
    double depth_sum = 0.0;
    size_t depth_pixels = 0;
    size_t top = 0;
    stack[top++] = static_cast<int32_t>(start);
    seen[start] = 1;
    while (top > 0) {
      const size_t i = static_cast<size_t>(stack[--top]);
      const int u = static_cast<int>(i % static_cast<size_t>(width));
      const int v = static_cast<int>(i / static_cast<size_t>(width));
      ++blob.pixels;
      wide_pixels += wide[i] != 0 ? 1 : 0;
      blob.u_min = std::min(blob.u_min, u);
      blob.u_max = std::max(blob.u_max, u);
      blob.v_min = std::min(blob.v_min, v);
      blob.v_max = std::max(blob.v_max, v);
      const double z_m = batch.nearest_raw[i] != 0 ? batch.nearest_raw[i] * static_cast<double>(batch.depth_scale_m)
                                                   : static_cast<double>(model.mean_m[i]);
      if (z_m > 0.0) depth_sum += z_m, ++depth_pixels;
      for (int nv = std::max(v - 1, 0); nv <= std::min(v + 1, height - 1); ++nv) {
        for (int nu = std::max(u - 1, 0); nu <= std::min(u + 1, width - 1); ++nu) {
          const size_t j = static_cast<size_t>(nv) * width + nu;
          if (moving[j] == 0 || seen[j] != 0) continue;
          seen[j] = 1;
          stack[top++] = static_cast<int32_t>(j);  // each pixel once: the stack never exceeds n
        }
      }
    }
    blob.depth_m = depth_pixels == 0 ? 0.0 : depth_sum / static_cast<double>(depth_pixels);
    // A blob that cannot be placed (no depth, no focal length) is not known to be small.
    blob.size_mm = fx_px > 0.0F && blob.depth_m > 0.0
                       ? 2.0 * std::sqrt(static_cast<double>(blob.pixels) / kPi) * blob.depth_m / fx_px * 1000.0
                       : std::numeric_limits<double>::infinity();
    if (wide_pixels == 0 || !(blob.size_mm >= min_object_mm)) continue;
    out.counted += wide_pixels;
    if (blob.pixels > out.largest.pixels) out.largest = blob;
  }
  return out;
}

std::string describe_blob(const MotionBlob& blob) {
  char text[192];
  std::snprintf(text, sizeof text, "the largest moving blob: pixels u %d-%d, v %d-%d, %.1f m away, %.0f mm across",
                blob.u_min, blob.u_max, blob.v_min, blob.v_max, blob.depth_m, blob.size_mm);
  return text;
}

}  // namespace hrcsense::segmentation_detail
