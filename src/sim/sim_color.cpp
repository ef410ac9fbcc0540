// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulated D435's colour camera: its intrinsics and its flat-shaded image.

#include "sim_color.hpp"

#include "hrcsense/sim/sim.hpp"

#include <cstring>

namespace hrcsense {
namespace {

/// A calibrated colour row of specs/d435-sensor-model.md §2 (test D435i).
struct ColorRow {
  int width, height;
  float fx, fy, ppx, ppy;
};
constexpr ColorRow k1280x720{1280, 720, 908.09F, 908.42F, 646.97F, 361.90F};
constexpr ColorRow k640x480{640, 480, 605.39F, 605.61F, 324.64F, 241.27F};

/// The colour sensor makes its other modes by scaling its full frame and cropping about the
/// centre, so a mode's intrinsics are the row's scaled by s = height / row height, with the
/// principal point moved by the crop. Pixel centres are at integers, edges at −0.5, so
/// positions scale as (p + 0.5)·s − 0.5.
Intrinsics scaled(const ColorRow& row, int width, int height) {
  const float s = static_cast<float>(height) / static_cast<float>(row.height);
  const float crop_x = 0.5F * (static_cast<float>(row.width) * s - static_cast<float>(width));
  Intrinsics in;
  in.width = width;
  in.height = height;
  in.fx = row.fx * s;
  in.fy = row.fy * s;
  in.ppx = (row.ppx + 0.5F) * s - 0.5F - crop_x;
  in.ppy = (row.ppy + 0.5F) * s - 0.5F;
  in.model = Distortion::inverse_brown_conrady;  // as the camera reports it, coefficients 0
  return in;
}

}  // namespace

std::optional<Intrinsics> d435_color_intrinsics(int width, int height) {
  if (width == 640 && height == 480) return scaled(k640x480, width, height);
  if (width == 320 && height == 240) return scaled(k640x480, width, height);
  static constexpr std::array<std::array<int, 2>, 7> kWide{
      {{1920, 1080}, {1280, 720}, {960, 540}, {848, 480}, {640, 360}, {480, 270}, {424, 240}}};
  for (const auto& mode : kWide) {
    if (mode[0] == width && mode[1] == height) return scaled(k1280x720, width, height);
  }
  return std::nullopt;
}

namespace sim_detail {

void write_color(const std::vector<uint16_t>& ids, const std::vector<std::array<uint8_t, 3>>& color_of_id, int width,
                 int height, ColorImage& out) {
  out.width = width;
  out.height = height;
  const size_t n = static_cast<size_t>(width) * height;
  out.rgb.resize(n * 3);
  uint8_t* rgb = out.rgb.data();
  const std::array<uint8_t, 3>* colors = color_of_id.data();
  if (n == 0) return;
  std::array<uint32_t, 256> packed{};
  if (color_of_id.size() > packed.size()) {
    for (size_t i = 0; i < n; ++i) std::memcpy(rgb + 3 * i, colors[ids[i]].data(), 3);
    return;
  }
  // Each colour as 4 bytes stored at once, the fourth spilling into the next pixel, which
  // overwrites it: a load and a store per pixel instead of three of each.
  for (size_t k = 0; k < color_of_id.size(); ++k) std::memcpy(&packed[k], colors[k].data(), 3);
  const uint16_t* id = ids.data();
  for (size_t i = 0; i + 1 < n; ++i) std::memcpy(rgb + 3 * i, &packed[id[i]], 4);
  std::memcpy(rgb + 3 * (n - 1), &packed[id[n - 1]], 3);
}

}  // namespace sim_detail
}  // namespace hrcsense
