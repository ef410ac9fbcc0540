// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — what `record` and `run --record` share (record_setup.hpp).
#include "common/record_setup.hpp"

#include "common/assembly.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace hrcsense::app {

RecorderParams recorder_params(const Config& config, const std::string& path, const SourceInfo& info) {
  RecorderParams params;
  params.path = path;
  params.split_mb = config.record.split_mb;
  params.on_error = config.record.on_error == "stop" ? RecordOnError::stop_run : RecordOnError::continue_run;
  params.queue_frames = config.record.queue_frames;
  params.bag.fps = static_cast<uint32_t>(std::lround(std::max(1.0, info.nominal_fps)));
  params.bag.stereo_baseline_mm = info.stereo_baseline_mm;
  // A UR arm's joints under UR's ROS names; other arms' descriptions name none: joint_0..5.
  if (config.robot_model == "ur5" || config.robot_model == "ur5e" || config.robot_model == "ur10e") {
    params.bag.joint_names.assign(kUrJointNames.begin(), kUrJointNames.end());
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  return params;
}

void log_recording(const RecorderStats& stats) {
  for (const std::string& file : stats.files) spdlog::info("recording file: {}", file);
  spdlog::info("recording: {} frames written, {} dropped", stats.frames_recorded, stats.frames_dropped);
  if (!stats.error.empty()) spdlog::error("recording: {}", stats.error);
}

RecordStateLookup record_state_lookup(const Config& config, Source& source, RobotStateSource& run_states, bool paced,
                                      std::unique_ptr<RobotStateSource>& own,
                                      std::shared_ptr<TrajectoryClock> trajectory_clock) {
  const RobotStateOrigin origin = run_states.origin();
  if (origin == RobotStateOrigin::sim || origin == RobotStateOrigin::fixed) {
    own = make_robot_state_source(config, source, nullptr, std::move(trajectory_clock));
  }
  RecordStateLookup lookup;
  lookup.states = own ? own.get() : &run_states;
  lookup.host_time_is_source_time = host_time_is_source_time(origin, paced);
  lookup.lookup_offset_ns = robot_state_lookup_offset_ns(origin, config.robot_state.camera_latency_s);
  return lookup;
}

}  // namespace hrcsense::app
