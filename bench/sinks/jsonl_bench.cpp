// SPDX-License-Identifier: Apache-2.0
// The cost of flushing every JSON Lines line (R1): one frame line with a contact written to a
// file (a write(2) per line) against the same line into memory (flush is a no-op there). The
// difference is what the per-line flush costs; docs/BENCHMARKS.md puts it beside a frame's budget.
#include "hrcsense/sinks/sinks.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace hrcsense {
namespace {

FrameResult typical_result() {
  FrameResult result;
  result.frame = 1234;
  result.timestamp_ns = 41'133'333'333;
  result.valid = true;
  result.verdict.state = VerdictState::slow;
  result.verdict.speed_scale = 0.42F;
  result.verdict.reason = "in slow zone";
  result.contact.valid = true;
  result.contact.distance_m = 0.7123F;
  result.contact.closest_base = {1.1F, -0.2F, 0.9F};
  result.contact.closest_camera = {0.3F, 0.1F, 2.2F};
  result.contact.closest_robot_base = {0.5F, 0.0F, 0.8F};
  result.contact.robot_link = 3;
  result.foreground_points = 5823;
  result.invalid_pixels = 24682;
  result.latency_us = 593.1;
  for (const char* stage : {"threshold", "decimation", "to_disparity", "spatial", "temporal", "to_depth",
                            "foreground", "proximity", "safety"}) {
    result.timings.push_back({stage, 42.0});
  }
  return result;
}

void JsonLines_frame_file(benchmark::State& state) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("hrcsense_jsonl_bench_" + std::to_string(::getpid()) + ".jsonl");
  {
    std::ofstream file(path, std::ios::out | std::ios::trunc);
    JsonLinesSink sink(file);
    const FrameResult result = typical_result();
    for (auto _ : state) sink.frame(result);
  }
  std::filesystem::remove(path);
}
BENCHMARK(JsonLines_frame_file)->Name("JsonLines/frame/file_flushed");

void JsonLines_frame_memory(benchmark::State& state) {
  std::ostringstream memory;
  JsonLinesSink sink(memory);
  const FrameResult result = typical_result();
  for (auto _ : state) {
    sink.frame(result);
    if (memory.tellp() > (1 << 24)) memory.str(std::string());  // keep the buffer bounded
  }
}
BENCHMARK(JsonLines_frame_memory)->Name("JsonLines/frame/memory");

}  // namespace
}  // namespace hrcsense
