// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's hole-filling filter (spec §7): in place, raster order, looking
// only up-left, up, left, down-left and down (never right).
#include "hrcsense/filters.hpp"

#include <algorithm>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {
namespace {

[[maybe_unused]] bool empty(uint16_t value) { return value == 0; }
bool empty(float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits == 0;  // only +0.0, as the SDK's integer test of the bits
}

// Mode 0: a hole takes its (possibly just filled) left neighbour; column 0 is never filled.
template <typename T>
void fill_from_left(T* pixels, int w, int h) {
  for (int v = 0; v < h; ++v) {
    T* row = pixels + static_cast<size_t>(v) * w;
    for (int u = 1; u < w; ++u) {
      if (empty(row[u])) row[u] = row[u - 1];
    }
  }
}

// Modes 1 and 2 over rows 1..h-2 and columns 1..w-1. Farthest: the largest of the five
// neighbours. Nearest: starts from the pixel above even when it is empty (SDK quirk), then
// takes any smaller non-empty neighbour.
template <typename T>
void fill_from_around(T* pixels, int w, int h, bool farthest) {
  for (int v = 1; v + 1 < h; ++v) {
    T* row = pixels + static_cast<size_t>(v) * w;
    const T* up = row - w;
    const T* down = row + w;
    for (int u = 1; u < w; ++u) {
      if (!empty(row[u])) continue;
      const T neighbours[4] = {up[u - 1], row[u - 1], down[u - 1], down[u]};
      T best = up[u];
      for (const T value : neighbours) {
        if (farthest ? value > best : (!empty(value) && value < best)) best = value;
      }
      row[u] = best;
    }
  }
}

#if defined(__SSE2__)
inline __m128i load8(const uint16_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); }
inline __m128i select(__m128i mask, __m128i a, __m128i b) {
  return _mm_or_si128(_mm_and_si128(mask, a), _mm_andnot_si128(mask, b));
}
inline __m128i min_u16(__m128i a, __m128i b) { return _mm_sub_epi16(a, _mm_subs_epu16(a, b)); }
inline __m128i max_u16(__m128i a, __m128i b) { return _mm_add_epi16(b, _mm_subs_epu16(a, b)); }

// Mode 0, 8 pixels at a time: each hole takes the nearest non-hole to its left, found in three
// doubling steps (1, 2, 4 lanes); lanes shifted in from before the block, and holes with no
// non-hole left of them in the block, take `carry`, the finished pixel left of the block.
// Column 0 is never filled.
void fill_from_left(uint16_t* pixels, int w, int h) {
  const __m128i zero = _mm_setzero_si128();
  for (int v = 0; v < h; ++v) {
    uint16_t* row = pixels + static_cast<size_t>(v) * w;
    int u = 1;
    for (; u + 8 <= w; u += 8) {
      __m128i x = load8(row + u);
      if (_mm_movemask_epi8(_mm_cmpeq_epi16(x, zero)) == 0) continue;
      const __m128i carry = _mm_set1_epi16(static_cast<int16_t>(row[u - 1]));
      x = select(_mm_cmpeq_epi16(x, zero), _mm_or_si128(_mm_slli_si128(x, 2), _mm_srli_si128(carry, 14)), x);
      x = select(_mm_cmpeq_epi16(x, zero), _mm_or_si128(_mm_slli_si128(x, 4), _mm_srli_si128(carry, 12)), x);
      x = select(_mm_cmpeq_epi16(x, zero), _mm_or_si128(_mm_slli_si128(x, 8), _mm_srli_si128(carry, 8)), x);
      x = select(_mm_cmpeq_epi16(x, zero), carry, x);  // a hole with only holes left of it in the block
      _mm_storeu_si128(reinterpret_cast<__m128i*>(row + u), x);
    }
    for (; u < w; ++u) {
      if (row[u] == 0) row[u] = row[u - 1];
    }
  }
}

// Modes 1 and 2, 8 pixels at a time. The candidate of each hole is computed from up-left, up,
// down-left, down and the *unfilled* left pixel; a hole right of another hole (inside the
// block) then combines its candidate with the finished left pixel, in order. For the first
// pixel of a block the left pixel is already finished. Nearest uses v − 1 (wrapping), which
// turns holes into 65535 and so ignores them, and keeps a hole whose upper pixel is a hole.
void fill_from_around(uint16_t* pixels, int w, int h, bool farthest) {
  const __m128i zero = _mm_setzero_si128();
  const __m128i one = _mm_set1_epi16(1);
  for (int v = 1; v + 1 < h; ++v) {
    uint16_t* row = pixels + static_cast<size_t>(v) * w;
    const uint16_t* up = row - w;
    const uint16_t* down = row + w;
    int u = 1;
    for (; u + 8 <= w; u += 8) {
      const __m128i current = load8(row + u);
      const __m128i hole = _mm_cmpeq_epi16(current, zero);
      const int holes = _mm_movemask_epi8(hole);
      if (holes == 0) continue;
      const __m128i above = load8(up + u);
      const __m128i n0 = load8(up + u - 1), n1 = load8(row + u - 1), n2 = load8(down + u - 1), n3 = load8(down + u);
      __m128i candidate;
      if (farthest) {
        candidate = max_u16(max_u16(max_u16(above, n0), max_u16(n1, n2)), n3);
      } else {
        const __m128i m = min_u16(min_u16(min_u16(_mm_sub_epi16(above, one), _mm_sub_epi16(n0, one)),
                                          min_u16(_mm_sub_epi16(n1, one), _mm_sub_epi16(n2, one))),
                                  _mm_sub_epi16(n3, one));
        candidate = _mm_andnot_si128(_mm_cmpeq_epi16(above, zero), _mm_add_epi16(m, one));
      }
      _mm_storeu_si128(reinterpret_cast<__m128i*>(row + u), select(hole, candidate, current));
      // Holes whose left neighbour (in this block) was a hole too: two mask bits per lane.
      int chained = holes & (holes << 2) & 0xFFFC;
      while (chained != 0) {
        const int lane = __builtin_ctz(static_cast<unsigned>(chained)) / 2;
        chained &= ~(3 << (2 * lane));
        uint16_t& pixel = row[u + lane];
        const uint16_t left = row[u + lane - 1];
        if (farthest) {
          pixel = std::max(pixel, left);
        } else if (pixel != 0 && left != 0) {
          pixel = std::min(pixel, left);
        }
      }
    }
    for (; u < w; ++u) {
      if (row[u] != 0) continue;
      const uint16_t neighbours[4] = {up[u - 1], row[u - 1], down[u - 1], down[u]};
      uint16_t best = up[u];
      for (const uint16_t value : neighbours) {
        if (farthest ? value > best : (value != 0 && value < best)) best = value;
      }
      row[u] = best;
    }
  }
}
#endif

template <typename T>
void fill(const HoleFillingParams& params, T* pixels, int w, int h) {
  if (params.mode == 0) {
    fill_from_left(pixels, w, h);
  } else {
    fill_from_around(pixels, w, h, params.mode == 1);
  }
}

}  // namespace

void fill_holes(const HoleFillingParams& params, DepthImage& depth) {
  fill(params, depth.pixels.data(), depth.width, depth.height);
}

void fill_holes(const HoleFillingParams& params, DisparityImage& disparity) {
  fill(params, disparity.pixels.data(), disparity.width, disparity.height);
}

}  // namespace hrcsense
