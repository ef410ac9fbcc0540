// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's edge-preserving spatial filter (spec §5). The depth (uint16)
// and disparity (float) domains are two different algorithms in the SDK; both are copied.
//
// Speed without changing a bit of the result (tests/filters/fast_test.cpp checks it against
// the plain reference, on the SSE2 and the AVX2 path): each scan is a recursion along a line, so many lines are
// filtered side by side. The vertical passes run across a whole image row at once (the lines
// are the columns, adjacent in memory). The horizontal passes copy a strip of kStrip rows into
// a small transposed buffer (column-major, hot in L1), run the same kind of scan there with
// the rows side by side, and copy it back. No branches in the inner loops (selects), no double.
#include "hrcsense/filters.hpp"
#include "isa.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {
namespace {

constexpr int kStrip = 16;  // rows filtered side by side in a horizontal pass

// The caller's SpatialScratch, sized for `width`, as raw pointers for the loops. Holds no
// result: every call overwrites what it reads.
template <typename T>
struct Scratch {
  T* strip;            // kStrip rows, transposed: strip[column * kStrip + row]
  T* previous_raw;     // disparity: the previous line's unfiltered values
  uint16_t* fill;      // depth: hole-fill counter of every line (saturating)
};

template <typename T>
void grow(std::vector<T>& buffer, size_t size) {
  if (buffer.size() < size) buffer.resize(size);
}

Scratch<uint16_t> depth_scratch(SpatialScratch& s, int width) {
  const size_t w = static_cast<size_t>(width);
  grow(s.depth_strip, w * kStrip);
  grow(s.depth_fill, std::max(w, size_t{kStrip}));  // a row, or a strip's rows
  return {s.depth_strip.data(), nullptr, s.depth_fill.data()};
}

Scratch<float> disparity_scratch(SpatialScratch& s, int width) {
  const size_t w = static_cast<size_t>(width);
  grow(s.disparity_strip, w * kStrip);
  grow(s.disparity_line, std::max(w, size_t{kStrip}));
  return {s.disparity_strip.data(), s.disparity_line.data(), nullptr};
}

// ---- transposing a strip of kStrip rows ----

#if defined(__SSE2__)
void load_strip(const float* rows, int w, float* strip) {
  int u = 0;
  for (; u + 4 <= w; u += 4) {
    for (int g = 0; g < kStrip; g += 4) {
      const float* r = rows + static_cast<ptrdiff_t>(g) * w + u;
      __m128 a = _mm_loadu_ps(r), b = _mm_loadu_ps(r + w), c = _mm_loadu_ps(r + 2 * w), d = _mm_loadu_ps(r + 3 * w);
      _MM_TRANSPOSE4_PS(a, b, c, d);
      float* s = strip + static_cast<ptrdiff_t>(u) * kStrip + g;
      _mm_storeu_ps(s, a);
      _mm_storeu_ps(s + kStrip, b);
      _mm_storeu_ps(s + 2 * kStrip, c);
      _mm_storeu_ps(s + 3 * kStrip, d);
    }
  }
  for (; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) strip[u * kStrip + g] = rows[static_cast<ptrdiff_t>(g) * w + u];
}

void store_strip(const float* strip, int w, float* rows) {
  int u = 0;
  for (; u + 4 <= w; u += 4) {
    for (int g = 0; g < kStrip; g += 4) {
      const float* s = strip + static_cast<ptrdiff_t>(u) * kStrip + g;
      __m128 a = _mm_loadu_ps(s), b = _mm_loadu_ps(s + kStrip), c = _mm_loadu_ps(s + 2 * kStrip),
             d = _mm_loadu_ps(s + 3 * kStrip);
      _MM_TRANSPOSE4_PS(a, b, c, d);
      float* r = rows + static_cast<ptrdiff_t>(g) * w + u;
      _mm_storeu_ps(r, a);
      _mm_storeu_ps(r + w, b);
      _mm_storeu_ps(r + 2 * w, c);
      _mm_storeu_ps(r + 3 * w, d);
    }
  }
  for (; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) rows[static_cast<ptrdiff_t>(g) * w + u] = strip[u * kStrip + g];
}

// 8x8 blocks of uint16: three rounds of interleaving; the transpose is its own inverse.
inline void transpose8x8(__m128i r[8]) {
  __m128i a[8], c[8];
  for (int i = 0; i < 8; i += 2) {
    a[i] = _mm_unpacklo_epi16(r[i], r[i + 1]);
    a[i + 1] = _mm_unpackhi_epi16(r[i], r[i + 1]);
  }
  for (int i = 0; i < 8; i += 4) {
    c[i] = _mm_unpacklo_epi32(a[i], a[i + 2]);
    c[i + 1] = _mm_unpackhi_epi32(a[i], a[i + 2]);
    c[i + 2] = _mm_unpacklo_epi32(a[i + 1], a[i + 3]);
    c[i + 3] = _mm_unpackhi_epi32(a[i + 1], a[i + 3]);
  }
  for (int i = 0; i < 4; ++i) {
    r[2 * i] = _mm_unpacklo_epi64(c[i], c[i + 4]);
    r[2 * i + 1] = _mm_unpackhi_epi64(c[i], c[i + 4]);
  }
}

void load_strip(const uint16_t* rows, int w, uint16_t* strip) {
  static_assert(kStrip % 8 == 0, "strips of whole 8x8 blocks");
  int u = 0;
  for (; u + 8 <= w; u += 8) {
    for (int g = 0; g < kStrip; g += 8) {
      __m128i r[8];
      for (int i = 0; i < 8; ++i)
        r[i] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(rows + static_cast<ptrdiff_t>(g + i) * w + u));
      transpose8x8(r);
      for (int i = 0; i < 8; ++i)
        _mm_storeu_si128(reinterpret_cast<__m128i*>(strip + static_cast<ptrdiff_t>(u + i) * kStrip + g), r[i]);
    }
  }
  for (; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) strip[u * kStrip + g] = rows[static_cast<ptrdiff_t>(g) * w + u];
}

