// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — what the spatial filter's two domains share (internal): the caller's
// scratch as raw pointers, and the transposition of a strip of rows that lets the horizontal
// passes filter kStrip rows side by side (spatial_depth.cpp, spatial_disparity.cpp).
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
