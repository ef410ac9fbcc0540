// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's temporal filter (spec §6): smoothing across frames and hole
// filling from a rotating 8-frame validity history, with the SDK's persistence rules.
#include "hrcsense/filters.hpp"
#include "isa.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {
namespace {

// Window N (frames before the current one) and minimum count M of each persistence mode.
constexpr int kWindow[9] = {0, 8, 3, 4, 8, 2, 5, 8, 0};
constexpr int kMinValid[9] = {0, 8, 2, 2, 2, 1, 1, 1, 0};

// Bit k of lut[history] says whether a hole may be filled at phase k: bit k of the history
// is the pixel's validity in the last frame of phase k, so the N frames before a frame of
// phase k are the bits k-1, ..., k-N (mod 8).
std::array<uint8_t, 256> persistence_lut(int persistence) {
  std::array<uint8_t, 256> lut{};
  for (int history = 0; history < 256; ++history) {
    for (int phase = 0; phase < 8; ++phase) {
      bool fill = persistence == 8;
      if (persistence >= 1 && persistence <= 7) {
        int count = 0;
        for (int back = 1; back <= kWindow[persistence]; ++back) count += (history >> ((phase - back + 8) % 8)) & 1;
        fill = count >= kMinValid[persistence];
      }
      if (fill) lut[static_cast<size_t>(history)] |= static_cast<uint8_t>(1U << phase);
    }
  }
  return lut;
}

bool same(const TemporalParams& a, const TemporalParams& b) {
  return a.alpha == b.alpha && a.delta == b.delta && a.persistence == b.persistence;
}

// |a - b| as the SDK computes it: through int for uint16, in float for float.
inline uint16_t abs_difference(uint16_t a, uint16_t b) {
  return static_cast<uint16_t>(std::abs(static_cast<int>(a) - static_cast<int>(b)));
}
inline float abs_difference(float a, float b) { return std::fabs(a - b); }

#if defined(__SSE2__)
// The persistence rule without the table, as lane operations: m = the history bits of the N
// frames before the current phase (`window`); "M of N" is then m != 0 (M 1), m has two bits
// set (m & (m − 1) != 0, M 2) or m is all N bits (M 8). Mode 0 never fills, mode 8 always.
struct PersistenceRule {
  int window = 0;
  int min_valid = 0;  // 0: never, 9: always
};

PersistenceRule persistence_rule(int persistence, int phase) {
  if (persistence <= 0) return {0, 0};
  if (persistence >= 8) return {0, 9};
  PersistenceRule rule{0, kMinValid[persistence]};
  for (int back = 1; back <= kWindow[persistence]; ++back) rule.window |= 1 << ((phase - back + 8) % 8);
  return rule;
}

inline __m128i persistence_allows(__m128i history, const PersistenceRule& rule) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i all = _mm_set1_epi32(-1);
  const __m128i w = _mm_set1_epi32(rule.window);
  const __m128i m = _mm_and_si128(history, w);
  switch (rule.min_valid) {
    case 0: return zero;
    case 1: return _mm_xor_si128(_mm_cmpeq_epi32(m, zero), all);
    case 2: return _mm_xor_si128(_mm_cmpeq_epi32(_mm_and_si128(m, _mm_sub_epi32(m, _mm_set1_epi32(1))), zero), all);
    case 8: return _mm_cmpeq_epi32(m, w);
    default: return all;
  }
}

using filters_detail::select;

// Four pixels as 32-bit lanes: float bits, or uint16 widened.
inline __m128i load4(const float* p) { return _mm_castps_si128(_mm_loadu_ps(p)); }
inline __m128i load4(const uint16_t* p) {
  return _mm_unpacklo_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)), _mm_setzero_si128());
}
inline void store4(float* p, __m128i v) { _mm_storeu_ps(p, _mm_castsi128_ps(v)); }
inline void store4(uint16_t* p, __m128i v) {
  // Sign-extend the low 16 bits so that the signed saturating pack passes them on unchanged.
  const __m128i packed = _mm_packs_epi32(_mm_srai_epi32(_mm_slli_epi32(v, 16), 16), _mm_setzero_si128());
  _mm_storel_epi64(reinterpret_cast<__m128i*>(p), packed);
}

