// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — decimation (spec §4): lower median of the non-zero pixels of each block
// for magnitudes 2–3, their truncated integer mean otherwise; output padded to multiples of 4.
#include "hrcsense/filters.hpp"
#include "isa.hpp"

#include <algorithm>
#include <cassert>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {
namespace {

int ceil4(int n) { return (n + 3) / 4 * 4; }

// The lower median of the first n values (n <= 9): the element at index (n-1)/2 once sorted.
// Insertion sort: at most 9 values.
uint16_t lower_median(uint16_t* values, int n) {
  for (int i = 1; i < n; ++i) {
    const uint16_t value = values[i];
    int j = i;
    for (; j > 0 && values[j - 1] > value; --j) values[j] = values[j - 1];
    values[j] = value;
  }
  return values[(n - 1) / 2];
}

#if defined(__SSE2__)
using filters_detail::max_u16;
using filters_detail::min_u16;

// Even and odd uint16 of 16 consecutive values, each as 8 lanes (the low or high halves of the
// 32-bit lanes, sign-extended so that the signed saturating pack passes them on).
inline void deinterleave(const uint16_t* p, __m128i& even, __m128i& odd) {
  const __m128i x0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
  const __m128i x1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 8));
  even = _mm_packs_epi32(_mm_srai_epi32(_mm_slli_epi32(x0, 16), 16), _mm_srai_epi32(_mm_slli_epi32(x1, 16), 16));
  odd = _mm_packs_epi32(_mm_srai_epi32(x0, 16), _mm_srai_epi32(x1, 16));
}

// Magnitude 2 for 8 output pixels: v − 1 (wrapping) turns holes into 65535, the largest value,
// so the sorted block starts with the valid values. A sorting network gives the smallest three
// s0 ≤ s1 ≤ s2; the lower median is s1 when at least three values are valid (s2 is no hole),
// else s0; adding 1 back turns "no valid value" (65535) into 0.
inline __m128i lower_median_2x2(const uint16_t* top, const uint16_t* bottom) {
  __m128i a, b, c, d;
  deinterleave(top, a, b);
  deinterleave(bottom, c, d);
  const __m128i one = _mm_set1_epi16(1);
  a = _mm_sub_epi16(a, one);
  b = _mm_sub_epi16(b, one);
  c = _mm_sub_epi16(c, one);
  d = _mm_sub_epi16(d, one);
  const __m128i low_ab = min_u16(a, b), high_ab = max_u16(a, b);
  const __m128i low_cd = min_u16(c, d), high_cd = max_u16(c, d);
  const __m128i s0 = min_u16(low_ab, low_cd);
  const __m128i x = max_u16(low_ab, low_cd), y = min_u16(high_ab, high_cd);
  const __m128i s1 = min_u16(x, y), s2 = max_u16(x, y);
  const __m128i three = _mm_xor_si128(_mm_cmpeq_epi16(s2, _mm_set1_epi16(-1)), _mm_set1_epi16(-1));
  const __m128i median = _mm_or_si128(_mm_and_si128(three, s1), _mm_andnot_si128(three, s0));
  return _mm_add_epi16(median, one);
}
#endif

}  // namespace

void decimate(const DecimationParams& params, const DepthImage& in, const Intrinsics& in_intrinsics,
              DepthImage& out, Intrinsics& out_intrinsics) {
  assert(&in != &out);
  const int s = std::clamp(params.magnitude, 1, 8);
  const int real_w = in.width / s;
  const int real_h = in.height / s;
  out.depth_scale_m = in.depth_scale_m;
  out.resize(ceil4(real_w), ceil4(real_h));
  std::fill(out.pixels.begin(), out.pixels.end(), uint16_t{0});
  const bool median = s == 2 || s == 3;
  uint16_t block[9];
  for (int j = 0; j < real_h; ++j) {
    int i = 0;
#if defined(__SSE2__)
    if (s == 2) {
      const uint16_t* top = in.pixels.data() + static_cast<size_t>(2 * j) * in.width;
      uint16_t* row = out.pixels.data() + static_cast<size_t>(j) * out.width;
      for (; i + 8 <= real_w; i += 8) {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(row + i), lower_median_2x2(top + 2 * i, top + in.width + 2 * i));
      }
    }
#endif
    for (; i < real_w; ++i) {
      int count = 0;
      uint32_t sum = 0;
      for (int y = j * s; y < j * s + s; ++y) {
        const uint16_t* row = in.pixels.data() + static_cast<size_t>(y) * in.width + static_cast<size_t>(i) * s;
        for (int x = 0; x < s; ++x) {
          if (row[x] == 0) continue;  // holes never pull the result down
          if (median) block[count] = row[x];
          sum += row[x];
          ++count;
        }
      }
      uint16_t value = 0;
      if (count > 0) value = median ? lower_median(block, count) : static_cast<uint16_t>(sum / static_cast<uint32_t>(count));
      out.pixels[static_cast<size_t>(j) * out.width + i] = value;
    }
  }
  out_intrinsics = in_intrinsics;
  const float scale = static_cast<float>(s);
  out_intrinsics.width = out.width;
  out_intrinsics.height = out.height;
  out_intrinsics.fx = in_intrinsics.fx / scale;
  out_intrinsics.fy = in_intrinsics.fy / scale;
  out_intrinsics.ppx = in_intrinsics.ppx / scale;
  out_intrinsics.ppy = in_intrinsics.ppy / scale;
}

}  // namespace hrcsense
