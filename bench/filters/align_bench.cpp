// SPDX-License-Identifier: Apache-2.0
// Depth ↔ colour alignment at 848x480 depth, onto an 848x480 colour camera (a mode the D435's
// RGB sensor offers) with the D435i test unit's depth→colour translation and a rotation of a
// few tenths of a degree, so every pixel takes the general path. Depth: the thesis box scene
// from the simulator, with its noise and dropouts.

#include "../common/thesis_scene.hpp"
#include "hrcsense/align.hpp"
#include "hrcsense/camera.hpp"

#include <benchmark/benchmark.h>

namespace hrcsense {
namespace {

struct AlignInput {
  Frame frame;
  Intrinsics color_intrinsics;
  Extrinsics depth_to_color;
  ColorImage color;
};

const AlignInput& align_input() {
  static const AlignInput input = [] {
    AlignInput in;
    const Simulator sim = bench::thesis_box_simulator();
    sim.render(bench::kLearnFrames + 10, in.frame);
    in.color_intrinsics = *d435_depth_intrinsics(848, 480);
    in.color_intrinsics.fx = in.color_intrinsics.fy = 615.0F;  // the RGB lens is narrower
    in.color_intrinsics.ppx = 421.7F;
    in.color_intrinsics.ppy = 243.1F;
    in.color_intrinsics.model = Distortion::inverse_brown_conrady;  // all-zero coefficients, as reported
    in.depth_to_color.rotation = {0.99999F, 0.0031F, -0.0024F, -0.0031F, 0.99999F, 0.0012F,
                                  0.0024F,  -0.0012F, 0.99999F};
    in.depth_to_color.translation_m = {0.01508F, 0.0000046F, 0.00017F};
    in.color.width = 848;
    in.color.height = 480;
    in.color.rgb.resize(848 * 480 * 3);
    for (size_t i = 0; i < in.color.rgb.size(); ++i) in.color.rgb[i] = static_cast<uint8_t>(i * 7);
    return in;
  }();
  return input;
}

void depth_to_color(benchmark::State& state) {
  const AlignInput& in = align_input();
  AlignDepthToColor align;
  DepthImage out;
  for (auto _ : state) {
    align.apply(in.frame.depth, in.frame.intrinsics, in.color_intrinsics, in.depth_to_color, out);
    benchmark::DoNotOptimize(out.pixels.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(depth_to_color)->Name("Align/depth_to_color/848x480")->Unit(benchmark::kMillisecond);

void color_to_depth(benchmark::State& state) {
  const AlignInput& in = align_input();
  AlignColorToDepth align;
  ColorImage out;
  for (auto _ : state) {
    align.apply(in.frame.depth, in.frame.intrinsics, in.color, in.color_intrinsics, in.depth_to_color, out);
    benchmark::DoNotOptimize(out.rgb.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(color_to_depth)->Name("Align/color_to_depth/848x480")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
