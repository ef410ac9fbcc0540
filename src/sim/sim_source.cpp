// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator as a Source: frames 0 .. frames-1, then the end.

#include "hrcsense/sim.hpp"

#include <string>

namespace hrcsense {

SourceInfo SimSource::info() const {
  SourceInfo info;
  info.type = "sim";
  size_t moving = 0;
  for (const SceneObject& object : sim_.scene.objects) moving += object.is_static ? 0 : 1;
  info.description = "simulated scene: " + std::to_string(sim_.scene.objects.size()) + " objects (" +
                     std::to_string(moving) + " moving), seed " + std::to_string(sim_.params.seed) +
                     (sim_.params.noise ? ", disparity noise" : ", no noise");
  info.intrinsics = sim_.intrinsics();
  info.stereo_baseline_mm = sim_.params.baseline_mm;
  info.nominal_fps = sim_.params.fps;
  info.frame_count = sim_.params.frames;
  return info;
}

Source::Status SimSource::next(Frame& out) {
  if (next_index_ >= sim_.params.frames) return Status::end;
  sim_.render(next_index_, out);
  ++next_index_;
  return Status::frame;
}

}  // namespace hrcsense
