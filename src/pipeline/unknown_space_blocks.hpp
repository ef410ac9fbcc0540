// SPDX-License-Identifier: Apache-2.0
// hrcsense — unknown space, the pixel kinds of a block of 16 pixels at once (internal to
// src/pipeline/unknown_space.cpp; tests/pipeline checks the SSE2 variant against the plain one).
//
// Most of a frame is measured background and most of the rest is one of a few kinds that need
// no further work (the table that was never reliably seen, the robot's envelope); classifying
// pixel by pixel cost a branch per pixel, and those branches follow the sensor's noise, so they
// were mispredicted. A block's kinds are bit masks (bit k = pixel first + k) combined without
// branches; only the pixels that need work are then visited.
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense::unknown_space_detail {

inline constexpr int kBlockPx = 16;

/// One frame's per-pixel inputs; the optional ones are null where absent.
struct BlockInputs {
  const uint16_t* raw = nullptr;                ///< depth now, 0 = no depth
  const uint8_t* foreground_mask = nullptr;     ///< 1 = foreground (optional)
  const uint16_t* envelope_from_raw = nullptr;  ///< the robot's envelope: nonzero inside (optional)
  const float* background_m = nullptr;          ///< background mean, m (> 0: known)
  /// ReliableBackground::bits: pixel i reliable when bit i % 8 of byte i / 8 is set (optional:
  /// none is).
  const uint8_t* reliable_bits = nullptr;
};

/// The reliable bits of pixels [first, first + 16) (bit k: pixel first + k); ReliableBackground
/// pads its bytes so that the three bytes read here exist for every pixel.
inline uint32_t reliable_bits16(const uint8_t* bits, size_t first) {
  const uint8_t* b = bits + first / 8;
  const uint32_t word = uint32_t{b[0]} | (uint32_t{b[1]} << 8) | (uint32_t{b[2]} << 16);
  return (word >> (first % 8)) & 0xFFFFU;
}

/// The raw tests of a block, one bit per pixel.
struct BlockBits {
  uint32_t no_depth = 0;    ///< raw == 0
  uint32_t envelope = 0;    ///< in the robot's envelope
  uint32_t foreground = 0;  ///< in the foreground mask
  /// A reliable background (reliable_bits); only where no_depth outside the envelope, else 0.
  uint32_t reliable = 0;
};

/// The kinds unknown_space() treats differently, disjoint, one bit per pixel.
struct BlockKinds {
  uint32_t envelope = 0;     ///< the arm and its edges: never unknown, and where its shadow starts
  uint32_t hidden = 0;       ///< foreground: unknown behind it
  uint32_t gap = 0;          ///< no depth over a reliable background: shadow, dropout or unknown
  uint32_t never_valid = 0;  ///< no depth over a background that was not reliable
};

inline BlockKinds kinds_of(const BlockBits& b) {
  BlockKinds k;
  k.envelope = b.envelope;
  k.hidden = ~b.envelope & ~b.no_depth & b.foreground;
  k.gap = ~b.envelope & b.no_depth & b.reliable;
  k.never_valid = ~b.envelope & b.no_depth & ~b.reliable;
  return k;
}

/// The tests of pixels [first, first + count), count ≤ kBlockPx, one at a time.
inline BlockBits block_bits_plain(const BlockInputs& in, size_t first, int count) {
  BlockBits b;
  for (int k = 0; k < count; ++k) {
    const size_t i = first + static_cast<size_t>(k);
    const uint32_t bit = 1U << k;
    if (in.raw[i] == 0) b.no_depth |= bit;
    const bool envelope = in.envelope_from_raw != nullptr && in.envelope_from_raw[i] != 0;
    if (envelope) b.envelope |= bit;
    if (in.foreground_mask != nullptr && in.foreground_mask[i] != 0) b.foreground |= bit;
    const bool reliable = in.reliable_bits != nullptr && ((in.reliable_bits[i / 8] >> (i % 8)) & 1U) != 0;
    if (in.raw[i] == 0 && !envelope && reliable) b.reliable |= bit;
  }
  return b;
}

#if defined(__SSE2__)
/// The same bits for a whole block with SSE2 (every x86-64 CPU): compares on 8 or 16 lanes,
/// narrowed to bytes and gathered with movemask. Most blocks are measured background only
/// (depth everywhere, no envelope, no foreground): one movemask tells, and they return at
/// once with no bit set. The reliable bits are read only for a block with a pixel without depth
/// outside the envelope.
inline BlockBits block_bits_sse2(const BlockInputs& in, size_t first) {
  const __m128i zero = _mm_setzero_si128(), ones = _mm_cmpeq_epi8(zero, zero);
  const auto load = [](const void* p) { return _mm_loadu_si128(static_cast<const __m128i*>(p)); };
  const auto zero_words = [&](const uint16_t* p) {  // 16 words → 16 bytes, 0xFF where 0
    return _mm_packs_epi16(_mm_cmpeq_epi16(load(p), zero), _mm_cmpeq_epi16(load(p + 8), zero));
  };
  // Bytes 0xFF where: no depth; outside the envelope; not foreground.
  const __m128i no_depth = zero_words(in.raw + first);
  const __m128i outside = in.envelope_from_raw != nullptr ? zero_words(in.envelope_from_raw + first) : ones;
  const __m128i background =
      in.foreground_mask != nullptr ? _mm_cmpeq_epi8(load(in.foreground_mask + first), zero) : ones;
  if (_mm_movemask_epi8(_mm_andnot_si128(no_depth, _mm_and_si128(outside, background))) == 0xFFFF) return {};
  BlockBits b;
  b.no_depth = static_cast<uint32_t>(_mm_movemask_epi8(no_depth));
  b.envelope = ~static_cast<uint32_t>(_mm_movemask_epi8(outside)) & 0xFFFFU;
  b.foreground = ~static_cast<uint32_t>(_mm_movemask_epi8(background)) & 0xFFFFU;
  const uint32_t gaps = b.no_depth & ~b.envelope;
  if (in.reliable_bits != nullptr && gaps != 0) b.reliable = reliable_bits16(in.reliable_bits, first) & gaps;
  return b;
}
#endif

/// Blocks whose quiet test is shared: a row's measured background comes in long runs, and one
/// test of 64 pixels costs about what a block's own did.
inline constexpr int kSpanBlocks = 4;

/// True when pixels [first, first + kSpanBlocks·kBlockPx) are measured background only: depth
/// everywhere, no envelope, no foreground (no bit set in any of their blocks).
inline bool span_quiet_plain(const BlockInputs& in, size_t first) {
  for (size_t i = first; i < first + kSpanBlocks * kBlockPx; ++i) {
    if (in.raw[i] == 0 || (in.envelope_from_raw != nullptr && in.envelope_from_raw[i] != 0) ||
        (in.foreground_mask != nullptr && in.foreground_mask[i] != 0)) {
      return false;
    }
  }
  return true;
}

#if defined(__SSE2__)
/// The same with SSE2: every test ORed into one register, nonzero where a pixel needs work.
inline bool span_quiet_sse2(const BlockInputs& in, size_t first) {
  const __m128i zero = _mm_setzero_si128();
  const auto load = [](const void* p) { return _mm_loadu_si128(static_cast<const __m128i*>(p)); };
  __m128i any = zero;
  for (size_t k = 0; k < kSpanBlocks * kBlockPx; k += 8) {
    any = _mm_or_si128(any, _mm_cmpeq_epi16(load(in.raw + first + k), zero));
    if (in.envelope_from_raw != nullptr) any = _mm_or_si128(any, load(in.envelope_from_raw + first + k));
  }
  for (size_t k = 0; in.foreground_mask != nullptr && k < kSpanBlocks * kBlockPx; k += 16) {
    any = _mm_or_si128(any, load(in.foreground_mask + first + k));
  }
  return _mm_movemask_epi8(_mm_cmpeq_epi8(any, zero)) == 0xFFFF;
}
#endif

inline bool span_quiet(const BlockInputs& in, size_t first) {
#if defined(__SSE2__)
  return span_quiet_sse2(in, first);
#else
  return span_quiet_plain(in, first);
#endif
}

/// A whole block's bits, with SSE2 where the compiler targets it.
inline BlockBits block_bits(const BlockInputs& in, size_t first) {
#if defined(__SSE2__)
  return block_bits_sse2(in, first);
#else
  return block_bits_plain(in, first, kBlockPx);
#endif
}

/// The bits of the first `count` pixels of a row from `row_start` (count < kBlockPx), in a row
/// `width` wide. A row of at least a block reads its first whole block and keeps the low bits:
/// a width that is no multiple of 16 (424 after decimation) left a partial block per row, and
/// testing it pixel by pixel cost a tenth of the stage.
inline BlockBits block_bits_head(const BlockInputs& in, size_t row_start, int count, int width) {
  if (width < kBlockPx) return block_bits_plain(in, row_start, count);
  BlockBits b = block_bits(in, row_start);
  const uint32_t keep = (1U << count) - 1U;
  b.no_depth &= keep;
  b.envelope &= keep;
  b.foreground &= keep;
  b.reliable &= keep;
  return b;
}

}  // namespace hrcsense::unknown_space_detail
