// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — which instruction set the fast paths may use (internal). The baseline is
// x86-64 (SSE2); where the CPU has AVX2, some loops take a wider copy of the same arithmetic,
// chosen at run time, so that one portable binary is fast on current CPUs. IEEE division,
// multiplication, addition and conversion give the same bits in any vector width, so the
// choice never changes a result (tests/filters/fast_test.cpp runs both against the references).
#pragma once

#if (defined(__x86_64__) || defined(__i386__)) && defined(__SSE2__)
#define HRCSENSE_FILTERS_X86 1
#include <immintrin.h>
#else
#define HRCSENSE_FILTERS_X86 0
#endif

namespace hrcsense::filters_detail {

/// True when the AVX2 loops may run: the CPU has AVX2 and set_filter_isa() did not force the
/// portable path. Always false on other architectures.
bool use_avx2();

#if HRCSENSE_FILTERS_X86
// Unsigned 16-bit min and max from SSE2's saturating subtraction (one instruction only from SSE4.1).
inline __m128i min_u16(__m128i a, __m128i b) { return _mm_sub_epi16(a, _mm_subs_epu16(a, b)); }
inline __m128i max_u16(__m128i a, __m128i b) { return _mm_add_epi16(b, _mm_subs_epu16(a, b)); }
// Per bit: a where mask is set, b elsewhere.
inline __m128i select(__m128i mask, __m128i a, __m128i b) {
  return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
}
#endif

}  // namespace hrcsense::filters_detail
