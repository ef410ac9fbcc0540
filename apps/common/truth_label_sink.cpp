// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — `truth.contact_label`: the simulated object under the measured contact.
#include "common/truth_label_sink.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <cmath>

namespace hrcsense {

int source_pixel_of(int filtered_pixel, const Intrinsics& filtered, const Intrinsics& source) {
  if (filtered.width <= 0 || filtered.height <= 0 || filtered_pixel < 0 ||
      filtered_pixel >= filtered.width * filtered.height) {
    return -1;
  }
  if (filtered.width == source.width && filtered.height == source.height) return filtered_pixel;
  const int u = filtered_pixel % filtered.width;
  const int v = filtered_pixel / filtered.width;
  const std::optional<Eigen::Vector3f> ray = deproject(filtered, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), 1.0F);
  const std::optional<Eigen::Vector2f> uv = ray ? project(source, *ray) : std::nullopt;
  if (!uv || !uv->allFinite()) return -1;
  const int us = std::clamp(static_cast<int>(std::lround(uv->x())), 0, source.width - 1);
  const int vs = std::clamp(static_cast<int>(std::lround(uv->y())), 0, source.height - 1);
  return vs * source.width + us;
}

void TruthLabelSink::header(const RunHeader& header) {
  source_ = header.source.intrinsics;
  filtered_ = header.filters.intrinsics.width > 0 ? header.filters.intrinsics : header.source.intrinsics;
  sink_.header(header);
}

void TruthLabelSink::frame(const FrameResult& result) {
  if (!result.truth || !result.contact.valid) {
    sink_.frame(result);
    return;
  }
  labelled_ = result;
  const int pixel = source_pixel_of(result.contact.pixel, filtered_, source_);
  if (pixel >= 0) {
    const std::string& name = sim_.label_name(sim_.label_at(result.frame, pixel));
    labelled_.truth_contact_label = name.empty() ? nullptr : name.c_str();
  }
  sink_.frame(labelled_);
}

}  // namespace hrcsense
