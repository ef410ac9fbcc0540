// SPDX-License-Identifier: Apache-2.0
// source.type ros2 on loopback: latency from dds_write of a depth image (848x480 16UC1 with
// its CameraInfo) to the Frame out of Ros2CameraSource::next(), p50 and p99, at the D435's
// top rate of 90 frames/s, and the rate it keeps up with unpaced. Needs CYCLONEDDS_URI set to
// tests/dds/cyclonedds-loopback.xml (docs/BENCHMARKS.md has the command).
#include "dds/ros2_camera_source.hpp"
#include "dds/ros2_publisher.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kFrames = 900;                  // 10 s at 90 frames/s
constexpr int64_t kStampBaseNs = 1'000'000'000;
constexpr int64_t kPeriod90Ns = 11'111'111;

Frame walk_frame() {
  const Config config = load_config(std::string(HRCSENSE_BENCH_SOURCE_DIR) + "/config/walk.yaml", {"sim.frames=1"});
  std::unique_ptr<Source> sim = make_source(config);
  Frame frame;
  sim->next(frame);
  frame.color.reset();
  return frame;
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * static_cast<double>(values.size() - 1))];
}

void BM_Ros2Loopback(benchmark::State& state, bool paced) {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (uri == nullptr || std::string(uri).find("cyclonedds-loopback.xml") == std::string::npos) {
    state.SkipWithError("set CYCLONEDDS_URI=file://<checkout>/tests/dds/cyclonedds-loopback.xml (loopback only)");
    return;
  }
  const uint32_t domain = 201;
  const Frame prototype = walk_frame();
  for (auto _ : state) {
    std::vector<Clock::time_point> sent(kFrames);
    std::atomic<bool> source_ready{false}, done{false};
    std::thread publisher_thread([&] {
      ros2::Ros2CameraPublisher publisher(ros2::Ros2PublisherParams{"/bench/camera", domain});
      Frame frame = prototype;
      // Warm-up frames (stamps below 0, 10 ms apart) until the source has started.
      for (int i = 0; !source_ready.load() && i < 3000; ++i) {
        frame.timestamp_ns = (i - 3000) * int64_t{10'000'000};
        publisher.publish(frame);
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      const Clock::time_point start = Clock::now();
      for (int i = 0; i < kFrames; ++i) {
        if (paced) std::this_thread::sleep_until(start + std::chrono::nanoseconds(kPeriod90Ns * i));
        frame.timestamp_ns = kStampBaseNs + kPeriod90Ns * i;
        sent[static_cast<size_t>(i)] = Clock::now();
        publisher.publish(frame);
      }
      done.store(true);
    });
    ros2::Ros2SourceParams params;
    params.topics = ros2::realsense_topics("/bench/camera");
    params.domain_id = domain;
    params.color = false;
    ros2::Ros2CameraSource source(params);
    source_ready.store(true);
    std::vector<double> latency_us;
    Frame frame;
    int idle_after_done = 0;
    Clock::time_point first{}, last{};
    while (static_cast<int>(latency_us.size()) < kFrames && idle_after_done < 3) {
      const Source::Status status = source.next(frame);
      if (status != Source::Status::frame) {
        idle_after_done += done.load() ? 1 : 0;
        continue;
      }
      const int64_t i = (frame.timestamp_ns - kStampBaseNs) / kPeriod90Ns;
      if (frame.timestamp_ns < kStampBaseNs || i >= kFrames) continue;
      const Clock::time_point now = Clock::now();
      if (latency_us.empty()) first = now;
      last = now;
      latency_us.push_back(std::chrono::duration<double, std::micro>(now - sent[static_cast<size_t>(i)]).count());
    }
    publisher_thread.join();
    state.counters["p50_us"] = percentile(latency_us, 0.50);
    state.counters["p99_us"] = percentile(latency_us, 0.99);
    state.counters["received_share"] = static_cast<double>(latency_us.size()) / kFrames;
    const double span_s = std::chrono::duration<double>(last - first).count();
    state.counters["frames_per_s"] = span_s > 0.0 ? static_cast<double>(latency_us.size() - 1) / span_s : 0.0;
    state.counters["dropped_camera"] = static_cast<double>(source.frames_dropped_camera());
  }
}

BENCHMARK_CAPTURE(BM_Ros2Loopback, paced_90fps, true)->Name("Ros2/loopback_90fps/848x480")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Ros2Loopback, unpaced, false)->Name("Ros2/loopback_unpaced/848x480")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
