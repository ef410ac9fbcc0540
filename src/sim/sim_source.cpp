// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator as a Source: frames 0 .. frames-1, then the end.

#include "hrcsense/sim/sim.hpp"

#include <cmath>
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
  info.sensor_model = sim_sensor_name(sim_.params.sensor);
  return info;
}

Source::Status SimSource::next(Frame& out) {
  if (next_index_ >= sim_.params.frames) return Status::end;
  const TrajectoryClock* clock = sim_.arm ? sim_.arm->clock.get() : nullptr;
  if (clock != nullptr && clock->lockstep() && next_index_ > 0) {
    // Closed loop, unpaced: the arm moves on at the scale sent for the previous frame. A run
    // whose output ended sends nothing more; a bounded wait then lets the source end too.
    constexpr double kWaitS = 1.0;
    const int64_t previous_ns = std::llround(static_cast<double>(next_index_ - 1) * 1e9 / sim_.params.fps);
    if (!clock->wait_sent(previous_ns, kWaitS)) ++lockstep_timeouts_;
  }
  sim_.render(next_index_, out);
  ++next_index_;
  return Status::frame;
}

}  // namespace hrcsense
