// SPDX-License-Identifier: Apache-2.0
// Random depth and disparity images for the filters' property tests (fast_test.cpp and
// tests/filters_alignment/alignment_test.cpp): patches, edges, noise, holes and the values the SDK treats specially.
#pragma once

#include "hrcsense/filters.hpp"

#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace hrcsense::test {

/// Disparity factor of the random images: 50 mm, fx 418.26, 1 mm units.
inline constexpr float kFactor = 669216.0F;

/// A depth-like image: flat patches at several depths (edges between them), noise of a few
/// units, holes alone and in runs, and the values the SDK treats specially (1, values < δ).
inline DepthImage random_depth(std::mt19937& rng, int w, int h) {
  std::uniform_int_distribution<int> base(0, 3);
  std::uniform_int_distribution<int> noise(-12, 12);
  std::uniform_int_distribution<int> kind(0, 99);
  DepthImage d;
  d.resize(w, h);
  const int bases[4] = {800, 1000, 1030, 2500};
  int run = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int k = kind(rng);
      uint16_t value = static_cast<uint16_t>(bases[(u / 5 + v / 4 + base(rng) / 3) % 4] + noise(rng));
      if (run > 0) {
        value = 0;
        --run;
      } else if (k < 8) {
        value = 0;
      } else if (k < 11) {
        run = k;  // a run of holes
        value = 0;
      } else if (k < 12) {
        value = 1;
      } else if (k < 13) {
        value = static_cast<uint16_t>(2 + k % 9);  // below δ: the top→bottom pass blends it with 0
      }
      d.pixels[static_cast<size_t>(v) * w + u] = value;
    }
  }
  return d;
}

/// Disparity from random depth; with `special`, a sprinkling of the floats the SDK's bit tests
/// single out (−0, negative, denormal, infinity, NaNs).
inline DisparityImage random_disparity(std::mt19937& rng, int w, int h, bool special) {
  DisparityImage d;
  depth_to_disparity(random_depth(rng, w, h), kFactor, d);
  if (special) {
    const float values[] = {-0.0F, -5.0F, 1e-41F, std::numeric_limits<float>::infinity(),
                            std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::quiet_NaN()};
    std::uniform_int_distribution<size_t> where(0, d.pixels.size() - 1);
    for (const float value : values) d.pixels[where(rng)] = value;
  }
  return d;
}

/// Bit-for-bit equality of float buffers (NaNs and −0 included).
inline bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace hrcsense::test
