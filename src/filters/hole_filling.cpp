// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's hole-filling filter (spec §7): in place, raster order, looking
// only up-left, up, left, down-left and down (never right).
#include "hrcsense/filters.hpp"

#include <cstring>

namespace hrcsense {
namespace {

bool empty(uint16_t value) { return value == 0; }
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
