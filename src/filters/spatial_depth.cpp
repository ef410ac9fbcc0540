// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's edge-preserving spatial filter in the depth (uint16) domain
// (spec §5b); the disparity domain is a different algorithm in the SDK (spatial_disparity.cpp).
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

// ---- depth (uint16) path, spec §5b ----

struct DepthBlend {
  float alpha;
  float one_minus_alpha;
  int delta;
  int radius;
};

inline int32_t blend(int32_t current, int32_t neighbour, const DepthBlend& b) {
  const float filtered = static_cast<float>(current) * b.alpha + static_cast<float>(neighbour) * b.one_minus_alpha;
  return static_cast<int32_t>(filtered + 0.5F);  // ≥ 0 and < 65536: the same as the SDK's uint16 cast
}

#if defined(__SSE2__)
// round(α·current + (1−α)·neighbour) for 8 uint16 lanes, in float as the scalar blend().
inline __m128i blend8(__m128i current, __m128i neighbour, __m128 alpha, __m128 one_minus_alpha) {
  const __m128i zero = _mm_setzero_si128();
  const __m128 half = _mm_set1_ps(0.5F);
  auto half_blend = [&](__m128i c, __m128i n) {
    const __m128 f = _mm_add_ps(_mm_mul_ps(_mm_cvtepi32_ps(c), alpha), _mm_mul_ps(_mm_cvtepi32_ps(n), one_minus_alpha));
    // Shifted by 2^15 so that SSE2's signed saturating pack keeps 0..65535.
    return _mm_sub_epi32(_mm_cvttps_epi32(_mm_add_ps(f, half)), _mm_set1_epi32(32768));
  };
  const __m128i low = half_blend(_mm_unpacklo_epi16(current, zero), _mm_unpacklo_epi16(neighbour, zero));
  const __m128i high = half_blend(_mm_unpackhi_epi16(current, zero), _mm_unpackhi_epi16(neighbour, zero));
  return _mm_xor_si128(_mm_packs_epi32(low, high), _mm_set1_epi16(static_cast<int16_t>(0x8000)));
}

using filters_detail::select;

inline __m128i abs_difference(__m128i a, __m128i b) {
  return _mm_or_si128(_mm_subs_epu16(a, b), _mm_subs_epu16(b, a));
}

// Unsigned 16-bit a <= b as a lane mask.
inline __m128i less_equal(__m128i a, __m128i b) { return _mm_cmpeq_epi16(_mm_subs_epu16(a, b), _mm_setzero_si128()); }
#endif

// One step of a horizontal scan for `lanes` rows side by side, comparing with the already
// filtered neighbour `previous_out` and filling holes in place when radius > 0. Left→right
// smooths when 1 ≤ |diff| ≤ δ and treats 0 as a hole; right→left smooths when |diff| ≤ δ and
// treats 0 and 1 as holes (SDK quirks). The fill counter survives invalid neighbours.
template <int kLanes, bool kLeftToRight>
inline void depth_step(uint16_t* __restrict__ line, const uint16_t* __restrict__ previous_out,
                       uint16_t* __restrict__ fill, int lanes, const DepthBlend& b) {
  const int n = kLanes > 0 ? kLanes : lanes;
  int u = 0;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  const __m128i one = _mm_set1_epi16(1);
  const __m128i min_valid_minus_one = _mm_set1_epi16(kLeftToRight ? 0 : 1);
  const __m128i delta = _mm_set1_epi16(static_cast<int16_t>(b.delta));
  const __m128i radius = _mm_set1_epi16(static_cast<int16_t>(b.radius));
  const __m128i fill_on = b.radius > 0 ? _mm_set1_epi16(-1) : zero;
  const __m128 alpha = _mm_set1_ps(b.alpha);
  const __m128 one_minus_alpha = _mm_set1_ps(b.one_minus_alpha);
  for (; u + 8 <= n; u += 8) {
    const __m128i current = _mm_loadu_si128(reinterpret_cast<const __m128i*>(line + u));
    const __m128i neighbour = _mm_loadu_si128(reinterpret_cast<const __m128i*>(previous_out + u));
    const __m128i counter_in = _mm_loadu_si128(reinterpret_cast<const __m128i*>(fill + u));
    const __m128i neighbour_valid = _mm_xor_si128(_mm_cmpeq_epi16(neighbour, zero), _mm_set1_epi16(-1));
    const __m128i current_invalid = less_equal(current, min_valid_minus_one);
    const __m128i difference = abs_difference(current, neighbour);
    __m128i close = less_equal(difference, delta);
    if (kLeftToRight) close = _mm_andnot_si128(_mm_cmpeq_epi16(difference, zero), close);
    const __m128i both_valid = _mm_andnot_si128(current_invalid, neighbour_valid);
    const __m128i smooth = _mm_and_si128(both_valid, close);
    const __m128i hole = _mm_and_si128(_mm_and_si128(neighbour_valid, current_invalid), fill_on);
    // Saturating: the counter only needs to stay ≥ radius once it got there.
    const __m128i counter = _mm_andnot_si128(both_valid, _mm_adds_epu16(counter_in, _mm_and_si128(hole, one)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(fill + u), counter);
    const __m128i take_neighbour = _mm_andnot_si128(less_equal(radius, counter), hole);
    const __m128i filled = select(take_neighbour, neighbour, current);
    const __m128i result = select(smooth, blend8(current, neighbour, alpha, one_minus_alpha), filled);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(line + u), result);
  }
#endif
  const int32_t min_valid = kLeftToRight ? 1 : 2;
  const int32_t min_difference = kLeftToRight ? 1 : 0;
  for (; u < n; ++u) {
    const int32_t current = line[u];
    const int32_t neighbour = previous_out[u];
    const bool neighbour_valid = neighbour >= 1;
    const bool current_valid = current >= min_valid;
    const int32_t difference = current > neighbour ? current - neighbour : neighbour - current;
    const bool smooth = neighbour_valid & current_valid & (difference >= min_difference) & (difference <= b.delta);
    const bool hole = neighbour_valid & !current_valid & (b.radius > 0);
    const int32_t counter = (neighbour_valid & current_valid) ? 0 : std::min(fill[u] + (hole ? 1 : 0), 65535);
    fill[u] = static_cast<uint16_t>(counter);
    const int32_t filled = (hole & (counter < b.radius)) ? neighbour : current;
    line[u] = static_cast<uint16_t>(smooth ? blend(current, neighbour, b) : filled);
  }
}

