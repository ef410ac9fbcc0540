// SPDX-License-Identifier: Apache-2.0
// hrcsense — the image watchdogs (cell_checks.hpp).

#include "hrcsense/cell_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {

namespace {

// The smallest raw value whose depth (float(raw) · scale, as blocked_share computes it) is at
// least limit_m, so that raw < the result ⇔ depth < limit_m, exactly: the product grows with
// raw. 65536 when even the largest raw value is nearer.
uint32_t first_raw_at_least(float scale, float limit_m) {
  if (!(scale > 0.0F)) return 65536;
  double guess = std::ceil(static_cast<double>(limit_m) / static_cast<double>(scale));
  uint32_t raw = static_cast<uint32_t>(std::clamp(guess, 0.0, 65536.0));
  while (raw > 0 && static_cast<float>(raw - 1) * scale >= limit_m) --raw;
  while (raw < 65536 && static_cast<float>(raw) * scale < limit_m) ++raw;
  return raw;
}

// Pixels [first, first + 8) that are valid and near (0 < raw < near_end): bit k for pixel
// first + k. SSE2 has only signed 16-bit compares, so raw − 1 and the span are both offset by
// 0x8000, which turns the unsigned compare into a signed one.
uint32_t near_bits(const uint16_t* raw, uint32_t near_span) {
#if defined(__SSE2__)
  // near_span ≤ 65535: near_end is at most 65536.
  const __m128i offset = _mm_set1_epi16(static_cast<int16_t>(-0x8000));
  const __m128i span = _mm_set1_epi16(static_cast<int16_t>(static_cast<uint16_t>(near_span) ^ 0x8000U));
  const __m128i minus_one = _mm_sub_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(raw)), _mm_set1_epi16(1));
  const __m128i near = _mm_cmplt_epi16(_mm_xor_si128(minus_one, offset), span);
  return static_cast<uint32_t>(_mm_movemask_epi8(_mm_packs_epi16(near, _mm_setzero_si128()))) & 0xFFU;
#else
  uint32_t bits = 0;
  for (int k = 0; k < 8; ++k) bits |= (static_cast<uint16_t>(raw[k] - 1U) < near_span ? 1U : 0U) << k;
  return bits;
#endif
}

}  // namespace

float blocked_share(const CellCheckParams& params, const DepthImage& depth, const BackgroundModel& background) {
  const size_t n = depth.pixels.size();
  if (n == 0 || background.mean_m.size() != n) return 0.0F;
  // Valid and nearer than blocked_depth_m: 0 < raw < near_end, one unsigned compare of raw − 1
  // (0 wraps to the top). Nearly every pixel fails it, 8 at a time, so the background is read
  // only for the few that pass.
  const uint32_t near_end = first_raw_at_least(depth.depth_scale_m, params.blocked_depth_m);
  const uint32_t near_span = near_end == 0 ? 0 : near_end - 1;
  const uint16_t* raw = depth.pixels.data();
  const float* mean_m = background.mean_m.data();
  // A background as near as this is the scene (a fixture by the lens), not a blockage.
  const auto blocks = [&](size_t i) {
    const float bg = mean_m[i];
    return !(bg > 0.0F && bg < params.blocked_depth_m) ? size_t{1} : size_t{0};
  };
  size_t blocking = 0;
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    for (uint32_t bits = near_bits(raw + i, near_span); bits != 0; bits &= bits - 1) {
      blocking += blocks(i + static_cast<size_t>(__builtin_ctz(bits)));
    }
  }
  for (; i < n; ++i) {
    if (static_cast<uint32_t>(static_cast<uint16_t>(raw[i] - 1U)) < near_span) blocking += blocks(i);
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
