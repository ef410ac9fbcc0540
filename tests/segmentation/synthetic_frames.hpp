// SPDX-License-Identifier: Apache-2.0
// Hand-built depth frames for the segmentation tests: a small pinhole camera facing a wall.
#pragma once

#include "hrcsense/segmentation.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <vector>

namespace hrcsense::testing {

constexpr int kWidth = 64;
constexpr int kHeight = 48;
// A narrow lens (fx = 200 px) keeps σ_model small at 2 m: 2² · 0.08 / (200 · 0.05) = 32 mm.
constexpr float kFx = 200.0F;
constexpr float kPpx = 31.5F;
constexpr float kPpy = 23.5F;
constexpr float kBaselineMm = 50.0F;
constexpr uint16_t kWallRaw = 2000;  // 2.000 m at 1 mm per unit

/// Deterministic pseudo-noise in raw units, -2..+2, different per pixel and frame.
inline int wall_noise(int u, int v, int64_t frame) {
  const uint32_t h = static_cast<uint32_t>(u) * 73856093U ^ static_cast<uint32_t>(v) * 19349663U ^
                     static_cast<uint32_t>(frame) * 83492791U;
  return static_cast<int>((h >> 7) % 5U) - 2;
}

/// A frame of the noisy wall at 2.000 m, pinhole intrinsics, 1 mm depth units.
inline Frame wall_frame(int64_t index, int width = kWidth, int height = kHeight) {
  Frame frame;
  frame.index = index;
  frame.timestamp_ns = index * 33'333'333;
  frame.depth.resize(width, height);
  frame.intrinsics = Intrinsics{width, height, kFx, kFx, kPpx, kPpy, Distortion::none, {}};
  frame.stereo_baseline_mm = kBaselineMm;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      frame.depth.pixels[static_cast<size_t>(v) * width + u] =
          static_cast<uint16_t>(kWallRaw + wall_noise(u, v, index));
    }
  }
  return frame;
}

/// Sets the raw depth of the rectangle [u0, u0 + w) × [v0, v0 + h).
inline void fill_rect(Frame& frame, int u0, int v0, int w, int h, uint16_t raw) {
  for (int v = v0; v < v0 + h; ++v) {
    for (int u = u0; u < u0 + w; ++u) frame.depth.pixels[static_cast<size_t>(v) * frame.depth.width + u] = raw;
  }
}

/// A background model of the noise-free wall: mean 2.000 m, spread 1.4 mm, always valid.
inline BackgroundModel wall_background(int width = kWidth, int height = kHeight) {
  const size_t n = static_cast<size_t>(width) * height;
  BackgroundModel model;
  model.width = width;
  model.height = height;
  model.mean_m.assign(n, 2.0F);
  model.spread_m.assign(n, 0.0014F);  // the spread of uniform -2..+2 mm noise
  model.valid_ratio.assign(n, 1.0F);
  return model;
}

/// A mask with 1 inside the rectangle [u0, u0 + w) × [v0, v0 + h), to compare against.
inline std::vector<uint8_t> rect_mask(int u0, int v0, int w, int h, int width = kWidth, int height = kHeight) {
  std::vector<uint8_t> mask(static_cast<size_t>(width) * height, 0);
  for (int v = v0; v < v0 + h; ++v) {
    for (int u = u0; u < u0 + w; ++u) mask[static_cast<size_t>(v) * width + u] = 1;
  }
  return mask;
}

}  // namespace hrcsense::testing
