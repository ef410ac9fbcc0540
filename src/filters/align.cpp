// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — depth ↔ colour alignment (specs/deprojection-and-alignment.md §6–§7).
// Compiled with -ffp-contract=off like the other filters: every pixel position is computed in
// float32 in the SDK's operation order, so footprints match the SDK's to the pixel.
#include "hrcsense/align.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>

namespace hrcsense {
namespace {

bool same_intrinsics(const Intrinsics& a, const Intrinsics& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.ppx == b.ppx &&
         a.ppy == b.ppy && a.model == b.model && a.coeffs == b.coeffs;
}

bool matches(const DepthImage& depth, const Intrinsics& intrinsics) {
  return depth.width == intrinsics.width && depth.height == intrinsics.height &&
         depth.pixels.size() == static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height);
}

/// Whether project() reduces to x/z·fx + ppx exactly: no model, or a Brown-Conrady model whose
/// coefficients are all exactly 0 (its distortion then multiplies by 1 and adds 0). Not
/// is_pinhole(), which also accepts coefficients below FLT_EPSILON that still move a pixel.
bool projects_as_pinhole(const Intrinsics& in) {
  if (in.model == Distortion::none) return true;
  const bool brown = in.model == Distortion::brown_conrady || in.model == Distortion::inverse_brown_conrady ||
                     in.model == Distortion::modified_brown_conrady;
  return brown && std::all_of(in.coeffs.begin(), in.coeffs.end(), [](float c) { return c == 0.0F; });
}

/// project() with its pinhole case inline: the division and multiply-add of the SDK's
/// rs2_project_point_to_pixel, in the same order, so the result is the same to the bit.
std::optional<Eigen::Vector2f> project_fast(const Intrinsics& in, bool pinhole, const Eigen::Vector3f& p) {
  if (!pinhole) return project(in, p);
  if (!(p.z() > 0.0F)) return std::nullopt;
  return Eigen::Vector2f(p.x() / p.z() * in.fx + in.ppx, p.y() / p.z() * in.fy + in.ppy);
}

/// The SDK's `int(p + 0.5f)` (truncation toward zero) for a corner coordinate `p`, or false
/// when the result would lie outside [0, size): such a corner either rejects the pixel (spec §6
/// step 4) or leaves its footprint empty, so both cases give "no footprint". Deciding on the
/// float first also keeps the conversion defined for huge values and NaN.
bool corner_index(float p, int size, int& index) {
  const float shifted = p + 0.5F;
  if (!(shifted > -1.0F && shifted < static_cast<float>(size))) return false;
  index = static_cast<int>(shifted);  // truncation: -1 < shifted < 0 gives 0, as in the SDK
  return true;
}

}  // namespace

Eigen::Vector3f transform_point(const Extrinsics& a_to_b, const Eigen::Vector3f& point_a) {
  const std::array<float, 9>& r = a_to_b.rotation;
  const std::array<float, 3>& t = a_to_b.translation_m;
  const float x = point_a.x(), y = point_a.y(), z = point_a.z();
  return {r[0] * x + r[3] * y + r[6] * z + t[0], r[1] * x + r[4] * y + r[7] * z + t[1],
          r[2] * x + r[5] * y + r[8] * z + t[2]};
}

bool DepthCornerRays::prepare(const Intrinsics& depth_intrinsics) {
  if (valid_ && same_intrinsics(intrinsics_, depth_intrinsics)) return true;
  intrinsics_ = depth_intrinsics;
  valid_ = false;
  const int w = depth_intrinsics.width, h = depth_intrinsics.height;
  if (w <= 0 || h <= 0) return false;
  const size_t corners = static_cast<size_t>(w + 1) * static_cast<size_t>(h + 1);
  x_.resize(corners);
  y_.resize(corners);
  size_t i = 0;
  for (int v = 0; v <= h; ++v) {
    for (int u = 0; u <= w; ++u, ++i) {
      // Deprojecting at z = 1 gives the ray; deproject() scales it by z as its last step, so
      // z · ray later is the SDK's deprojection at depth z to the bit.
      const std::optional<Eigen::Vector3f> ray = deproject(
          depth_intrinsics, Eigen::Vector2f(static_cast<float>(u) - 0.5F, static_cast<float>(v) - 0.5F), 1.0F);
      if (!ray) return false;
      x_[i] = ray->x();
      y_[i] = ray->y();
    }
  }
  valid_ = true;
  return true;
}

