// SPDX-License-Identifier: Apache-2.0
// PoseCheck/ur5/848x480: the per-frame camera pose check on a frame of config/cell-ur5.yaml (the
// D435 at 848x480 with its noise): the arm's visual shapes placed at the cell's joints
// (robot_render_capsules), the sparse rays through them compared with the source frame's depth,
// and the window's decision; what Pipeline::camera_pose_agrees does per frame. Budget: 0.1 ms
// (issue H3).

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/pose_check.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/sim/sim.hpp"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace hrcsense {
namespace {

void BM_PoseCheck(benchmark::State& state) {
  const Config config = load_config(std::string(HRCSENSE_BENCH_SOURCE_DIR) + "/config/cell-ur5.yaml", {"sim.color=false"});
  const Simulator sim = make_simulator(config);
  Frame frame;
  sim.render(0, frame);
  const PipelineParams& params = config.pipeline;
  PoseCheck check;
  check.params = params.pose_check;
  RobotModel visual;
  std::vector<ShapeInCamera> shapes;
  size_t samples = 0;
  for (auto _ : state) {
    robot_render_capsules(*params.robot.arm, config.robot_state.joints_rad, params.robot.base_frame, visual);
    const PoseDisagreement d =
        pose_disagreement(params.pose_check, frame.depth, frame.intrinsics, params.T_base_camera, visual, shapes);
    samples += d.samples;
    benchmark::DoNotOptimize(check.add(d));
  }
  state.counters["samples"] = benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_PoseCheck)->Name("PoseCheck/ur5/848x480")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
