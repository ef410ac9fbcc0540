// SPDX-License-Identifier: Apache-2.0
// Watchdog/no_frame_after_gap: how late the watchdog's stop comes when a live 30 frames/s
// source falls silent, on the steady clock. Each iteration runs run_pipeline on a small live
// source (64x48, a wall at 2 m, a robot point) that delivers 6 frames 33 ms apart and then
// returns idle; the time from the output of the last frame to the output of the watchdog's
// no_frame stop is measured against safety.max_frame_gap_periods (2 periods: 66.7 ms). Reported:
// the mean delay and its excess over the limit (the bound: a stop within 100 ms).
#include "hrcsense/pipeline.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

namespace hrcsense {
namespace {

using Clock = std::chrono::steady_clock;

class SilentAfterSixFrames final : public Source {
 public:
  SourceInfo info() const override {
    SourceInfo info;
    info.type = "bench";
    info.live = true;
    info.nominal_fps = 30.0;
    info.intrinsics = intrinsics();
    return info;
  }
  Status next(Frame& out) override {
    if (delivered_ >= 6) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));  // a live source's short wait
      return Status::idle;
    }
    if (delivered_ > 0) std::this_thread::sleep_for(std::chrono::microseconds(33'333));
    out.index = delivered_;
    out.timestamp_ns = delivered_ * 33'333'333;
    out.intrinsics = intrinsics();
    out.depth.resize(64, 48);
    out.depth.depth_scale_m = 0.001F;
    std::fill(out.depth.pixels.begin(), out.depth.pixels.end(), uint16_t{2000});
    ++delivered_;
    return Status::frame;
  }

 private:
  static Intrinsics intrinsics() {
    Intrinsics in;
    in.width = 64;
    in.height = 48;
    in.fx = in.fy = 60.0F;
    in.ppx = 32.0F;
    in.ppy = 24.0F;
    return in;
  }
  int64_t delivered_ = 0;
};

// Notes when the last frame and the watchdog's stop were written, and ends the run after it.
struct TimingSink final : Sink {
  std::atomic<bool>* stop = nullptr;
  Clock::time_point last_frame, watchdog;
  bool fired = false;
  void header(const RunHeader&) override {}
  void frame(const FrameResult& r) override {
    if (r.source_frame) {
      last_frame = Clock::now();
    } else if (!fired && r.verdict.code == ReasonCode::no_frame) {
      watchdog = Clock::now();
      fired = true;
      stop->store(true);
    }
  }
  void summary(const RunSummary&) override {}
};

void BM_WatchdogAfterGap(benchmark::State& state) {
  PipelineParams params;
  Capsule point;
  point.a = point.b = {0.0F, 0.0F, 0.5F};
  params.robot.points.capsules.push_back(point);
  params.background.frames = 2;
  params.filters.order.clear();
  std::vector<double> delays_ms;
  for (auto _ : state) {
    Pipeline pipeline(params);
    SilentAfterSixFrames source;
    FixedRobotState robot({});
    std::atomic<bool> stop{false};
    TimingSink sink;
    sink.stop = &stop;
    RunOptions options;
    options.stop_requested = &stop;
    run_pipeline(source, robot, pipeline, sink, options, RunHeader{});
    if (sink.fired) delays_ms.push_back(std::chrono::duration<double, std::milli>(sink.watchdog - sink.last_frame).count());
  }
  if (delays_ms.empty()) {
    state.SkipWithError("the watchdog never fired");
    return;
  }
  std::sort(delays_ms.begin(), delays_ms.end());
  const double limit_ms = 2.0 * 1000.0 / 30.0;
  state.counters["delay_ms_p50"] = delays_ms[delays_ms.size() / 2];
  state.counters["delay_ms_max"] = delays_ms.back();
  state.counters["excess_ms_p50"] = delays_ms[delays_ms.size() / 2] - limit_ms;
  state.counters["excess_ms_max"] = delays_ms.back() - limit_ms;
}

BENCHMARK(BM_WatchdogAfterGap)->Name("Watchdog/no_frame_after_gap")->Iterations(20)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