// The per-pixel rules of apply_to() on four pixels at a time; returns how many it did.
template <typename T>
size_t temporal_sse2(T* pixels, T* last, uint8_t* history, size_t n, int phase, const TemporalParams& params) {
  constexpr bool kFloat = std::is_same_v<T, float>;
  const __m128i zero = _mm_setzero_si128();
  const __m128i all = _mm_set1_epi32(-1);
  const __m128i mask = _mm_set1_epi32(1 << phase);
  const __m128 alpha = _mm_set1_ps(params.alpha);
  const __m128 one_minus_alpha = _mm_set1_ps(1.0F - params.alpha);
  const __m128 delta_f = _mm_set1_ps(static_cast<float>(params.delta));
  const __m128i delta_i = _mm_set1_epi32(params.delta);
  const PersistenceRule rule = persistence_rule(params.persistence, phase);
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m128i current = load4(pixels + i);
    const __m128i previous = load4(last + i);
    int32_t bytes = 0;
    std::memcpy(&bytes, history + i, sizeof bytes);
    const __m128i old_history = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(bytes), zero), zero);
    __m128i current_valid, previous_valid, close, blended;
    if constexpr (kFloat) {
      const __m128 c = _mm_castsi128_ps(current);
      const __m128 p = _mm_castsi128_ps(previous);
      current_valid = _mm_castps_si128(_mm_cmpneq_ps(c, _mm_setzero_ps()));  // NaN counts, −0 does not
      previous_valid = _mm_castps_si128(_mm_cmpneq_ps(p, _mm_setzero_ps()));
      close = _mm_castps_si128(_mm_cmplt_ps(_mm_andnot_ps(_mm_set1_ps(-0.0F), _mm_sub_ps(c, p)), delta_f));
      blended = _mm_castps_si128(_mm_add_ps(_mm_mul_ps(alpha, c), _mm_mul_ps(one_minus_alpha, p)));
    } else {
      current_valid = _mm_xor_si128(_mm_cmpeq_epi32(current, zero), all);
      previous_valid = _mm_xor_si128(_mm_cmpeq_epi32(previous, zero), all);
      const __m128i difference = _mm_sub_epi32(current, previous);
      const __m128i sign = _mm_srai_epi32(difference, 31);
      close = _mm_cmplt_epi32(_mm_sub_epi32(_mm_xor_si128(difference, sign), sign), delta_i);
      const __m128 f = _mm_add_ps(_mm_mul_ps(alpha, _mm_cvtepi32_ps(current)),
                                  _mm_mul_ps(one_minus_alpha, _mm_cvtepi32_ps(previous)));
      blended = _mm_cvttps_epi32(f);  // truncated, as the SDK
    }
    const __m128i agree = _mm_and_si128(_mm_and_si128(current_valid, previous_valid), close);
    const __m128i updated = select(agree, blended, current);
    const __m128i fill = _mm_and_si128(previous_valid, persistence_allows(old_history, rule));
    store4(pixels + i, select(current_valid, updated, select(fill, previous, current)));
    store4(last + i, select(current_valid, updated, previous));
    const __m128i new_history =
        select(current_valid, select(agree, _mm_or_si128(old_history, mask), mask), _mm_andnot_si128(mask, old_history));
    bytes = _mm_cvtsi128_si32(_mm_packus_epi16(_mm_packs_epi32(new_history, zero), zero));
    std::memcpy(history + i, &bytes, sizeof bytes);
  }
  return i;
}
#endif

#if HRCSENSE_FILTERS_X86
// The same lane operations as temporal_sse2(), eight pixels at a time.
__attribute__((target("avx2"))) inline __m256i persistence_allows_avx2(__m256i history, const PersistenceRule& rule) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i all = _mm256_set1_epi32(-1);
  const __m256i w = _mm256_set1_epi32(rule.window);
  const __m256i m = _mm256_and_si256(history, w);
  switch (rule.min_valid) {
    case 0: return zero;
    case 1: return _mm256_xor_si256(_mm256_cmpeq_epi32(m, zero), all);
    case 2:
      return _mm256_xor_si256(_mm256_cmpeq_epi32(_mm256_and_si256(m, _mm256_sub_epi32(m, _mm256_set1_epi32(1))), zero),
                              all);
    case 8: return _mm256_cmpeq_epi32(m, w);
    default: return all;
  }
}

