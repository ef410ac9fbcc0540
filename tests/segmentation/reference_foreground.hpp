// SPDX-License-Identifier: Apache-2.0
// The foreground extraction as it was before its per-pixel thresholds, written plainly: the
// float background test per pixel per frame, a flood fill that computes each jump limit in
// float, raster-order deprojection. The fast extractor must reproduce it bit for bit.
#pragma once

#include "hrcsense/camera.hpp"
#include "hrcsense/segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace hrcsense::testing {

/// The reference's result; the base-frame cloud is left to the caller (R · p + t).
struct ReferenceForeground {
  std::vector<uint8_t> mask;  ///< 1 = foreground
  PointCloud points_camera;
};

/// The foreground of `frame` against `background` as the original extractor computed it.
inline ReferenceForeground reference_foreground(const Frame& frame, const BackgroundModel& background,
                                                const ForegroundParams& params, const Pose& T_base_camera) {
  enum : uint8_t { kNone, kKept, kCandidate, kVisited };
  const DepthImage& depth = frame.depth;
  const Intrinsics& intr = frame.intrinsics;
  const int width = depth.width;
  const int height = depth.height;
  const size_t n = depth.pixels.size();
  const float scale_m = depth.depth_scale_m;
  const float sigma_z2 =
      frame.stereo_baseline_mm <= 0.0F || intr.fx <= 0.0F
          ? 0.0F
          : static_cast<float>(stereo_depth_sigma_m(1.0, intr.fx, frame.stereo_baseline_mm, params.subpixel_rms_px));
  const Eigen::Matrix3f R = T_base_camera.linear().cast<float>();
  const Eigen::Vector3f t = T_base_camera.translation().cast<float>();
  const bool pinhole = is_pinhole(intr);
  // The camera point of pixel i at its raw depth, through the float pinhole rays or deproject().
  const auto camera_point = [&](size_t i, Eigen::Vector3f& p) {
    const int u = static_cast<int>(i % static_cast<size_t>(width));
    const int v = static_cast<int>(i / static_cast<size_t>(width));
    const float z = static_cast<float>(depth.pixels[i]) * scale_m;
    if (pinhole) {
      p = {z * ((static_cast<float>(u) - intr.ppx) / intr.fx), z * ((static_cast<float>(v) - intr.ppy) / intr.fy), z};
      return true;
    }
    const auto q = deproject(intr, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), z);
    if (q) p = *q;
    return q.has_value();
  };

  // The background test, and the workspace rule where the background is unknown.
  std::vector<uint8_t> state(n, kNone);
  for (size_t i = 0; i < n; ++i) {
    if (depth.pixels[i] == 0) continue;
    const float z = static_cast<float>(depth.pixels[i]) * scale_m;
    const float m = background.mean_m[i];
    if (!(m > 0.0F)) {
      Eigen::Vector3f p;
      if (camera_point(i, p) && params.workspace_base.contains(R * p + t)) state[i] = kCandidate;
      continue;
    }
    const float a = params.k_sigma * background.spread_m[i];
    const float b = params.k_sigma * sigma_z2 * z * z;
    const float ab = a > b ? a : b;
    const float margin = ab > params.min_margin_m ? ab : params.min_margin_m;
    if (z < m - margin) state[i] = kCandidate;
  }

  // Blobs: 8-neighbours join when their raw depths differ by less than the jump limit at the
  // farther one, max(5 cm, 4 σ_model(z)); blobs below min_object_mm at their mean depth go.
  const float jump_min_raw = 0.05F / scale_m;
  const float jump_per_raw2 = 4.0F * sigma_z2 * scale_m;
  std::vector<size_t> blob;
  for (size_t seed = 0; seed < n; ++seed) {
    if (state[seed] != kCandidate) continue;
    blob.assign(1, seed);
    state[seed] = kVisited;
    uint64_t raw_sum = 0;
    for (size_t head = 0; head < blob.size(); ++head) {
      const size_t i = blob[head];
      const int u = static_cast<int>(i % static_cast<size_t>(width));
      const int v = static_cast<int>(i / static_cast<size_t>(width));
      const int r = depth.pixels[i];
      raw_sum += static_cast<uint64_t>(r);
      for (int nv = std::max(v - 1, 0); nv <= std::min(v + 1, height - 1); ++nv) {
        for (int nu = std::max(u - 1, 0); nu <= std::min(u + 1, width - 1); ++nu) {
          const size_t j = static_cast<size_t>(nv) * static_cast<size_t>(width) + static_cast<size_t>(nu);
          if (state[j] != kCandidate) continue;
          const int rn = depth.pixels[j];
          const float far = static_cast<float>(std::max(r, rn));
          if (static_cast<float>(std::abs(rn - r)) >= std::max(jump_min_raw, jump_per_raw2 * far * far)) continue;
          state[j] = kVisited;
          blob.push_back(j);
        }
      }
    }
    const double size_mm = static_cast<double>(raw_sum) / std::sqrt(static_cast<double>(blob.size())) *
                           (1000.0 * scale_m / intr.fx);
    for (const size_t i : blob) state[i] = size_mm >= params.min_object_mm ? kKept : kNone;
  }

  ReferenceForeground out;
  out.mask.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector3f p;
    if (state[i] != kKept || !camera_point(i, p)) continue;
    out.mask[i] = 1;
    out.points_camera.push_back(p.x(), p.y(), p.z(), static_cast<uint32_t>(i));
  }
  return out;
}

}  // namespace hrcsense::testing
