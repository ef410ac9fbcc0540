// SPDX-License-Identifier: Apache-2.0
// Pipeline/process/848x480: the whole per-frame path on pre-rendered thesis-box frames.

#include "../common/thesis_scene.hpp"

#include <benchmark/benchmark.h>

namespace hrcsense {
namespace {

void BM_PipelineProcess(benchmark::State& state) {
  const Simulator sim = bench::thesis_box_simulator();
  const PipelineParams params = bench::thesis_box_params(sim);
  Pipeline pipeline(params);
  pipeline.set_background(bench::learn_background(sim, params));
  const std::vector<Frame> frames = bench::render_box_frames(sim, 16);
  FrameResult result;
  size_t i = 0;
  for (auto _ : state) {
    pipeline.process(frames[i++ % frames.size()], fixed_robot_state({}), result);
    benchmark::DoNotOptimize(result.contact.distance_m);
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_PipelineProcess)->Name("Pipeline/process/848x480")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
