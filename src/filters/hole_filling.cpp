// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's hole-filling filter (spec §7): in place, raster order, looking
// only up-left, up, left, down-left and down (never right).
#include "hrcsense/filters.hpp"
#include "isa.hpp"

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
inline __m128i load_u16x8(const uint16_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); }
using filters_detail::select;
using filters_detail::max_u16;
using filters_detail::min_u16;

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
      __m128i x = load_u16x8(row + u);
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
      const __m128i current = load_u16x8(row + u);
      const __m128i hole = _mm_cmpeq_epi16(current, zero);
      const int holes = _mm_movemask_epi8(hole);
      if (holes == 0) continue;
      const __m128i above = load_u16x8(up + u);
      const __m128i n0 = load_u16x8(up + u - 1), n1 = load_u16x8(row + u - 1), n2 = load_u16x8(down + u - 1), n3 = load_u16x8(down + u);
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

#if HRCSENSE_FILTERS_X86
// AVX2, all three modes in two passes per row, because most pixels are valid and holes come in
// runs (dropouts, the left band): a branch per block on "any hole?" mispredicts at every run
// and cost more than the filling. Pass 1, branch-free, 16 pixels at a time: every hole takes
// the value its rule gives with the *unfilled* left neighbour (kept in a register, so no load
// waits for the previous block's store) and the finished row above; a hole that is first in
// its run is then final. Pass 2, per 64 pixels: the holes right of a hole ("chained", one bit
// each) combine, in order, with their finished left neighbour.
constexpr int kFromLeft = 0, kFarthest = 1, kNearest = 2;

// x moved right by one pixel (lane k takes lane k − 1), lane 0 taking the last pixel of `before`.
__attribute__((target("avx2"))) inline __m256i shift_in_left(__m256i x, __m256i before) {
  return _mm256_alignr_epi8(x, _mm256_permute2x128_si256(before, x, 0x21), 14);
}

__attribute__((target("avx2"))) inline __m256i load16(const uint16_t* p) {
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}

// Pass 1 on the 16 pixels at u; returns the hole mask (16-bit lanes).
template <int kMode>
__attribute__((target("avx2"))) inline __m256i fill_block_avx2(uint16_t* row, const uint16_t* up, const uint16_t* down,
                                                               int u, __m256i& previous) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i current = load16(row + u);
  const __m256i hole = _mm256_cmpeq_epi16(current, zero);
  const __m256i left = shift_in_left(current, previous);
  previous = current;
  __m256i candidate = left;
  if (kMode == kFarthest) {
    candidate = _mm256_max_epu16(_mm256_max_epu16(_mm256_max_epu16(load16(up + u), load16(up + u - 1)),
                                                  _mm256_max_epu16(left, load16(down + u - 1))),
                                 load16(down + u));
  } else if (kMode == kNearest) {
    // Holes become 65535 by the wrapping v − 1, so the minimum ignores them; a hole above
    // keeps the pixel a hole (the SDK starts from the pixel above).
    const __m256i one = _mm256_set1_epi16(1);
    const __m256i above = load16(up + u);
    const __m256i m = _mm256_min_epu16(
        _mm256_min_epu16(_mm256_min_epu16(_mm256_sub_epi16(above, one), _mm256_sub_epi16(load16(up + u - 1), one)),
                         _mm256_min_epu16(_mm256_sub_epi16(left, one), _mm256_sub_epi16(load16(down + u - 1), one))),
        _mm256_sub_epi16(load16(down + u), one));
    candidate = _mm256_andnot_si256(_mm256_cmpeq_epi16(above, zero), _mm256_add_epi16(m, one));
  }
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(row + u), _mm256_blendv_epi8(current, candidate, hole));
  return hole;
}

// Pass 2 for one chained hole at u: combine with the finished left neighbour.
template <int kMode>
inline uint16_t chained_value(uint16_t pixel, uint16_t left) {
  if (kMode == kFromLeft) return left;
  if (kMode == kFarthest) return std::max(pixel, left);
  // Nearest keeps the pixel when either is a hole; min(0, left) is 0 already, so only the left
  // one needs a test (a select, not a branch on data).
  const uint16_t smaller = std::min(pixel, left);
  return left != 0 ? smaller : pixel;
}

// One bit per pixel of two blocks' hole masks: the byte pack interleaves by 128-bit lane,
// the permute undoes it.
__attribute__((target("avx2"))) inline uint32_t hole_bits(__m256i a, __m256i b) {
  return static_cast<uint32_t>(_mm256_movemask_epi8(_mm256_permute4x64_epi64(_mm256_packs_epi16(a, b), 0xD8)));
}

