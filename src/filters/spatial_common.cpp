// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the spatial filter's shared parts (spatial_common.hpp): scratch, strip
// transposition (SSE2 where the build has it: 4x4 float and 8x8 uint16 blocks), the hole-fill
// radius and the entry points without a caller's scratch.
#include "spatial_common.hpp"

#include <algorithm>
#include <cstddef>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace hrcsense {
namespace filters_detail {
namespace {

template <typename T>
void grow(std::vector<T>& buffer, size_t size) {
  if (buffer.size() < size) buffer.resize(size);
}

// Columns [u, w) one value at a time: what the vector loops leave over (all of them where the
// build has no SSE2).
template <typename T>
void load_columns(const T* rows, int u, int w, T* strip) {
  for (; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) strip[u * kStrip + g] = rows[static_cast<ptrdiff_t>(g) * w + u];
}

template <typename T>
void store_columns(const T* strip, int u, int w, T* rows) {
  for (; u < w; ++u)
    for (int g = 0; g < kStrip; ++g) rows[static_cast<ptrdiff_t>(g) * w + u] = strip[u * kStrip + g];
}

#if defined(__SSE2__)
// Whole 4x4 (float) or 8x8 (uint16) blocks of columns; returns the first column left over.
int load_blocks(const float* rows, int w, float* strip) {
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
  return u;
}

int store_blocks(const float* strip, int w, float* rows) {
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
  return u;
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

int load_blocks(const uint16_t* rows, int w, uint16_t* strip) {
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
  return u;
}

int store_blocks(const uint16_t* strip, int w, uint16_t* rows) {
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
  return u;
}
#else
template <typename T>
int load_blocks(const T*, int, T*) { return 0; }
template <typename T>
int store_blocks(const T*, int, T*) { return 0; }
#endif

}  // namespace

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

void load_strip(const float* rows, int w, float* strip) {
  load_columns(rows, load_blocks(rows, w, strip), w, strip);
}
void store_strip(const float* strip, int w, float* rows) {
  store_columns(strip, store_blocks(strip, w, rows), w, rows);
}
void load_strip(const uint16_t* rows, int w, uint16_t* strip) {
  load_columns(rows, load_blocks(rows, w, strip), w, strip);
}
void store_strip(const uint16_t* strip, int w, uint16_t* rows) {
  store_columns(strip, store_blocks(strip, w, rows), w, rows);
}

}  // namespace filters_detail

int spatial_holes_radius(int holes_fill) {
  if (holes_fill <= 0) return 0;
  if (holes_fill >= 5) return 255;
  return 1 << holes_fill;
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