// Scans lines 1..count-1 (left→right: 1..count-2, the SDK never visits the last column).
template <int kLanes, bool kLeftToRight>
void scan_depth(uint16_t* first, ptrdiff_t step, int count, int lanes, uint16_t* fill, const DepthBlend& b) {
  const int n = kLanes > 0 ? kLanes : lanes;
  std::memset(fill, 0, sizeof(uint16_t) * static_cast<size_t>(n));
  const int end = kLeftToRight ? count - 1 : count;
  for (int k = 1; k < end; ++k) {
    uint16_t* line = first + step * k;
    depth_step<kLanes, kLeftToRight>(line, line - step, fill, lanes, b);
  }
}

void horizontal_depth(DepthImage& image, const DepthBlend& b, const Scratch<uint16_t>& s) {
  const int w = image.width;
  const int h = image.height;
  uint16_t* pixels = image.pixels.data();
  int v = 0;
  for (; v + kStrip <= h; v += kStrip) {
    uint16_t* rows = pixels + static_cast<ptrdiff_t>(v) * w;
    uint16_t* strip = s.strip;
    load_strip(rows, w, strip);
    scan_depth<kStrip, true>(strip, kStrip, w, kStrip, s.fill, b);
    scan_depth<kStrip, false>(strip + static_cast<ptrdiff_t>(w - 1) * kStrip, -kStrip, w, kStrip, s.fill, b);
    store_strip(strip, w, rows);
  }
  for (; v < h; ++v) {
    uint16_t* row = pixels + static_cast<ptrdiff_t>(v) * w;
    scan_depth<1, true>(row, 1, w, 1, s.fill, b);
    scan_depth<1, false>(row + w - 1, -1, w, 1, s.fill, b);
  }
}

// One row of a vertical pass against its finished neighbour row. Top→bottom smooths when
// |diff| < δ with no validity check (as the SDK); bottom→top (`check_valid`) also needs both
// values valid.
void vertical_depth_row(uint16_t* __restrict__ row, const uint16_t* __restrict__ neighbour_row, int w, bool check_valid,
                        const DepthBlend& b) {
  int u = 0;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  const __m128i delta_minus_one = _mm_set1_epi16(static_cast<int16_t>(b.delta - 1));
  const __m128 alpha = _mm_set1_ps(b.alpha);
  const __m128 one_minus_alpha = _mm_set1_ps(b.one_minus_alpha);
  for (; u + 8 <= w; u += 8) {
    const __m128i current = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + u));
    const __m128i neighbour = _mm_loadu_si128(reinterpret_cast<const __m128i*>(neighbour_row + u));
    __m128i smooth = less_equal(abs_difference(current, neighbour), delta_minus_one);
    if (check_valid) {
      const __m128i invalid = _mm_or_si128(_mm_cmpeq_epi16(current, zero), _mm_cmpeq_epi16(neighbour, zero));
      smooth = _mm_andnot_si128(invalid, smooth);
    }
    const __m128i result = select(smooth, blend8(current, neighbour, alpha, one_minus_alpha), current);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(row + u), result);
  }
#endif
  for (; u < w; ++u) {
    const int32_t current = row[u];
    const int32_t neighbour = neighbour_row[u];
    const int32_t difference = current > neighbour ? current - neighbour : neighbour - current;
    const bool valid = !check_valid || ((current >= 1) & (neighbour >= 1));
    row[u] = static_cast<uint16_t>(valid && difference < b.delta ? blend(current, neighbour, b) : current);
  }
}

// A whole row at a time: each row only depends on the finished row before it.
void vertical_depth(DepthImage& image, const DepthBlend& b) {
  const int w = image.width;
  uint16_t* pixels = image.pixels.data();
  for (int v = 1; v < image.height; ++v) {
    uint16_t* row = pixels + static_cast<ptrdiff_t>(v) * w;
    vertical_depth_row(row, row - w, w, false, b);
  }
  for (int v = image.height - 2; v >= 0; --v) {
    uint16_t* row = pixels + static_cast<ptrdiff_t>(v) * w;
    vertical_depth_row(row, row + w, w, true, b);
  }
}

}  // namespace

void spatial_filter(const SpatialParams& params, DepthImage& depth, SpatialScratch& scratch) {
  if (depth.width < 1 || depth.height < 1) return;  // one column: the vertical passes still run
  const DepthBlend b{params.alpha, 1.0F - params.alpha, params.delta, spatial_holes_radius(params.holes_fill)};
  const Scratch<uint16_t> s = filters_detail::depth_scratch(scratch, depth.width);
  for (int i = 0; i < params.magnitude; ++i) {
    horizontal_depth(depth, b, s);
    vertical_depth(depth, b);
  }
}

}  // namespace hrcsense
