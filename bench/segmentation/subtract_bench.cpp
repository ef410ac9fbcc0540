// SPDX-License-Identifier: Apache-2.0
// Background/subtract/848x480: foreground extraction (test against the learnt background,
// speckle removal, deprojection to camera and base frames) on rendered thesis-box frames.

#include "../common/thesis_scene.hpp"

#include <benchmark/benchmark.h>

namespace hrcsense {
namespace {

void BM_BackgroundSubtract(benchmark::State& state) {
  const Simulator sim = bench::thesis_box_simulator();
  const PipelineParams params = bench::thesis_box_params(sim);
  const BackgroundModel background = bench::learn_background(sim, params);
  const std::vector<Frame> frames = bench::render_box_frames(sim, 16);
  ForegroundExtractor extractor;
  extractor.params = params.foreground;
  // Once per background, as the pipeline does; not part of the per-frame cost.
  const Frame& first = frames.front();
  extractor.set_background(background, first.intrinsics.fx, first.stereo_baseline_mm, first.depth.depth_scale_m);
  Foreground foreground;
  size_t i = 0;
  for (auto _ : state) {
    if (!extractor.extract(frames[i++ % frames.size()], params.T_base_camera, foreground)) {
      state.SkipWithError("the extractor was not prepared for the frame");
      break;
    }
    benchmark::DoNotOptimize(foreground.points_base.x.data());
  }
  state.counters["points"] = static_cast<double>(foreground.points_base.size());
}

BENCHMARK(BM_BackgroundSubtract)->Name("Background/subtract/848x480")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
