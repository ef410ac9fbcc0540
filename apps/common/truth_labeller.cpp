// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — `truth.contact_label`: the simulated object under the measured contact.
#include "common/truth_labeller.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace hrcsense {

SourceBlock source_block_of(int filtered_pixel, const Intrinsics& filtered, const Intrinsics& source) {
  if (filtered.width <= 0 || filtered.height <= 0 || filtered_pixel < 0 ||
      filtered_pixel >= filtered.width * filtered.height) {
    return SourceBlock{};
  }
  const int u = filtered_pixel % filtered.width;
  const int v = filtered_pixel / filtered.width;
  if (filtered.width == source.width && filtered.height == source.height) return SourceBlock{u, u + 1, v, v + 1};
  // The source pixel the ray of filtered pixel (uf, vf) meets, rounded (not clamped).
  const auto source_of = [&](int uf, int vf) -> std::optional<Eigen::Vector2i> {
    const std::optional<Eigen::Vector3f> ray = deproject(filtered, Eigen::Vector2f(static_cast<float>(uf), static_cast<float>(vf)), 1.0F);
    const std::optional<Eigen::Vector2f> uv = ray ? project(source, *ray) : std::nullopt;
    if (!uv || !uv->allFinite()) return std::nullopt;
    return Eigen::Vector2i(static_cast<int>(std::lround(uv->x())), static_cast<int>(std::lround(uv->y())));
  };
  const std::optional<Eigen::Vector2i> first = source_of(u, v);
  const std::optional<Eigen::Vector2i> next = source_of(u + 1, v + 1);
  if (!first || !next) return SourceBlock{};
  SourceBlock block;
  block.u_begin = std::clamp(first->x(), 0, source.width - 1);
  block.v_begin = std::clamp(first->y(), 0, source.height - 1);
  block.u_end = std::clamp(next->x(), block.u_begin + 1, source.width);
  block.v_end = std::clamp(next->y(), block.v_begin + 1, source.height);
  return block;
}

TruthLabeller::TruthLabeller(Simulator simulator, const RunHeader& header)
    : sim_(std::move(simulator)),
      source_(header.source.intrinsics),
      filtered_(header.filters.intrinsics.width > 0 ? header.filters.intrinsics : header.source.intrinsics) {}

const char* TruthLabeller::contact_label(const FrameResult& result) const {
  if (!result.truth || !result.contact.valid) return nullptr;
  const char* label = nullptr;
  const SourceBlock block = source_block_of(result.contact.pixel, filtered_, source_);
  const float measured_z_m = result.contact.closest_camera.z();
  float best_gap_m = std::numeric_limits<float>::infinity();
  for (int v = block.v_begin; v < block.v_end; ++v) {
    for (int u = block.u_begin; u < block.u_end; ++u) {
      const Simulator::Hit hit = sim_.hit_at(result.frame, v * source_.width + u);
      // A ray that meets nothing (z 0) measured nothing; the first pixel wins a tie.
      const float gap_m = hit.z_m > 0.0F ? std::abs(hit.z_m - measured_z_m) : std::numeric_limits<float>::max();
      if (gap_m < best_gap_m) {
        best_gap_m = gap_m;
        const std::string& name = sim_.label_name(hit.label);
        label = name.empty() ? nullptr : name.c_str();
      }
    }
  }
  return label;
}

}  // namespace hrcsense
