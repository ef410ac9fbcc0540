// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's edge-preserving spatial filter in the disparity (float) domain
// (spec §5a); the depth domain is a different algorithm in the SDK (spatial_depth.cpp).
// How it is made fast without changing a bit: spatial_common.hpp.
#include "isa.hpp"
#include "spatial_common.hpp"

#include <algorithm>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {
namespace {

using filters_detail::kStrip;
using filters_detail::load_strip;
using filters_detail::Scratch;
using filters_detail::store_strip;

// ---- disparity (float) path, spec §5a ----

struct DisparityBlend {
  float alpha;
  float one_minus_alpha;
  float delta;
};

// One step of a scan for `lanes` lines side by side. The SDK's rule: with an unbroken chain
// (previous raw value valid), a valid value within δ of the previous raw value becomes
// α·value + (1−α)·state; otherwise it is kept. Its state is always the previous output when
// the previous raw value is valid (smoothed, or restarted at the kept value), so the rule
// reads the line written one step before. Valid is the SDK's "bits > 0": positive, or a
// positive NaN, which fails the δ test anyway, so `> 0` gives the same result.
inline float smooth_disparity(float current, float previous, float previous_out, const DisparityBlend& b) {
  const float difference = previous - current;
  const bool smooth = (previous > 0.0F) & (current > 0.0F) & (difference < b.delta) & (difference > -b.delta);
  const float blended = current * b.alpha + previous_out * b.one_minus_alpha;
  return smooth ? blended : current;
}

template <int kLanes>
inline void disparity_step(float* __restrict__ line, const float* __restrict__ previous_out,
                           float* __restrict__ previous_raw, int lanes, const DisparityBlend& b) {
  const int n = kLanes > 0 ? kLanes : lanes;
  int u = 0;
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps();
  const __m128 alpha = _mm_set1_ps(b.alpha);
  const __m128 one_minus_alpha = _mm_set1_ps(b.one_minus_alpha);
  const __m128 delta = _mm_set1_ps(b.delta);
  const __m128 sign = _mm_set1_ps(-0.0F);
  for (; u + 4 <= n; u += 4) {
    const __m128 current = _mm_loadu_ps(line + u);
    const __m128 previous = _mm_loadu_ps(previous_raw + u);
    _mm_storeu_ps(previous_raw + u, current);
    // min() passes a NaN's partner through, but a NaN fails the δ test anyway.
    const __m128 valid = _mm_cmpgt_ps(_mm_min_ps(previous, current), zero);
    const __m128 close = _mm_cmplt_ps(_mm_andnot_ps(sign, _mm_sub_ps(previous, current)), delta);
    const __m128 smooth = _mm_and_ps(valid, close);
    const __m128 blended =
        _mm_add_ps(_mm_mul_ps(current, alpha), _mm_mul_ps(_mm_loadu_ps(previous_out + u), one_minus_alpha));
    _mm_storeu_ps(line + u, _mm_or_ps(_mm_and_ps(smooth, blended), _mm_andnot_ps(smooth, current)));
  }
#endif
  for (; u < n; ++u) {
    const float current = line[u];
    line[u] = smooth_disparity(current, previous_raw[u], previous_out[u], b);
    previous_raw[u] = current;
  }
}

// Scans `count` lines `step` apart (negative: backwards), each `lanes` values wide; the first
// line is never written.
template <int kLanes>
void scan_disparity(float* first, ptrdiff_t step, int count, int lanes, float* previous_raw, const DisparityBlend& b) {
  const int n = kLanes > 0 ? kLanes : lanes;
  std::memcpy(previous_raw, first, sizeof(float) * static_cast<size_t>(n));
  for (int k = 1; k < count; ++k) {
    float* line = first + step * k;
    disparity_step<kLanes>(line, line - step, previous_raw, lanes, b);
  }
}

#if HRCSENSE_FILTERS_X86
// disparity_step() eight lanes at a time, the same operations in the same order; any lanes
// left over (fewer than 8) take the SSE2/scalar step.
template <int kLanes>
__attribute__((target("avx2"))) inline void disparity_step_avx2(float* __restrict__ line,
                                                                const float* __restrict__ previous_out,
                                                                float* __restrict__ previous_raw, int lanes,
                                                                const DisparityBlend& b) {
  const int n = kLanes > 0 ? kLanes : lanes;
  const __m256 zero = _mm256_setzero_ps();
  const __m256 alpha = _mm256_set1_ps(b.alpha);
  const __m256 one_minus_alpha = _mm256_set1_ps(b.one_minus_alpha);
  const __m256 delta = _mm256_set1_ps(b.delta);
  const __m256 sign = _mm256_set1_ps(-0.0F);
  int u = 0;
  for (; u + 8 <= n; u += 8) {
    const __m256 current = _mm256_loadu_ps(line + u);
    const __m256 previous = _mm256_loadu_ps(previous_raw + u);
    _mm256_storeu_ps(previous_raw + u, current);
    // Ordered greater-than and less-than: cmpgtps and cmpltps of the SSE2 step.
    const __m256 valid = _mm256_cmp_ps(_mm256_min_ps(previous, current), zero, _CMP_GT_OS);
    const __m256 close = _mm256_cmp_ps(_mm256_andnot_ps(sign, _mm256_sub_ps(previous, current)), delta, _CMP_LT_OS);
    const __m256 smooth = _mm256_and_ps(valid, close);
    const __m256 blended =
        _mm256_add_ps(_mm256_mul_ps(current, alpha), _mm256_mul_ps(_mm256_loadu_ps(previous_out + u), one_minus_alpha));
    _mm256_storeu_ps(line + u, _mm256_blendv_ps(current, blended, smooth));
  }
  if (u < n) disparity_step<0>(line + u, previous_out + u, previous_raw + u, n - u, b);
}

template <int kLanes>
__attribute__((target("avx2"))) void scan_disparity_avx2(float* first, ptrdiff_t step, int count, int lanes,
                                                         float* previous_raw, const DisparityBlend& b) {
  const int n = kLanes > 0 ? kLanes : lanes;
  std::memcpy(previous_raw, first, sizeof(float) * static_cast<size_t>(n));
  for (int k = 1; k < count; ++k) {
    float* line = first + step * k;
    disparity_step_avx2<kLanes>(line, line - step, previous_raw, lanes, b);
  }
}
#endif

// The scan of `lanes` side-by-side lines, with the widest vectors the CPU allows.
template <int kLanes>
void scan_disparity_lines(float* first, ptrdiff_t step, int count, int lanes, float* previous_raw,
                          const DisparityBlend& b) {
#if HRCSENSE_FILTERS_X86
  if (kLanes != 1 && filters_detail::use_avx2()) {
    scan_disparity_avx2<kLanes>(first, step, count, lanes, previous_raw, b);
    return;
  }
#endif
  scan_disparity<kLanes>(first, step, count, lanes, previous_raw, b);
}

void horizontal_disparity(DisparityImage& image, const DisparityBlend& b, const Scratch<float>& s) {
  const int w = image.width;
  const int h = image.height;
  float* pixels = image.pixels.data();
  int v = 0;
  for (; v + kStrip <= h; v += kStrip) {
    float* rows = pixels + static_cast<ptrdiff_t>(v) * w;
    float* strip = s.strip;
    load_strip(rows, w, strip);
    scan_disparity_lines<kStrip>(strip, kStrip, w, kStrip, s.previous_raw, b);
    scan_disparity_lines<kStrip>(strip + static_cast<ptrdiff_t>(w - 1) * kStrip, -kStrip, w, kStrip,
                                 s.previous_raw, b);
    store_strip(strip, w, rows);
  }
  for (; v < h; ++v) {  // the last rows, one at a time
    float* row = pixels + static_cast<ptrdiff_t>(v) * w;
    scan_disparity<1>(row, 1, w, 1, s.previous_raw, b);
    scan_disparity<1>(row + w - 1, -1, w, 1, s.previous_raw, b);
  }
}

void vertical_disparity(DisparityImage& image, const DisparityBlend& b, const Scratch<float>& s) {
  const int w = image.width;
  const int h = image.height;
  float* pixels = image.pixels.data();
  scan_disparity_lines<0>(pixels, w, h, w, s.previous_raw, b);
  scan_disparity_lines<0>(pixels + static_cast<ptrdiff_t>(h - 1) * w, -static_cast<ptrdiff_t>(w), h, w,
                          s.previous_raw, b);
}

bool empty_disparity(float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits == 0;  // only +0.0 is a hole; -0.0 is not
}

// Fills at most radius − 1 holes from each side, once after all iterations.
void holes_fill_disparity(DisparityImage& image, int radius) {
  const int w = image.width;
  for (int v = 0; v < image.height; ++v) {
    float* row = image.pixels.data() + static_cast<size_t>(v) * w;
    int fill = 0;
    for (int u = 1; u < w; ++u) {
      if (!empty_disparity(row[u])) {
        fill = 0;
      } else if (++fill < radius) {
        row[u] = row[u - 1];
      }
    }
    fill = 0;
    for (int u = w - 1; u >= 1; --u) {
      if (!empty_disparity(row[u])) {
        fill = 0;
      } else if (++fill < radius) {
        // The SDK takes the next row's first pixel as the right neighbour of the last column;
        // the goldens need that copied (spatial_disp_*_h*). On the last row it reads past the
        // buffer's end; there we use 0, i.e. no neighbour.
        row[u] = u + 1 < w ? row[u + 1] : (v + 1 < image.height ? row[w] : 0.0F);
      }
    }
  }
}

}  // namespace

void spatial_filter(const SpatialParams& params, DisparityImage& disparity, SpatialScratch& scratch) {
  if (disparity.width < 1 || disparity.height < 1) return;
  const DisparityBlend b{params.alpha, 1.0F - params.alpha, static_cast<float>(params.delta)};
  const Scratch<float> s = filters_detail::disparity_scratch(scratch, disparity.width);
  for (int i = 0; i < params.magnitude; ++i) {
    horizontal_disparity(disparity, b, s);
    vertical_disparity(disparity, b, s);
  }
  const int radius = spatial_holes_radius(params.holes_fill);
  if (radius > 0) holes_fill_disparity(disparity, radius);
}

}  // namespace hrcsense
