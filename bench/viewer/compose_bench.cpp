// SPDX-License-Identifier: Apache-2.0
// The viewer's CPU side per drawn frame (viewer/view_model.hpp): the whole 2D pane of a
// processed 848×480 frame with colour, and its parts, on walk.yaml at the closest approach
// (frame 198) and on the moving UR5 cell (frame 300: the arm's capsules in view); the 3D
// pane of the same UR5 frame at 1280×720.
#include "viewer/cloud_view.hpp"
#include "viewer/view_model.hpp"
#include "viewer/view_tap.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"

#include <benchmark/benchmark.h>

#include <string>

namespace hrcsense::view {
namespace {

// Runs the configured cell up to `index` and returns that frame as the viewer gets it.
ViewFrame processed_frame(const std::string& config_name, int64_t index) {
  const Config config = load_config(std::string(HRCSENSE_BENCH_SOURCE_DIR) + "/config/" + config_name, {});
  std::unique_ptr<Source> source = make_source(config);
  std::unique_ptr<RobotStateSource> states = make_robot_state_source(config, *source);
  Pipeline pipeline(config.pipeline);
  Frame frame;
  FrameResult result;
  RobotState state;
  ViewFrame out;
  for (int64_t i = 0; i <= index && source->next(frame) == Source::Status::frame; ++i) {
    if (!states->state_at(frame.timestamp_ns, state)) state.valid = false;
    pipeline.process(frame, state, result);
    if (i == index) fill_view_frame(frame, pipeline, result, 0, out);
  }
  return out;
}

void BM_Compose(benchmark::State& state, const char* config_name, int64_t index) {
  const ViewFrame frame = processed_frame(config_name, index);
  ComposeScratch scratch;
  ColorImage out;
  for (auto _ : state) {
    compose_2d(frame, 0.5F, 6, scratch, out);
    benchmark::DoNotOptimize(out.rgb.data());
  }
  state.counters["capsules"] = static_cast<double>(frame.capsules_base.size());
  state.counters["foreground_points"] = static_cast<double>(frame.foreground_points);
}

void BM_ComposeAlign(benchmark::State& state) {
  const ViewFrame frame = processed_frame("walk.yaml", 198);
  AlignDepthToColor align;
  DepthImage aligned;
  for (auto _ : state) {
    align.apply(frame.depth, frame.depth_intrinsics, frame.color_intrinsics, *frame.depth_to_color, aligned);
    benchmark::DoNotOptimize(aligned.pixels.data());
  }
}

void BM_ComposeColorize(benchmark::State& state) {
  const ViewFrame frame = processed_frame("walk.yaml", 198);
  std::vector<uint32_t> histogram;
  std::vector<uint32_t> lut;
  ColorImage rgb;
  for (auto _ : state) {
    colorize_depth(frame.depth, histogram, lut, rgb);
    benchmark::DoNotOptimize(rgb.rgb.data());
  }
}

void BM_ComposeRobotMask(benchmark::State& state) {
  const ViewFrame frame = processed_frame("cell-ur5-moving.yaml", 300);
  const ViewCamera camera = view_camera(frame);
  std::vector<uint8_t> mask;
  for (auto _ : state) {
    robot_mask(frame.capsules_base, frame.T_camera_base, camera, mask);
    benchmark::DoNotOptimize(mask.data());
  }
}

void BM_Compose3d(benchmark::State& state) {
  const ViewFrame frame = processed_frame("cell-ur5-moving.yaml", 300);
  const OrbitCamera orbit = default_orbit(frame);
  Cloud3dScratch scratch;
  ColorImage out;
  for (auto _ : state) {
    compose_3d(frame, orbit, 1280, 720, scratch, out);
    benchmark::DoNotOptimize(out.rgb.data());
  }
}

BENCHMARK_CAPTURE(BM_Compose, walk, "walk.yaml", 198)->Name("View/compose_walk/848x480")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Compose, ur5, "cell-ur5-moving.yaml", 300)
    ->Name("View/compose_ur5_moving/848x480")
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ComposeAlign)->Name("View/align_depth_to_color/848x480")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ComposeColorize)->Name("View/colorize_depth/848x480")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ComposeRobotMask)->Name("View/robot_mask_ur5/848x480")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Compose3d)->Name("View/compose_3d_ur5_moving/1280x720")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense::view
