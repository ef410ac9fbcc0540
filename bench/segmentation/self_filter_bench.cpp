// SPDX-License-Identifier: Apache-2.0
// SelfFilter/ur5/848x480: the UR5 of config/cell-ur5-moving.yaml rendered into a full-resolution
// D435 depth frame, a new pose every iteration (the union of self_filter.memory_frames poses).
// Pipeline/moving_ur5_sdk/848x480: the whole per-frame path on that cell with the sdk filters,
// the self-filter and the arm's pose of each frame.

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/self_filter.hpp"
#include "hrcsense/sim/sim.hpp"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace hrcsense {
namespace {

Config moving_cell(const std::vector<std::string>& overrides) {
  return load_config(std::string(HRCSENSE_BENCH_SOURCE_DIR) + "/config/cell-ur5-moving.yaml", overrides);
}

RobotState state_at(const Config& config, int64_t frame, double fps) {
  const TrajectorySample sample = joints_at(*config.robot_state.trajectory, static_cast<double>(frame) / fps);
  RobotState state = fixed_robot_state(sample.q_rad);
  state.qd_rad_s = sample.qd_rad_s;
  return state;
}

void BM_SelfFilter(benchmark::State& state) {
  const Config config = moving_cell({"sim.noise=false", "sim.color=false"});
  const Simulator sim = make_simulator(config);
  Frame frame;
  sim.render(0, frame);  // the D435's 848x480 geometry, depth unit and baseline
  // One cycle of poses (81 frames at 30 fps), placed once: the benchmark times the filter.
  std::vector<RobotModel> poses(81);
  for (size_t i = 0; i < poses.size(); ++i) {
    robot_model_at(config.pipeline.robot, state_at(config, static_cast<int64_t>(i), config.sim.fps).q_rad, poses[i]);
  }
  SelfFilter filter;
  filter.params = config.pipeline.self_filter;
  size_t i = 0;
  size_t silhouette = 0;
  for (auto _ : state) {
    filter.add_pose(poses[i++ % poses.size()]);
    filter.render(frame, config.pipeline.T_base_camera, config.pipeline.foreground);
    silhouette += filter.silhouette_pixels();
    benchmark::DoNotOptimize(filter.robot_pixels().from_raw);
  }
  state.counters["silhouette_px"] = benchmark::Counter(static_cast<double>(silhouette), benchmark::Counter::kAvgIterations);
  state.SetItemsProcessed(state.iterations());
}

void BM_PipelineMovingUr5(benchmark::State& state) {
  const Config config = moving_cell({"sim.color=false"});
  const Simulator sim = make_simulator(config);
  const double fps = config.sim.fps;
  Pipeline pipeline(config.pipeline);
  Frame frame;
  FrameResult result;
  // Learn the background from the scene's first 100 frames (the arm moving, nobody in view).
  for (int64_t i = 0; i < config.pipeline.background.frames; ++i) {
    sim.render(i, frame);
    pipeline.process(frame, state_at(config, i, fps), result);
  }
  // Then 81 frames with the person in view (one arm cycle), cycled.
  std::vector<Frame> frames(81);
  std::vector<RobotState> states(frames.size());
  for (size_t k = 0; k < frames.size(); ++k) {
    const int64_t index = 240 + static_cast<int64_t>(k);
    sim.render(index, frames[k]);
    states[k] = state_at(config, index, fps);
  }
  size_t i = 0;
  for (auto _ : state) {
    const size_t k = i++ % frames.size();
    pipeline.process(frames[k], states[k], result);
    benchmark::DoNotOptimize(result.contact.distance_m);
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_SelfFilter)->Name("SelfFilter/ur5/848x480")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PipelineMovingUr5)->Name("Pipeline/moving_ur5_sdk/848x480")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
