// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — per-pixel blocks: threshold and the depth↔disparity transforms (spec §2, §3).
#include "hrcsense/filters.hpp"
#include "isa.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {
namespace {

#if HRCSENSE_FILTERS_X86
// Both transforms are bound by the divider; 8-wide divisions go through it about twice as fast
// as 4-wide ones on current x86 cores, and give the same IEEE quotients. Each returns how many
// pixels it did; the portable loops do the rest.
__attribute__((target("avx2"))) size_t depth_to_disparity_avx2(const uint16_t* src, float* dst, size_t n,
                                                               float factor) {
  const __m256 f = _mm256_set1_ps(factor);
  const __m256i one = _mm256_set1_epi32(1);
  const __m256i zero = _mm256_setzero_si256();
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256i raw = _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i)));
    // Holes divide by 1 (no division by zero) and are then masked to 0.
    const __m256 quotient = _mm256_div_ps(f, _mm256_cvtepi32_ps(_mm256_max_epi32(raw, one)));
    _mm256_storeu_ps(dst + i, _mm256_andnot_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(raw, zero)), quotient));
  }
  return i;
}

// The low 16 bits of trunc(F / d + 0.5) for normal d, else 0, as 32-bit lanes sign-extended
// from bit 15 (so that the signed saturating pack passes them on unchanged).
__attribute__((target("avx2"))) inline __m256i to_depth8_avx2(const float* p, __m256 f) {
  const __m256i exponent = _mm256_set1_epi32(0x7f800000);
  const __m256i zero = _mm256_setzero_si256();
  const __m256 d = _mm256_loadu_ps(p);
  const __m256i e = _mm256_and_si256(_mm256_castps_si256(d), exponent);
  const __m256i not_normal = _mm256_or_si256(_mm256_cmpeq_epi32(e, zero), _mm256_cmpeq_epi32(e, exponent));
  const __m256 safe = _mm256_blendv_ps(d, _mm256_set1_ps(1.0F), _mm256_castsi256_ps(not_normal));
  const __m256i raw = _mm256_cvttps_epi32(_mm256_add_ps(_mm256_div_ps(f, safe), _mm256_set1_ps(0.5F)));
  return _mm256_andnot_si256(not_normal, _mm256_srai_epi32(_mm256_slli_epi32(raw, 16), 16));
}

__attribute__((target("avx2"))) size_t disparity_to_depth_avx2(const float* src, uint16_t* dst, size_t n,
                                                               float factor) {
  const __m256 f = _mm256_set1_ps(factor);
  size_t i = 0;
  for (; i + 16 <= n; i += 16) {
    // The pack interleaves the two halves by 128-bit lane; the permute restores pixel order.
    const __m256i packed = _mm256_packs_epi32(to_depth8_avx2(src + i, f), to_depth8_avx2(src + i + 8, f));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst + i), _mm256_permute4x64_epi64(packed, 0xD8));
  }
  return i;
}
#endif

// float → uint16 as the SDK's build does it on x86 (through a 32-bit integer, keeping the low
// 16 bits), but without undefined behaviour: out-of-range values give what cvttss2si gives.
uint16_t to_u16_like_sdk(float value) {
  if (!(value > -2147483648.0F && value < 2147483648.0F)) return 0;
  return static_cast<uint16_t>(static_cast<uint32_t>(static_cast<int32_t>(value)));
}

}  // namespace