// and/andnot/or rather than _mm256_blendv_epi8: with blends, this loop gave wrong results
// (holes left unfilled) in a -march=native build on an AVX-512 CPU only; whether our code or
// GCC 12 was at fault is not pinned down. The bitwise form, as in the SSE2 loop, is right in
// every build; tests/filters/fast_test.cpp in a native build catches a regression.
__attribute__((target("avx2"))) inline __m256i select8(__m256i mask, __m256i a, __m256i b) {
  return _mm256_or_si256(_mm256_and_si256(mask, a), _mm256_andnot_si256(mask, b));
}

__attribute__((target("avx2"))) inline __m256i load8(const float* p) {
  return _mm256_castps_si256(_mm256_loadu_ps(p));
}
__attribute__((target("avx2"))) inline __m256i load8(const uint16_t* p) {
  return _mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}
__attribute__((target("avx2"))) inline void store8(float* p, __m256i v) {
  _mm256_storeu_ps(p, _mm256_castsi256_ps(v));
}
__attribute__((target("avx2"))) inline void store8(uint16_t* p, __m256i v) {
  // Sign-extend the low 16 bits so that the signed saturating pack passes them on unchanged.
  const __m256i low16 = _mm256_srai_epi32(_mm256_slli_epi32(v, 16), 16);
  const __m128i packed = _mm_packs_epi32(_mm256_castsi256_si128(low16), _mm256_extracti128_si256(low16, 1));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(p), packed);
}

template <typename T>
__attribute__((target("avx2"))) size_t temporal_avx2(T* pixels, T* last, uint8_t* history, size_t n, int phase,
                                                     const TemporalParams& params) {
  constexpr bool kFloat = std::is_same_v<T, float>;
  const __m256i zero = _mm256_setzero_si256();
  const __m256i all = _mm256_set1_epi32(-1);
  const __m256i mask = _mm256_set1_epi32(1 << phase);
  const __m256 alpha = _mm256_set1_ps(params.alpha);
  const __m256 one_minus_alpha = _mm256_set1_ps(1.0F - params.alpha);
  const __m256 delta_f = _mm256_set1_ps(static_cast<float>(params.delta));
  const __m256i delta_i = _mm256_set1_epi32(params.delta);
  const PersistenceRule rule = persistence_rule(params.persistence, phase);
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256i current = load8(pixels + i);
    const __m256i previous = load8(last + i);
    const __m256i old_history = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(history + i)));
    __m256i current_valid, previous_valid, close, blended;
    if constexpr (kFloat) {
      const __m256 c = _mm256_castsi256_ps(current);
      const __m256 p = _mm256_castsi256_ps(previous);
      // Unordered not-equal and ordered less-than: cmpneqps and cmpltps of the SSE2 loop.
      current_valid = _mm256_castps_si256(_mm256_cmp_ps(c, _mm256_setzero_ps(), _CMP_NEQ_UQ));
      previous_valid = _mm256_castps_si256(_mm256_cmp_ps(p, _mm256_setzero_ps(), _CMP_NEQ_UQ));
      const __m256 difference = _mm256_andnot_ps(_mm256_set1_ps(-0.0F), _mm256_sub_ps(c, p));
      close = _mm256_castps_si256(_mm256_cmp_ps(difference, delta_f, _CMP_LT_OS));
      blended = _mm256_castps_si256(_mm256_add_ps(_mm256_mul_ps(alpha, c), _mm256_mul_ps(one_minus_alpha, p)));
    } else {
      current_valid = _mm256_xor_si256(_mm256_cmpeq_epi32(current, zero), all);
      previous_valid = _mm256_xor_si256(_mm256_cmpeq_epi32(previous, zero), all);
      close = _mm256_cmpgt_epi32(delta_i, _mm256_abs_epi32(_mm256_sub_epi32(current, previous)));
      const __m256 f = _mm256_add_ps(_mm256_mul_ps(alpha, _mm256_cvtepi32_ps(current)),
                                     _mm256_mul_ps(one_minus_alpha, _mm256_cvtepi32_ps(previous)));
      blended = _mm256_cvttps_epi32(f);  // truncated, as the SDK
    }
    const __m256i agree = _mm256_and_si256(_mm256_and_si256(current_valid, previous_valid), close);
    const __m256i updated = select8(agree, blended, current);
    const __m256i fill = _mm256_and_si256(previous_valid, persistence_allows_avx2(old_history, rule));
    store8(pixels + i, select8(current_valid, updated, select8(fill, previous, current)));
    store8(last + i, select8(current_valid, updated, previous));
    const __m256i new_history = select8(current_valid, select8(agree, _mm256_or_si256(old_history, mask), mask),
                                        _mm256_andnot_si256(mask, old_history));
    // Bytes 0–7 of the history: pack 32 → 16 → 8 bits (values < 256, so nothing saturates).
    const __m128i words = _mm_packs_epi32(_mm256_castsi256_si128(new_history), _mm256_extracti128_si256(new_history, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(history + i), _mm_packus_epi16(words, words));
  }
  return i;
}
#endif

}  // namespace

