// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense bench`: times Pipeline::process end to end on pre-rendered frames.
#include "common/app_errors.hpp"
#include "commands.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config.hpp"
#include "hrcsense/robot_state.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
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

    // The timed frames follow the learning frames, as in a run; buffers warm up on the first pass.
    const size_t first = std::min(frames.size(), static_cast<size_t>(config.pipeline.background.frames));
    if (first == frames.size()) throw std::runtime_error("no frames left after background learning");
    std::vector<double> latencies_us;
    latencies_us.reserve((frames.size() - first) * kRepetitions);
    FrameResult result;
    const RobotState robot_state = fixed_robot_state(config.robot_state.joints_rad);
    for (size_t i = first; i < frames.size(); ++i) pipeline.process(frames[i], robot_state, result);  // warm-up
    double total_s = 0.0;
    for (int rep = 0; rep < kRepetitions; ++rep) {
      for (size_t i = first; i < frames.size(); ++i) {
        const Clock::time_point start = Clock::now();
        pipeline.process(frames[i], robot_state, result);
        const double us = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
        latencies_us.push_back(us);
        total_s += us * 1e-6;
      }
    }
    const double mean_ms = total_s * 1e3 / static_cast<double>(latencies_us.size());
    std::printf("config        %s\n", args.config_path.c_str());
    std::printf("frames        %zu timed x %d repetitions (%zu learning frames before them), %dx%d\n",
                frames.size() - first, kRepetitions, first, info.intrinsics.width, info.intrinsics.height);
    std::printf("frames/s      %.1f\n", static_cast<double>(latencies_us.size()) / total_s);
    std::printf("latency ms    mean %.3f  p50 %.3f  p99 %.3f\n", mean_ms, percentile_ms(latencies_us, 0.50),
                percentile_ms(latencies_us, 0.99));
    std::printf("rendering     %.3f ms/frame (not included above)\n", render_s * 1e3 / static_cast<double>(frames.size()));
    std::printf("peak RSS      %.1f MiB (includes the pre-rendered frames)\n", peak_rss_mib());
    return 0;
  } catch (const std::exception& e) {
    return report_error(e);
  }
}

}  // namespace hrcsense::app
