// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — per-pixel blocks: threshold and the depth↔disparity transforms (spec §2, §3).
#include "hrcsense/filters.hpp"

#include <cmath>

namespace hrcsense {
namespace {

// float → uint16 as the SDK's build does it on x86 (through a 32-bit integer, keeping the low
// 16 bits), but without undefined behaviour: out-of-range values give what cvttss2si gives.
uint16_t to_u16_like_sdk(float value) {
  if (!(value > -2147483648.0F && value < 2147483648.0F)) return 0;
  return static_cast<uint16_t>(static_cast<uint32_t>(static_cast<int32_t>(value)));
}

}  // namespace

// The SDK multiplies raw by the depth units in float32 and compares inclusively, so the
// float rounding of min/max decides the boundaries (max 1.5 m drops 1500 mm).
void apply_threshold(const ThresholdParams& params, DepthImage& depth) {
  const float scale = depth.depth_scale_m;
  const float min_m = params.min_m;
  const float max_m = params.max_m;
  for (uint16_t& raw : depth.pixels) {
    const float z_m = static_cast<float>(raw) * scale;
    raw = (z_m >= min_m && z_m <= max_m) ? raw : uint16_t{0};
  }
}

// Evaluated left to right in float32, as the SDK: ((B_mm · 0.001) · fx · 32) / units.
float disparity_factor(float stereo_baseline_mm, float fx_px, float depth_scale_m) {
  const float baseline_m = stereo_baseline_mm * 0.001F;
  return baseline_m * fx_px * 32.0F / depth_scale_m;
}

void depth_to_disparity(const DepthImage& in, float factor, DisparityImage& out) {
  out.resize(in.width, in.height);
  const size_t n = in.pixels.size();
  const uint16_t* src = in.pixels.data();
  float* dst = out.pixels.data();
  for (size_t i = 0; i < n; ++i) {
    // Every non-zero uint16 is a normal float; 0 stays "no data".
    dst[i] = src[i] != 0 ? factor / static_cast<float>(src[i]) : 0.0F;
  }
}

void disparity_to_depth(const DisparityImage& in, float factor, DepthImage& out) {
  out.resize(in.width, in.height);
  const size_t n = in.pixels.size();
  const float* src = in.pixels.data();
  uint16_t* dst = out.pixels.data();
  for (size_t i = 0; i < n; ++i) {
    // The SDK converts only normal floats (not 0, denormals, inf or NaN).
    dst[i] = std::isnormal(src[i]) ? to_u16_like_sdk(factor / src[i] + 0.5F) : uint16_t{0};
  }
}

}  // namespace hrcsense
