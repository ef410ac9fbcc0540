// SPDX-License-Identifier: Apache-2.0
// The camera calibration (`hrcsense calibrate`, issue H3 part 1) on config/cell-ur5-moving.yaml
// (the D435 at 848x480 with its noise, the arm's pick-and-place sweep):
//   Calibration/add_frame/848x480/keyframe  one frame into the samples as a keyframe: the 5×5
//                                  mean and median at every grid sample, the farthest depth
//   Calibration/add_frame/848x480/held  the same frame when it is no keyframe (the arm held):
//                                  the means and the farthest depth only
//   Calibration/fit/200_frames     the whole fit (coarse alignment, robust refinement, the
//                                  keyframes left out, the jackknife's spread) over the samples of
//                                  the first 200 frames, from a told pose 0.2 m and 15 degrees off
// The command's own run time (reading the simulator, progress fits, the final fit) is measured
// with `time hrcsense calibrate` in docs/BENCHMARKS.md.

#include "common/assembly.hpp"
#include "hrcsense/calibration.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace hrcsense {
namespace {

struct CalibrationBenchCell {
  Config config;
  Simulator sim;
};

CalibrationBenchCell calibration_bench_cell() {
  CalibrationBenchCell cell{
      load_config(std::string(HRCSENSE_BENCH_SOURCE_DIR) + "/config/cell-ur5-moving.yaml", {"sim.color=false"}), {}};
  cell.sim = make_simulator(cell.config);
  return cell;
}

// One frame into the samples; state.range(0): 1 when every frame is a keyframe (the patch
// medians too), 0 when the arm holds still (the means and the farthest depth only).
void BM_CalibrationAddFrame(benchmark::State& state) {
  const CalibrationBenchCell cell = calibration_bench_cell();
  const bool keyframes = state.range(0) != 0;
  CalibrationParams params = cell.config.calibration;
  params.keyframe_motion_m = keyframes ? 0.0 : 1e9;
  params.max_keyframes = 64;  // bounded memory over long runs (every second one dropped when full)
  std::vector<Frame> frames(30);
  for (size_t i = 0; i < frames.size(); ++i) cell.sim.render(static_cast<int64_t>(i), frames[i]);
  ArmSamples samples(params, cell.sim.intrinsics(), *cell.config.pipeline.robot.arm, BaseFrame::base);
  const JointAngles q = cell.sim.arm_joints(0).q_rad;
  int64_t index = 0;
  for (auto _ : state) {
    const Frame& frame = frames[static_cast<size_t>(index) % frames.size()];
    benchmark::DoNotOptimize(samples.add(index, frame.depth, q));
    ++index;
  }
}
BENCHMARK(BM_CalibrationAddFrame)->Name("Calibration/add_frame/848x480/keyframe")->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CalibrationAddFrame)->Name("Calibration/add_frame/848x480/held")->Arg(0)->Unit(benchmark::kMicrosecond);

void BM_CalibrationFit(benchmark::State& state) {
  const CalibrationBenchCell cell = calibration_bench_cell();
  ArmSamples samples(cell.config.calibration, cell.sim.intrinsics(), *cell.config.pipeline.robot.arm, BaseFrame::base);
  Frame frame;
  for (int64_t i = 0; i < 200; ++i) {
    cell.sim.render(i, frame);
    samples.add(i, frame.depth, cell.sim.arm_joints(i).q_rad, frame.stereo_baseline_mm);
  }
  Pose told = cell.sim.T_base_camera;
  told.linear() = Eigen::AngleAxisd(15.0 * 3.14159265358979323846 / 180.0, Eigen::Vector3d(1, 1, 0).normalized()) *
                  told.linear();
  told.translation() += Eigen::Vector3d(0.1, -0.1, 0.14);
  double error_mm = 0.0;
  for (auto _ : state) {
    const CameraCalibration fit = calibrate_camera(samples, told);
    error_mm = translation_between_m(fit.T_base_camera, cell.sim.T_base_camera) * 1000.0;
    benchmark::DoNotOptimize(fit);
  }
  state.counters["keyframes"] = static_cast<double>(samples.keyframes().size());
  state.counters["error_mm"] = error_mm;
}
BENCHMARK(BM_CalibrationFit)->Name("Calibration/fit/200_frames")->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace hrcsense
