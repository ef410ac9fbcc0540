// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — decimation (spec §4): lower median of the non-zero pixels of each block
// for magnitudes 2–3, their truncated integer mean otherwise; output padded to multiples of 4.
#include "hrcsense/filters.hpp"

#include <algorithm>
#include <cassert>

namespace hrcsense {
namespace {

int ceil4(int n) { return (n + 3) / 4 * 4; }

// The lower median of the first n values (n <= 9): the element at index (n-1)/2 once sorted.
// Insertion sort: at most 9 values.
uint16_t lower_median(uint16_t* values, int n) {
  for (int i = 1; i < n; ++i) {
    const uint16_t value = values[i];
    int j = i;
    for (; j > 0 && values[j - 1] > value; --j) values[j] = values[j - 1];
    values[j] = value;
  }
  return values[(n - 1) / 2];
}

}  // namespace

void decimate(const DecimationParams& params, const DepthImage& in, const Intrinsics& in_intrinsics,
              DepthImage& out, Intrinsics& out_intrinsics) {
  assert(&in != &out);
  const int s = std::clamp(params.magnitude, 1, 8);
  const int real_w = in.width / s;
  const int real_h = in.height / s;
  out.depth_scale_m = in.depth_scale_m;
  out.resize(ceil4(real_w), ceil4(real_h));
  std::fill(out.pixels.begin(), out.pixels.end(), uint16_t{0});
  const bool median = s == 2 || s == 3;
  uint16_t block[9];
  for (int j = 0; j < real_h; ++j) {
    for (int i = 0; i < real_w; ++i) {
      int count = 0;
      uint32_t sum = 0;
      for (int y = j * s; y < j * s + s; ++y) {
        const uint16_t* row = in.pixels.data() + static_cast<size_t>(y) * in.width + static_cast<size_t>(i) * s;
        for (int x = 0; x < s; ++x) {
          if (row[x] == 0) continue;  // holes never pull the result down
          if (median) block[count] = row[x];
          sum += row[x];
          ++count;
        }
      }
      uint16_t value = 0;
      if (count > 0) value = median ? lower_median(block, count) : static_cast<uint16_t>(sum / static_cast<uint32_t>(count));
      out.pixels[static_cast<size_t>(j) * out.width + i] = value;
    }
  }
  out_intrinsics = in_intrinsics;
  const float scale = static_cast<float>(s);
  out_intrinsics.width = out.width;
  out_intrinsics.height = out.height;
  out_intrinsics.fx = in_intrinsics.fx / scale;
  out_intrinsics.fy = in_intrinsics.fy / scale;
  out_intrinsics.ppx = in_intrinsics.ppx / scale;
  out_intrinsics.ppy = in_intrinsics.ppy / scale;
}

}  // namespace hrcsense
