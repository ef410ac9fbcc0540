// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense bench`: times what a run does per frame on pre-rendered frames: the
// measurement (Pipeline::process) and the SafetyMonitor's decision, with the robot state the
// configured source gives each frame.
#include "common/app_errors.hpp"
#include "commands.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/safety.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace hrcsense::app {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int64_t kDefaultFrames = 300;
constexpr int kRepetitions = 5;

// Peak resident set size (VmHWM) in MiB; -1 when /proc is not available.
double peak_rss_mib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // value in kB
  }
  return -1.0;
}

double percentile_ms(std::vector<double> sorted_us, double q) {
  std::sort(sorted_us.begin(), sorted_us.end());
  const size_t rank = std::min(sorted_us.size() - 1, static_cast<size_t>(q * static_cast<double>(sorted_us.size())));
  return sorted_us[rank] * 1e-3;
}

// Reads up to `count` frames from the configured source; returns the rendering time in s.
double prerender(Source& source, int64_t count, std::vector<Frame>& frames) {
  const Clock::time_point start = Clock::now();
  frames.reserve(static_cast<size_t>(count));
  Frame frame;
  while (static_cast<int64_t>(frames.size()) < count) {
    const Source::Status status = source.next(frame);
    if (status == Source::Status::error) throw std::runtime_error("source error: " + source.error());
    if (status == Source::Status::end) break;
    frames.push_back(frame);
    // Keep only the true contact (what a run copies): the per-pixel truth would multiply the
    // memory held by the pre-rendered frames.
    if (frames.back().truth) {
      std::vector<float>().swap(frames.back().truth->depth_m);  // `= {}` would keep the capacity
      std::vector<uint16_t>().swap(frames.back().truth->labels);
    }
  }
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Learns the background from the frames, as a run would, so that the timed passes measure the
// whole path (foreground, proximity, verdict) on every frame.
BackgroundModel learn(const PipelineParams& params, const std::vector<Frame>& frames) {
  Pipeline learner(params);
  FrameResult result;
  for (const Frame& frame : frames) {
    if (learner.background_ready()) break;
    learner.process(frame, fixed_robot_state({}), result);  // learning needs no robot
  }
  if (!learner.background_ready()) {
    throw std::runtime_error("the background did not finish learning in " + std::to_string(frames.size()) +
                             " frames (background.frames = " + std::to_string(params.background.frames) +
                             "); raise --frames");
  }
  return learner.background();
}

// The robot state the configured source gives each frame at its timestamp (the simulator's
// trajectory for `sim`, the recording's for `recorded`); live sources (rtde, udp_json, ros2) have no
// state to replay, so their frames get robot.joints_rad, with a warning.
std::vector<RobotState> robot_states_for(const Config& config, Source& source, const std::vector<Frame>& frames) {
  std::unique_ptr<RobotStateSource> states;
  const RobotStateOrigin origin = config.robot_state.source;
  if (origin == RobotStateOrigin::fixed || origin == RobotStateOrigin::sim) {
    states = make_robot_state_source(config);
  } else if (origin == RobotStateOrigin::recorded) {
    states = make_robot_state_source(config, source);
  } else {
    spdlog::warn("bench: robot.state.source {} is live; the frames get robot.joints_rad instead",
                 robot_state_origin_name(origin));
  }
  std::vector<RobotState> out(frames.size(), fixed_robot_state(config.robot_state.joints_rad));
  if (!states) return out;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (!states->state_at(frames[i].timestamp_ns, out[i])) out[i].valid = false;
  }
  return out;
}

// Per stage, the median of its timings over the timed frames, in the order the stages ran.
void print_stage_medians(const std::vector<std::pair<const char*, std::vector<double>>>& stages) {
  std::printf("stages ms     median:");
  for (const auto& [name, us] : stages) {
    if (us.empty()) continue;
    std::printf(" %s %.3f", name, percentile_ms(us, 0.50));
  }
  std::printf("\n");
}

// Adds `us` under `name` (static names: compared by pointer first, then by text).
void add_stage(std::vector<std::pair<const char*, std::vector<double>>>& stages, const char* name, double us) {
  for (auto& [stage, values] : stages) {
    if (stage == name || std::string_view(stage) == name) {
      values.push_back(us);
      return;
    }
  }
  stages.push_back({name, {us}});
}

// What the timed passes measured: per frame the measurement plus the decision (µs), per stage
// its timings (µs) in the order the stages ran, and how many verdicts were `run`.
struct BenchTimings {
  std::vector<double> latencies_us;
  std::vector<std::pair<const char*, std::vector<double>>> stages;
  double total_s = 0.0;
  size_t decided_run = 0;
};

