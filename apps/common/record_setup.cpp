// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — what `record` and `run --record` share (record_setup.hpp).
#include "common/record_setup.hpp"

#include "common/assembly.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace hrcsense::app {

RecorderParams recorder_params(const Config& config, const std::string& path, const SourceInfo& info) {
  RecorderParams params;
  params.path = path;
  params.split_mb = config.record.split_mb;
  params.on_error = config.record.on_error;
  params.queue_frames = config.record.queue_frames;
  params.bag.fps = static_cast<uint32_t>(std::lround(std::max(1.0, info.nominal_fps)));
  params.bag.stereo_baseline_mm = info.stereo_baseline_mm;
  // A UR arm's joints under UR's ROS names; other arms' descriptions name none: joint_0..5.
  if (builtin_arm_of(config.robot_model)) {  // every built-in arm is a UR
    params.bag.joint_names.assign(kUrJointNames.begin(), kUrJointNames.end());
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  return params;
}

namespace {

// The files of the set a recording to `out` would write that exist now: `out` itself, or with
// split_mb every FILE-NNN.bag beside it (the parts need not be numbered without gaps).
std::vector<std::filesystem::path> existing_outputs(const std::string& out, int64_t split_mb) {
  namespace fs = std::filesystem;
  std::vector<fs::path> found;
  std::error_code ignored;
  if (split_mb <= 0) {
    if (fs::exists(out, ignored)) found.emplace_back(out);
    return found;
  }
  const std::string first = split_file_name(out, 0);  // "FILE-000.bag": the pattern's prefix and suffix
  const fs::path folder = fs::path(first).parent_path().empty() ? fs::path(".") : fs::path(first).parent_path();
  const std::string name = fs::path(first).filename().string();
  const std::string prefix = name.substr(0, name.size() - std::string("000.bag").size());
  for (fs::directory_iterator it(folder, ignored), end; !ignored && it != end; it.increment(ignored)) {
    const std::string entry = it->path().filename().string();
    if (entry.size() <= prefix.size() + 4 || entry.compare(0, prefix.size(), prefix) != 0 ||
        entry.compare(entry.size() - 4, 4, ".bag") != 0) {
      continue;
    }
    const std::string digits = entry.substr(prefix.size(), entry.size() - prefix.size() - 4);
    if (digits.size() >= 3 && std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      found.push_back(it->path());
    }
  }
  return found;
}

}  // namespace

void check_record_output(const Config& config, const std::string& out, bool overwrite) {
  namespace fs = std::filesystem;
  // A folder on the way that is a file: said here, naming both, rather than as the library's
  // "cannot create directories".
  std::error_code ignored;
  for (fs::path folder = fs::path(out).parent_path(); !folder.empty(); folder = folder.parent_path()) {
    if (fs::exists(folder, ignored) && !fs::is_directory(folder, ignored)) {
      throw ConfigError("record: cannot write " + out + ": " + folder.string() + " is a file, not a folder");
    }
    if (folder == folder.parent_path()) break;
  }
  const std::vector<fs::path> existing = existing_outputs(out, config.record.split_mb);
  // Never the source being played, --overwrite or not: the recording would destroy what it reads.
  if (!config.source.path.empty() && fs::exists(config.source.path, ignored)) {
    for (const fs::path& file : existing) {
      if (fs::equivalent(file, config.source.path, ignored)) {
        throw ConfigError("record: " + file.string() + " is the source being played (source.path " +
                          config.source.path + "); record to another file");
      }
    }
  }
  if (existing.empty() || overwrite) return;
  std::string names = existing.front().string();
  if (existing.size() > 1) names += " and " + std::to_string(existing.size() - 1) + " more part(s) of the set";
  throw ConfigError("record: " + names + " exists; pass --overwrite to replace it, or record to another file");
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
