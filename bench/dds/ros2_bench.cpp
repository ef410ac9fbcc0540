// SPDX-License-Identifier: Apache-2.0
// source.type ros2 on loopback: latency from dds_write (in a child process, so the samples
// cross the loopback interface) of a depth image (848x480 16UC1 with
// its CameraInfo) to the Frame out of Ros2CameraSource::next(), p50 and p99, at the D435's
// top rate of 90 frames/s, and the rate it keeps up with unpaced. Needs CYCLONEDDS_URI set to
// tests/dds/cyclonedds-loopback.xml (docs/BENCHMARKS.md has the command).
#include "../common/percentile.hpp"
#include "dds/ros2_camera_source.hpp"
#include "dds/ros2_publisher.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <new>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

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

using bench::percentile;

// What the publisher process and the benchmark share (an anonymous shared mapping made
// before fork): the steady_clock send times (CLOCK_MONOTONIC is one clock for the whole
// machine) and two flags.
struct SharedState {
  std::atomic<bool> source_ready{false};
  std::atomic<bool> done{false};
  int64_t sent_ns[kFrames];
};

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// Runs in the child process: its own Cyclone domain instance, so samples cross the
// loopback interface as UDP (within one process Cyclone would deliver them locally).
[[noreturn]] void publish_in_child(SharedState& shared, const Frame& prototype, uint32_t domain, bool paced) {
  {
    ros2::Ros2CameraPublisher publisher(ros2::Ros2PublisherParams{"/bench/camera", domain});
    Frame frame = prototype;
    // Warm-up frames (stamps below 0, 10 ms apart) until the source has started and matched.
    for (int i = 0; !shared.source_ready.load() && i < 3000; ++i) {
      frame.timestamp_ns = (i - 3000) * int64_t{10'000'000};
      publisher.publish(frame);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const Clock::time_point start = Clock::now();
    for (int i = 0; i < kFrames; ++i) {
      if (paced) std::this_thread::sleep_until(start + std::chrono::nanoseconds(kPeriod90Ns * i));
      frame.timestamp_ns = kStampBaseNs + kPeriod90Ns * i;
      shared.sent_ns[i] = steady_ns();
      publisher.publish(frame);
    }
    // Keep the writer alive briefly so the last fragments are not cut off by its deletion.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    shared.done.store(true);
  }
  std::_Exit(0);
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
    void* mapping = mmap(nullptr, sizeof(SharedState), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (mapping == MAP_FAILED) {
      state.SkipWithError("mmap of the shared send times failed");
      return;
    }
    SharedState& shared = *new (mapping) SharedState();
    // Fork before this process creates any DDS entity of this iteration.
    const pid_t child = fork();
    if (child == 0) publish_in_child(shared, prototype, domain, paced);
    if (child < 0) {
      munmap(mapping, sizeof(SharedState));
      state.SkipWithError("fork of the publisher failed");
      return;
    }
    std::vector<double> latency_us;
    int64_t dropped_camera = 0;
    int64_t last_ns = 0;
    {
      ros2::Ros2SourceParams params;
      params.topics = ros2::realsense_topics("/bench/camera");
      params.domain_id = domain;
      params.color = false;
      ros2::Ros2CameraSource source(params);
      shared.source_ready.store(true);
      Frame frame;
      int idle_after_done = 0;
      while (static_cast<int>(latency_us.size()) < kFrames && idle_after_done < 3) {
        const Source::Status status = source.next(frame);
        if (status != Source::Status::frame) {
          idle_after_done += shared.done.load() ? 1 : 0;
          continue;
        }
        const int64_t i = (frame.timestamp_ns - kStampBaseNs) / kPeriod90Ns;
        if (frame.timestamp_ns < kStampBaseNs || i >= kFrames) continue;
        last_ns = steady_ns();
        latency_us.push_back(static_cast<double>(last_ns - shared.sent_ns[i]) / 1e3);
      }
      dropped_camera = source.frames_dropped_camera();
    }
    int child_status = 0;
    waitpid(child, &child_status, 0);
    state.counters["p50_us"] = percentile(latency_us, 0.50);
    state.counters["p99_us"] = percentile(latency_us, 0.99);
    state.counters["received_share"] = static_cast<double>(latency_us.size()) / kFrames;
    // Delivered rate: frames received over the time from the first dds_write to the last
    // Frame out (not first to last receipt, which a burst drained from the reader's queue
    // would inflate).
    const double span_s = static_cast<double>(last_ns - shared.sent_ns[0]) / 1e9;
    state.counters["frames_per_s"] = span_s > 0.0 ? static_cast<double>(latency_us.size()) / span_s : 0.0;
    state.counters["dropped_camera"] = static_cast<double>(dropped_camera);
    shared.~SharedState();
    munmap(mapping, sizeof(SharedState));
  }
}

BENCHMARK_CAPTURE(BM_Ros2Loopback, paced_90fps, true)->Name("Ros2/loopback_90fps/848x480")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Ros2Loopback, unpaced, false)->Name("Ros2/loopback_unpaced/848x480")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
