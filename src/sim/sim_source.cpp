// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator as a Source: frames 0 .. frames-1, then the end; with an epoch, the
// frames of the shared scene clock as they fall due (docs/SIMULATOR.md, "The shared scene clock").

#include "hrcsense/sim/sim.hpp"

#include "hrcsense/clock.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

namespace hrcsense {
namespace {

// When scene frame `index` is due, realtime ns: epoch + index / fps, rounded to the nanosecond.
int64_t scene_frame_due_ns(int64_t epoch_ns, int64_t index, double fps) {
  return epoch_ns + std::llround(static_cast<double>(index) * 1e9 / fps);
}

// The first scene frame due at or after `now_ns` (0 before the epoch). The division in double
// may be a nanosecond off at a frame's due time; the two steps make the answer exact.
int64_t first_scene_frame_from(int64_t epoch_ns, int64_t now_ns, double fps) {
  if (now_ns <= epoch_ns) return 0;
  int64_t index = static_cast<int64_t>(std::ceil(static_cast<double>(now_ns - epoch_ns) * fps / 1e9));
  if (index > 0 && scene_frame_due_ns(epoch_ns, index - 1, fps) >= now_ns) --index;
  if (scene_frame_due_ns(epoch_ns, index, fps) < now_ns) ++index;
  return index;
}

}  // namespace

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
  // On the scene clock the frames come at the scene's rate whether asked for or not.
  info.live = sim_.params.epoch_ns.has_value();
  if (info.live) info.description += ", on the shared scene clock";
  return info;
}

Source::Status SimSource::next(Frame& out) {
  if (sim_.params.epoch_ns) return next_scene_frame(out);
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

Source::Status SimSource::next_scene_frame(Frame& out) {
  const int64_t epoch_ns = *sim_.params.epoch_ns;
  const double fps = sim_.params.fps;
  const int64_t period_ns = std::llround(1e9 / fps);
  const int64_t now_ns = shared_clock_ns();
  if (!scene_joined_) {
    next_index_ = first_scene_frame_from(epoch_ns, now_ns, fps);
    scene_joined_ = true;
  }
  if (next_index_ >= sim_.params.frames) return Status::end;
  int64_t due_ns = scene_frame_due_ns(epoch_ns, next_index_, fps);
  if (now_ns - due_ns > period_ns) {
    // Late by more than a period (a slow consumer, a stopped process): the newest frame due
    // instead, so that the scene is never played back in a burst of old frames.
    const int64_t newest = first_scene_frame_from(epoch_ns, now_ns + 1, fps) - 1;
    scene_frames_skipped_ += newest - next_index_;
    next_index_ = newest;
    if (next_index_ >= sim_.params.frames) return Status::end;
    due_ns = scene_frame_due_ns(epoch_ns, next_index_, fps);
  }
  if (due_ns - now_ns > kSceneWaitNs) {
    // The scene has not started yet (an epoch in the future): a bounded wait, then idle.
    std::this_thread::sleep_for(std::chrono::nanoseconds(kSceneWaitNs));
    return Status::idle;
  }
  // Sleep on the realtime clock itself: the due time is a realtime instant.
  std::this_thread::sleep_until(std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::nanoseconds(due_ns))));
  sim_.render(next_index_, out);
  out.timestamp_ns = due_ns;
  out.host_time_ns = due_ns - realtime_minus_steady_ns();
  ++next_index_;
  return Status::frame;
}

}  // namespace hrcsense