ColorFootprint DepthCornerRays::footprint(int u, int v, float z_m, const Intrinsics& color_intrinsics,
                                          const Extrinsics& depth_to_color) const {
  const size_t stride = static_cast<size_t>(intrinsics_.width) + 1;
  const size_t a = static_cast<size_t>(v) * stride + static_cast<size_t>(u);  // corner (u − ½, v − ½)
  const size_t b = a + stride + 1;                                             // corner (u + ½, v + ½)
  const bool pinhole = projects_as_pinhole(color_intrinsics);
  const std::optional<Eigen::Vector2f> pa =
      project_fast(color_intrinsics, pinhole, transform_point(depth_to_color, {z_m * x_[a], z_m * y_[a], z_m}));
  const std::optional<Eigen::Vector2f> pb =
      project_fast(color_intrinsics, pinhole, transform_point(depth_to_color, {z_m * x_[b], z_m * y_[b], z_m}));
  if (!pa || !pb) return {};  // behind the colour camera
  ColorFootprint box;
  if (!corner_index(pa->x(), color_intrinsics.width, box.x0) ||
      !corner_index(pa->y(), color_intrinsics.height, box.y0) ||
      !corner_index(pb->x(), color_intrinsics.width, box.x1) ||
      !corner_index(pb->y(), color_intrinsics.height, box.y1)) {
    return {};
  }
  return box;
}

void AlignDepthToColor::apply(const DepthImage& depth, const Intrinsics& depth_intrinsics,
                              const Intrinsics& color_intrinsics, const Extrinsics& depth_to_color,
                              DepthImage& out) {
  out.depth_scale_m = depth.depth_scale_m;
  out.resize(color_intrinsics.width, color_intrinsics.height);
  std::fill(out.pixels.begin(), out.pixels.end(), uint16_t{0});
  // A size mismatch would index past the corner table: fail safe with "no depth" instead.
  if (!matches(depth, depth_intrinsics) || !rays_.prepare(depth_intrinsics)) return;
  const size_t out_width = static_cast<size_t>(out.width);
  for (int v = 0; v < depth.height; ++v) {
    const uint16_t* row = depth.pixels.data() + static_cast<size_t>(v) * static_cast<size_t>(depth.width);
    for (int u = 0; u < depth.width; ++u) {
      const uint16_t raw = row[u];
      if (raw == 0) continue;
      const float z_m = depth.depth_scale_m * static_cast<float>(raw);
      const ColorFootprint box = rays_.footprint(u, v, z_m, color_intrinsics, depth_to_color);
      for (int y = box.y0; y <= box.y1; ++y) {
        uint16_t* dst = out.pixels.data() + static_cast<size_t>(y) * out_width;
        for (int x = box.x0; x <= box.x1; ++x) {
          // Nearest wins; 0 is "nothing written yet".
          dst[x] = dst[x] == 0 ? raw : std::min(dst[x], raw);
        }
      }
    }
  }
}

void AlignColorToDepth::apply(const DepthImage& depth, const Intrinsics& depth_intrinsics, const ColorImage& color,
                              const Intrinsics& color_intrinsics, const Extrinsics& depth_to_color,
                              ColorImage& out) {
  out.width = depth.width;
  out.height = depth.height;
  out.rgb.assign(static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height) * 3, uint8_t{0});
  const bool color_matches = color.width == color_intrinsics.width && color.height == color_intrinsics.height &&
                             color.rgb.size() == static_cast<size_t>(color.width) * color.height * 3;
  if (!matches(depth, depth_intrinsics) || !color_matches || !rays_.prepare(depth_intrinsics)) return;
  const size_t color_width = static_cast<size_t>(color.width);
  for (int v = 0; v < depth.height; ++v) {
    const size_t row_start = static_cast<size_t>(v) * static_cast<size_t>(depth.width);
    for (int u = 0; u < depth.width; ++u) {
      const uint16_t raw = depth.pixels[row_start + static_cast<size_t>(u)];
      if (raw == 0) continue;
      const float z_m = depth.depth_scale_m * static_cast<float>(raw);
      const ColorFootprint box = rays_.footprint(u, v, z_m, color_intrinsics, depth_to_color);
      if (box.empty()) continue;
      // The SDK copies every covered colour pixel in turn; the last, (x1, y1), is what stays.
      const uint8_t* src = color.rgb.data() + (static_cast<size_t>(box.y1) * color_width + box.x1) * 3;
      std::copy(src, src + 3, out.rgb.data() + (row_start + static_cast<size_t>(u)) * 3);
    }
  }
}

}  // namespace hrcsense
