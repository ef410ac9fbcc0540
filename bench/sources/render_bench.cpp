// SPDX-License-Identifier: Apache-2.0
// Sim/render/848x480: rendering one noisy frame with ground truth (reported apart from the
// processing path, which the other benchmarks time on pre-rendered frames).

#include "../common/thesis_scene.hpp"

#include <benchmark/benchmark.h>

namespace hrcsense {
namespace {

void BM_SimRender(benchmark::State& state) {
  const Simulator sim = bench::thesis_box_simulator();
  Frame frame;
  int64_t i = 0;
  for (auto _ : state) {
    sim.render(bench::kLearnFrames + (i++ % 100), frame);
    benchmark::DoNotOptimize(frame.depth.pixels.data());
  }
}

BENCHMARK(BM_SimRender)->Name("Sim/render/848x480")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