// One untimed pass over frames[first..] so that buffers reach their size, then kRepetitions
// timed passes: Pipeline::process and SafetyMonitor::decide on each frame with its robot state.
BenchTimings time_frames(Pipeline& pipeline, SafetyMonitor& monitor, const std::vector<Frame>& frames,
                         const std::vector<RobotState>& robot_states, size_t first) {
  BenchTimings timings;
  timings.latencies_us.reserve((frames.size() - first) * kRepetitions);
  FrameResult result;
  for (size_t i = first; i < frames.size(); ++i) {  // warm-up
    pipeline.process(frames[i], robot_states[i], result);
    monitor.decide(result, 0);
  }
  for (int rep = 0; rep < kRepetitions; ++rep) {
    for (size_t i = first; i < frames.size(); ++i) {
      const Clock::time_point start = Clock::now();
      pipeline.process(frames[i], robot_states[i], result);
      const Clock::time_point measured = Clock::now();
      monitor.decide(result, 0);
      const Clock::time_point decided = Clock::now();
      const double us = std::chrono::duration<double, std::micro>(decided - start).count();
      timings.latencies_us.push_back(us);
      timings.total_s += us * 1e-6;
      for (const StageTiming& timing : result.timings) add_stage(timings.stages, timing.stage, timing.us);
      add_stage(timings.stages, "decision", std::chrono::duration<double, std::micro>(decided - measured).count());
      timings.decided_run += result.verdict.state == VerdictState::run ? 1 : 0;
    }
  }
  return timings;
}

// The report on stdout: `first` learning frames, then the timed ones of `frame_count`;
// render_s is the time the source took to produce all of them.
void print_bench_report(const CommandArgs& args, const Config& config, const SourceInfo& info, size_t frame_count,
                        size_t first, double render_s, const BenchTimings& timings) {
  const std::vector<double>& latencies_us = timings.latencies_us;
  const double mean_ms = timings.total_s * 1e3 / static_cast<double>(latencies_us.size());
  std::printf("config        %s\n", args.config_path.c_str());
  std::printf("frames        %zu timed x %d repetitions (%zu learning frames before them), %dx%d\n",
              frame_count - first, kRepetitions, first, info.intrinsics.width, info.intrinsics.height);
  std::printf("frames/s      %.1f\n", static_cast<double>(latencies_us.size()) / timings.total_s);
  std::printf("latency ms    mean %.3f  p50 %.3f  p99 %.3f\n", mean_ms, percentile_ms(latencies_us, 0.50),
              percentile_ms(latencies_us, 0.99));
  print_stage_medians(timings.stages);
  std::printf("verdicts      %zu of %zu timed frames run (%s mode)\n", timings.decided_run, latencies_us.size(),
              config.pipeline.safety.mode == SafetyParams::Mode::ssm ? "ssm" : "zones");
  std::printf("rendering     %.3f ms/frame (not included above)\n", render_s * 1e3 / static_cast<double>(frame_count));
  std::printf("peak RSS      %.1f MiB (includes the pre-rendered frames)\n", peak_rss_mib());
}

}  // namespace

int bench_command(const CommandArgs& args) {
  try {
    const Config config = load_config(args.config_path, args.sets);
    std::unique_ptr<Source> source = make_source(config);
    const SourceInfo info = source->info();
    const int64_t count = args.frames > 0 ? args.frames : kDefaultFrames;

    std::vector<Frame> frames;
    const double render_s = prerender(*source, count, frames);
    spdlog::info("pre-rendered {} frames of {}x{} in {:.2f} s", frames.size(), info.intrinsics.width,
                 info.intrinsics.height, render_s);
    Pipeline pipeline(config.pipeline);
    pipeline.set_background(learn(config.pipeline, frames));

    // The timed frames follow the learning frames, as in a run.
    const size_t first = std::min(frames.size(), static_cast<size_t>(config.pipeline.background.frames));
    if (first == frames.size()) throw std::runtime_error("no frames left after background learning");
    const std::vector<RobotState> robot_states = robot_states_for(config, *source, frames);
    SafetyMonitor monitor(config.pipeline.safety);
    const BenchTimings timings = time_frames(pipeline, monitor, frames, robot_states, first);
    print_bench_report(args, config, info, frames.size(), first, render_s, timings);
    return 0;
  } catch (const std::exception& e) {
    return report_error(e);
  }
}

}  // namespace hrcsense::app