// Pass 1 runs over a whole segment of the row before pass 2, so that pass 2's single-pixel
// loads do not meet still-pending 32-byte stores of the same pixels; the chained bits wait here.
constexpr int kSegmentWords = 32;  // 2048 pixels

template <int kMode>
__attribute__((target("avx2"))) void fill_row_avx2(uint16_t* row, const uint16_t* up, const uint16_t* down, int w) {
  // Column 0 is never filled; it is the left neighbour of the first block.
  __m256i previous = _mm256_set1_epi16(static_cast<int16_t>(row[0]));
  uint64_t hole_before = row[0] == 0 ? 1 : 0;  // the hole bit of the pixel left of the word
  const __m256i zero = _mm256_setzero_si256();
  uint64_t chains[kSegmentWords];
  int u = 1;
  while (u + 16 <= w) {
    const int segment_start = u;
    int words = 0;
    for (; u + 16 <= w && words < kSegmentWords; ++words) {
      // 64 pixels (or what is left of 16-pixel blocks) per word.
      uint64_t holes = 0;
      for (int block = 0; block < 4 && u + 16 <= w; block += 2) {
        const __m256i a = fill_block_avx2<kMode>(row, up, down, u, previous);
        u += 16;
        __m256i b = zero;
        if (u + 16 <= w) {
          b = fill_block_avx2<kMode>(row, up, down, u, previous);
          u += 16;
        }
        holes |= static_cast<uint64_t>(hole_bits(a, b)) << (16 * block);
      }
      // Chained: a hole whose left neighbour is a hole. Bits past the row's last block are 0.
      chains[words] = holes & ((holes << 1) | hole_before);
      hole_before = holes >> 63;
    }
    // Inside a run the left neighbour is the value just written: taken from a register rather
    // than reloaded, so a run is not a chain of store-to-load round trips.
    int last = -1;
    uint16_t last_value = 0;
    for (int k = 0; k < words; ++k) {
      for (uint64_t bits = chains[k]; bits != 0; bits &= bits - 1) {
        const int at = segment_start + 64 * k + __builtin_ctzll(bits);
        const uint16_t left = at == last + 1 ? last_value : row[at - 1];
        last_value = chained_value<kMode>(row[at], left);
        row[at] = last_value;
        last = at;
      }
    }
  }
  for (; u < w; ++u) {
    if (row[u] != 0) continue;
    if (kMode == kFromLeft) {
      row[u] = row[u - 1];
      continue;
    }
    const uint16_t neighbours[4] = {up[u - 1], row[u - 1], down[u - 1], down[u]};
    uint16_t best = up[u];
    for (const uint16_t value : neighbours) {
      if (kMode == kFarthest ? value > best : (value != 0 && value < best)) best = value;
    }
    row[u] = best;
  }
}

template <int kMode>
__attribute__((target("avx2"))) void fill_avx2(uint16_t* pixels, int w, int h) {
  // Modes 1 and 2 skip the first and last rows.
  const int first = kMode == kFromLeft ? 0 : 1;
  const int end = kMode == kFromLeft ? h : h - 1;
  if (w < 1) return;
  for (int v = first; v < end; ++v) {
    uint16_t* row = pixels + static_cast<size_t>(v) * w;
    // Mode 0 never reads the rows above and below; pass the row itself so no pointer leaves the image.
    const uint16_t* up = kMode == kFromLeft ? row : row - w;
    const uint16_t* down = kMode == kFromLeft ? row : row + w;
    fill_row_avx2<kMode>(row, up, down, w);
  }
}

bool fill_holes_avx2(int mode, uint16_t* pixels, int w, int h) {
  if (!filters_detail::use_avx2()) return false;
  if (mode == 0) {
    fill_avx2<kFromLeft>(pixels, w, h);
  } else if (mode == 1) {
    fill_avx2<kFarthest>(pixels, w, h);
  } else {
    fill_avx2<kNearest>(pixels, w, h);
  }
  return true;
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
#if HRCSENSE_FILTERS_X86
  if (fill_holes_avx2(params.mode, depth.pixels.data(), depth.width, depth.height)) return;
#endif
  fill(params, depth.pixels.data(), depth.width, depth.height);
}

void fill_holes(const HoleFillingParams& params, DisparityImage& disparity) {
  fill(params, disparity.pixels.data(), disparity.width, disparity.height);
}

}  // namespace hrcsense
