// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — what the spatial filter's two domains share (internal): the caller's
// scratch as raw pointers, and the transposition of a strip of rows that lets the horizontal
// passes filter kStrip rows side by side (spatial_depth.cpp, spatial_disparity.cpp).
//
// Speed without changing a bit of the result (tests/filters/fast_test.cpp checks both domains
// against the plain reference, on the SSE2 and the AVX2 path): each scan is a recursion along a
// line, so many lines are filtered side by side. The vertical passes run across a whole image row
// at once (the lines are the columns, adjacent in memory). The horizontal passes copy a strip of
// kStrip rows into a small transposed buffer (column-major, hot in L1), run the same kind of scan
// there with the rows side by side, and copy it back. No branches in the inner loops (selects), no
// double.
#pragma once

#include "hrcsense/filters.hpp"

#include <cstdint>

namespace hrcsense::filters_detail {

inline constexpr int kStrip = 16;  ///< rows filtered side by side in a horizontal pass

/// The caller's SpatialScratch, sized for a width, as raw pointers for the loops. Holds no
/// result: every call overwrites what it reads.
template <typename T>
struct Scratch {
  T* strip;         ///< kStrip rows, transposed: strip[column * kStrip + row]
  T* previous_raw;  ///< disparity: the previous line's unfiltered values
  uint16_t* fill;   ///< depth: hole-fill counter of every line (saturating)
};

/// `s` grown (never shrunk) for rows of `width` pixels.
Scratch<uint16_t> depth_scratch(SpatialScratch& s, int width);
Scratch<float> disparity_scratch(SpatialScratch& s, int width);

/// kStrip consecutive rows of width `w` into `strip` (column-major), and back.
void load_strip(const float* rows, int w, float* strip);
void store_strip(const float* strip, int w, float* rows);
void load_strip(const uint16_t* rows, int w, uint16_t* strip);
void store_strip(const uint16_t* strip, int w, uint16_t* rows);

}  // namespace hrcsense::filters_detail
