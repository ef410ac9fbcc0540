// SPDX-License-Identifier: Apache-2.0
// hrcsense — the image watchdogs (cell_checks.hpp).

#include "hrcsense/cell_checks.hpp"

#include <algorithm>
#include <cmath>

namespace hrcsense {

float blocked_share(const CellCheckParams& params, const DepthImage& depth, const BackgroundModel& background) {
  const size_t n = depth.pixels.size();
  if (n == 0 || background.mean_m.size() != n) return 0.0F;
  const float scale = depth.depth_scale_m;
  size_t blocking = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint16_t raw = depth.pixels[i];
    if (raw == 0) continue;
    const float z = static_cast<float>(raw) * scale;
    const float bg = background.mean_m[i];
    // A background as near as this is the scene (a fixture by the lens), not a blockage.
    blocking += z < params.blocked_depth_m && !(bg > 0.0F && bg < params.blocked_depth_m) ? 1 : 0;
  }
  return static_cast<float>(blocking) / static_cast<float>(n);
}

EnvelopeCount envelope_invalid(const DepthImage& depth, const BackgroundModel& background, const RobotPixels* robot) {
  EnvelopeCount count;
  const size_t n = depth.pixels.size();
  if (robot == nullptr || background.mean_m.size() != n) return count;
  for (size_t i = 0; i < n; ++i) {
    if (robot->from_raw[i] == 0 || !(background.mean_m[i] > 0.0F)) continue;
    ++count.pixels;
    count.invalid += depth.pixels[i] == 0 ? 1 : 0;
  }
  return count;
}

std::vector<uint32_t> moved_reference_pixels(const CellCheckParams& params, const BackgroundModel& background) {
  std::vector<uint32_t> reference;
  const int grid = std::max(1, params.moved_grid_px);
  const size_t n = static_cast<size_t>(background.width) * static_cast<size_t>(background.height);
  if (background.mean_m.size() != n || background.spread_m.size() != n || background.valid_ratio.size() != n) {
    return reference;
  }
  for (int v0 = 0; v0 < background.height; v0 += grid) {
    for (int u0 = 0; u0 < background.width; u0 += grid) {
      uint32_t best = 0;
      float best_spread = INFINITY;
      for (int v = v0; v < std::min(background.height, v0 + grid); ++v) {
        for (int u = u0; u < std::min(background.width, u0 + grid); ++u) {
          const size_t i = static_cast<size_t>(v) * static_cast<size_t>(background.width) + static_cast<size_t>(u);
          if (!(background.valid_ratio[i] >= 1.0F) || !(background.mean_m[i] > 0.0F)) continue;
          if (background.spread_m[i] < best_spread) {
            best_spread = background.spread_m[i];
            best = static_cast<uint32_t>(i);
          }
        }
      }
      if (std::isfinite(best_spread)) reference.push_back(best);
    }
  }
  std::sort(reference.begin(), reference.end());
  return reference;
}

MovedCount moved_count(const CellCheckParams& params, const DepthImage& depth, const BackgroundModel& background,
                       const std::vector<uint32_t>& reference) {
  MovedCount count;
  if (background.mean_m.size() != depth.pixels.size()) return count;
  for (const uint32_t i : reference) {
    const uint16_t raw = depth.pixels[i];
    if (raw == 0) continue;
    ++count.valid;
    const float z = static_cast<float>(raw) * depth.depth_scale_m;
    const float margin = std::max(params.moved_k_sigma * background.spread_m[i], params.moved_min_margin_m);
    count.farther += z > background.mean_m[i] + margin ? 1 : 0;
  }
  return count;
}

}  // namespace hrcsense