void TemporalFilter::reset() { has_state_ = false; }

template <typename T>
void TemporalFilter::apply_to(T* pixels, int width, int height, bool disparity) {
  const size_t n = static_cast<size_t>(width) * height;
  std::vector<T>* last_storage = nullptr;
  if constexpr (std::is_same_v<T, float>) {
    last_storage = &last_disparity_;
  } else {
    last_storage = &last_depth_;
  }
  std::vector<T>& last_vector = *last_storage;
  if (!has_state_ || width != width_ || height != height_ || disparity != disparity_ || !same(params, state_params_)) {
    last_vector.assign(n, T{0});  // reuses the capacity of the previous stream
    history_.assign(n, 0);
    fill_lut_ = persistence_lut(params.persistence);
    state_params_ = params;
    width_ = width;
    height_ = height;
    disparity_ = disparity;
    phase_ = 0;
    has_state_ = true;
  }
  const T delta = static_cast<T>(params.delta);
  const float alpha = params.alpha;
  const float one_minus_alpha = 1.0F - alpha;
  const auto mask = static_cast<uint8_t>(1U << phase_);
  T* last = last_vector.data();
  uint8_t* history = history_.data();
  size_t i = 0;
#if HRCSENSE_FILTERS_X86
  if (filters_detail::use_avx2()) i = temporal_avx2(pixels, last, history, n, phase_, params);
#endif
#if defined(__SSE2__)
  i += temporal_sse2(pixels + i, last + i, history + i, n - i, phase_, params);
#endif
  for (; i < n; ++i) {
    const T current = pixels[i];
    const T previous = last[i];
    if (current != T{0}) {
      if (previous != T{0} && abs_difference(current, previous) < delta) {
        history[i] |= mask;
        // Truncated for uint16 (no +0.5, unlike the spatial filter), as the SDK.
        const T result = static_cast<T>(alpha * static_cast<float>(current) + one_minus_alpha * static_cast<float>(previous));
        pixels[i] = result;
        last[i] = result;
      } else {
        last[i] = current;  // first sample or a jump: start over, forgetting older frames
        history[i] = mask;
      }
    } else {
      // A filled hole keeps `last` unchanged.
      if (previous != T{0} && (fill_lut_[history[i]] & mask) != 0) pixels[i] = previous;
      history[i] = static_cast<uint8_t>(history[i] & ~mask);
    }
  }
  phase_ = (phase_ + 1) % 8;
}

void TemporalFilter::apply(DepthImage& depth) { apply_to(depth.pixels.data(), depth.width, depth.height, false); }

void TemporalFilter::apply(DisparityImage& disparity) {
  apply_to(disparity.pixels.data(), disparity.width, disparity.height, true);
}

}  // namespace hrcsense