// The SDK multiplies raw by the depth units in float32 and compares inclusively, so the
// float rounding of min/max decides the boundaries (max 1.5 m drops 1500 mm). raw · scale
// rounds monotonically for a finite positive scale, so the raw values kept form one interval
// [lo, hi], found by bisection; the per-pixel test is then an integer comparison.
void apply_threshold(const ThresholdParams& params, DepthImage& depth) {
  const float scale = depth.depth_scale_m;
  const float min_m = params.min_m;
  const float max_m = params.max_m;
  const auto keeps = [&](uint32_t raw) {
    const float z_m = static_cast<float>(raw) * scale;
    return z_m >= min_m && z_m <= max_m;
  };
  if (!(scale > 0.0F && scale < std::numeric_limits<float>::infinity())) {
    for (uint16_t& raw : depth.pixels) raw = keeps(raw) ? raw : uint16_t{0};
    return;
  }
  // lo: the first raw with z >= min (65536: none); hi + 1: the first raw with z > max.
  const auto first_true = [](auto predicate) {
    uint32_t low = 0, high = 65536;
    while (low < high) {
      const uint32_t middle = (low + high) / 2;
      if (predicate(middle)) {
        high = middle;
      } else {
        low = middle + 1;
      }
    }
    return low;
  };
  const uint32_t lo = first_true([&](uint32_t raw) { return static_cast<float>(raw) * scale >= min_m; });
  const uint32_t end = first_true([&](uint32_t raw) { return !(static_cast<float>(raw) * scale <= max_m); });
  if (lo >= end) {
    std::fill(depth.pixels.begin(), depth.pixels.end(), uint16_t{0});
    return;
  }
  // raw - lo wraps for raw < lo, so one unsigned comparison tests both ends.
  const auto low = static_cast<uint16_t>(lo);
  const auto span = static_cast<uint16_t>(end - 1 - lo);
  for (uint16_t& raw : depth.pixels) raw = static_cast<uint16_t>(raw - low) <= span ? raw : uint16_t{0};
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
  size_t i = 0;
#if HRCSENSE_FILTERS_X86
  if (filters_detail::use_avx2()) i = depth_to_disparity_avx2(src, dst, n, factor);
#endif
#if defined(__SSE2__)
  // Holes divide by 1 instead of 0 (no branch, no division by zero) and are then masked to 0.
  const __m128 f = _mm_set1_ps(factor);
  const __m128 one = _mm_set1_ps(1.0F);
  const __m128i zero = _mm_setzero_si128();
  const auto convert = [&](__m128i raw32) {
    const __m128 hole = _mm_castsi128_ps(_mm_cmpeq_epi32(raw32, zero));
    const __m128 raw = _mm_cvtepi32_ps(raw32);
    const __m128 quotient = _mm_div_ps(f, _mm_or_ps(_mm_andnot_ps(hole, raw), _mm_and_ps(hole, one)));
    return _mm_andnot_ps(hole, quotient);
  };
  for (; i + 8 <= n; i += 8) {
    const __m128i raw = _mm_loadu_si128(reinterpret_cast<const __m128i*>(src + i));
    _mm_storeu_ps(dst + i, convert(_mm_unpacklo_epi16(raw, zero)));
    _mm_storeu_ps(dst + i + 4, convert(_mm_unpackhi_epi16(raw, zero)));
  }
#endif
  for (; i < n; ++i) {
    // Every non-zero uint16 is a normal float; 0 stays "no data".
    dst[i] = src[i] != 0 ? factor / static_cast<float>(src[i]) : 0.0F;
  }
}

void disparity_to_depth(const DisparityImage& in, float factor, DepthImage& out) {
  out.resize(in.width, in.height);
  const size_t n = in.pixels.size();
  const float* src = in.pixels.data();
  uint16_t* dst = out.pixels.data();
  size_t i = 0;
#if HRCSENSE_FILTERS_X86
  if (filters_detail::use_avx2()) i = disparity_to_depth_avx2(src, dst, n, factor);
#endif
#if defined(__SSE2__)
  // cvttps2dq is the SDK's conversion: out of range and NaN give INT32_MIN, whose low 16 bits
  // are 0. Only normal floats (exponent neither 0 nor 255) are converted.
  const __m128 f = _mm_set1_ps(factor);
  const __m128 half = _mm_set1_ps(0.5F);
  const __m128 one = _mm_set1_ps(1.0F);
  const __m128i exponent = _mm_set1_epi32(0x7f800000);
  const __m128i zero = _mm_setzero_si128();
  const auto convert = [&](const float* p) {
    const __m128 d = _mm_loadu_ps(p);
    const __m128i e = _mm_and_si128(_mm_castps_si128(d), exponent);
    const __m128i normal = _mm_andnot_si128(_mm_or_si128(_mm_cmpeq_epi32(e, zero), _mm_cmpeq_epi32(e, exponent)),
                                            _mm_set1_epi32(-1));
    const __m128 safe = _mm_or_ps(_mm_and_ps(_mm_castsi128_ps(normal), d), _mm_andnot_ps(_mm_castsi128_ps(normal), one));
    const __m128i raw = _mm_cvttps_epi32(_mm_add_ps(_mm_div_ps(f, safe), half));
    // Keep the low 16 bits, sign-extended so that the signed saturating pack passes them on.
    return _mm_and_si128(normal, _mm_srai_epi32(_mm_slli_epi32(raw, 16), 16));
  };
  for (; i + 8 <= n; i += 8) {
    const __m128i packed = _mm_packs_epi32(convert(src + i), convert(src + i + 4));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + i), packed);
  }
#endif
  for (; i < n; ++i) {
    // The SDK converts only normal floats (not 0, denormals, inf or NaN).
    dst[i] = std::isnormal(src[i]) ? to_u16_like_sdk(factor / src[i] + 0.5F) : uint16_t{0};
  }
}

}  // namespace hrcsense