void store_strip(const uint16_t* strip, int w, uint16_t* rows) {
  int u = 0;
  for (; u + 8 <= w; u += 8) {
    for (int g = 0; g < kStrip; g += 8) {
      __m128i r[8];
      for (int i = 0; i < 8; ++i)
        r[i] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(strip + static_cast<ptrdiff_t>(u + i) * kStrip + g));
      transpose8x8(r);
      for (int i = 0; i < 8; ++i)
        _mm_storeu_si128(reinterpret_cast<__m128i*>(rows + static_cast<ptrdiff_t>(g + i) * w + u), r[i]);
    }
  }
  for (; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) rows[static_cast<ptrdiff_t>(g) * w + u] = strip[u * kStrip + g];
}
#endif

template <typename T>
void load_strip(const T* rows, int w, T* strip) {
  for (int u = 0; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) strip[u * kStrip + g] = rows[static_cast<ptrdiff_t>(g) * w + u];
}

template <typename T>
void store_strip(const T* strip, int w, T* rows) {
  for (int u = 0; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) rows[static_cast<ptrdiff_t>(g) * w + u] = strip[u * kStrip + g];
}

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

inline __m128i select(__m128i mask, __m128i a, __m128i b) {
  return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
}

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

int spatial_holes_radius(int holes_fill) {
  if (holes_fill <= 0) return 0;
  if (holes_fill >= 5) return 255;
  return 1 << holes_fill;
}

void spatial_filter(const SpatialParams& params, DepthImage& depth, SpatialScratch& scratch) {
  if (depth.width < 1 || depth.height < 1) return;  // one column: the vertical passes still run
  const DepthBlend b{params.alpha, 1.0F - params.alpha, params.delta, spatial_holes_radius(params.holes_fill)};
  const Scratch<uint16_t> s = depth_scratch(scratch, depth.width);
  for (int i = 0; i < params.magnitude; ++i) {
    horizontal_depth(depth, b, s);
    vertical_depth(depth, b);
  }
}

void spatial_filter(const SpatialParams& params, DisparityImage& disparity, SpatialScratch& scratch) {
  if (disparity.width < 1 || disparity.height < 1) return;
  const DisparityBlend b{params.alpha, 1.0F - params.alpha, static_cast<float>(params.delta)};
  const Scratch<float> s = disparity_scratch(scratch, disparity.width);
  for (int i = 0; i < params.magnitude; ++i) {
    horizontal_disparity(disparity, b, s);
    vertical_disparity(disparity, b, s);
  }
  const int radius = spatial_holes_radius(params.holes_fill);
  if (radius > 0) holes_fill_disparity(disparity, radius);
}

void spatial_filter(const SpatialParams& params, DepthImage& depth) {
  SpatialScratch scratch;
  spatial_filter(params, depth, scratch);
}

void spatial_filter(const SpatialParams& params, DisparityImage& disparity) {
  SpatialScratch scratch;
  spatial_filter(params, disparity, scratch);
}

}  // namespace hrcsense
