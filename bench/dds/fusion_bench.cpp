// SPDX-License-Identifier: Apache-2.0
// The fuser's own work per instant (docs/BENCHMARKS.md, "Cells with several cameras"): each
// camera's measurement taken (a copy into its slot), the cameras fused into one measurement (the
// seen-free grids united, the robot's distance to the cubes no camera saw free) and decided once.
//   Fusion/instant/<cameras>cams_<cubes>: one instant of N cameras, every camera new; each
//   camera's grid has a random third of its cubes unknown (the union a few, next to the arm).
//   Fusion/instant/.../layout:1: the same where every camera leaves a person-sized box 0.4 ×
//   0.4 × 1.8 m unknown 0.7 m from the arm (a shadow no camera sees into) and one more box of its
//   own elsewhere: the union's nearest unknown cube is far, so the search goes farther.
//   Fusion/messages/<cameras>cams_<cubes>: the same through the hrcsense_msgs/Measurement
//   conversion each received sample goes through (dds/measurement_messages.hpp).
#include "dds/measurement_messages.hpp"
#include "hrcsense/fusion.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/safety.hpp"

#include <Eigen/Geometry>
#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr int64_t kT0 = 1'800'000'000'000'000'000;

// The 3-camera cell's grid (config/cell-ur5-3cam.yaml: 3 × 4 × 2.75 m at 0.05 m, 264 000 cubes)
// or the 3 × 3 × 2 m box (144 000).
SeenFreeGridSpec grid_spec(int cubes) {
  SeenFreeGridSpec spec;
  spec.enabled = true;
  spec.voxel_m = 0.05F;
  spec.box_base = cubes > 200000 ? Eigen::AlignedBox3f(Eigen::Vector3f(-1.5F, -2.5F, -0.75F), Eigen::Vector3f(1.5F, 1.5F, 2.0F))
                                 : Eigen::AlignedBox3f(Eigen::Vector3f(-1.5F, -1.5F, 0.0F), Eigen::Vector3f(1.5F, 1.5F, 2.0F));
  return spec;
}

struct FusionSetup {
  FusionParams params;
  std::vector<FusionCamera> cameras;
  std::vector<CameraMeasurement> measurements;
};

// N cameras, each with three link contacts and a grid: layout 0, a third of the cubes unknown to
// it (random, so that the union still leaves some unknown near the arm); layout 1, a shadow
// unknown to all and a box of its own.
FusionSetup setup(int camera_count, int cubes, int layout) {
  FusionSetup s;
  s.params.safety.mode = SafetyParams::Mode::ssm;
  s.params.robot.arm = builtin_robot(BuiltinArm::ur5);
  s.params.robot.padding_m = 0.05;
  s.params.grid = grid_spec(cubes);
  std::mt19937 random(7);
  for (int c = 0; c < camera_count; ++c) {
    const std::string name = "cam" + std::to_string(c);
    s.cameras.push_back({name, 90.0});
    CameraMeasurement m;
    m.camera_name = name;
    m.session = 1;
    m.nominal_fps = 90.0;
    m.valid = true;
    m.reason_code = ReasonCode::clear;
    for (int link = 1; link <= 3; ++link) {
      LinkContact l;
      l.link = link;
      l.contact.valid = true;
      l.contact.distance_m = 0.6F + 0.05F * static_cast<float>(c + link);
      l.speed_towards_mps = 0.3F;
      l.distance_uncertainty_m = 0.03F;
      m.links.push_back(l);
    }
    m.contact = m.links.front().contact;
    m.foreground_points = 2000;
    m.robot_state.valid = true;
    m.robot_state.q_rad = {-2.74, -1.0, 1.6, -2.17, -1.57, 0.0};
    m.robot_state.speed_fraction = 1.0;
    m.seen_free.reset(s.params.grid.cell_count());
    // The arm reaches towards +x +y (its tool near (0.55, 0.35, 0.2)); the shadow is behind its base.
    const Eigen::AlignedBox3f shadow(Eigen::Vector3f(-1.2F, -0.6F, 0.0F), Eigen::Vector3f(-0.8F, -0.2F, 1.8F));
    const Eigen::Vector3f own_corner(1.1F, -1.4F + 0.15F * static_cast<float>(c % 16), 0.2F);
    const Eigen::AlignedBox3f own(own_corner, own_corner + Eigen::Vector3f(0.3F, 0.3F, 0.5F));
    for (size_t i = 0; i < m.seen_free.cells; ++i) {
      const Eigen::Vector3f centre = s.params.grid.centre(i);
      const bool unknown = layout == 0 ? random() % 3 == 0 : shadow.contains(centre) || own.contains(centre);
      if (!unknown) m.seen_free.set(i);
    }
    s.measurements.push_back(std::move(m));
  }
  return s;
}

// One instant per iteration: every camera's measurement stamped anew and handed over by `take`
// (straight into CellFusion::add, or through the message), then fused and decided.
template <typename Take>
void run_instants(benchmark::State& state, Take take) {
  FusionSetup s = setup(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), static_cast<int>(state.range(2)));
  CellFusion fusion(s.cameras, s.params);
  SafetyMonitor monitor(s.params.safety, 90.0, true);
  FrameResult result;
  int64_t t = kT0;
  uint64_t sequence = 0;
  for (auto _ : state) {
    t += 11'111'111;
    ++sequence;
    for (CameraMeasurement& m : s.measurements) {
      m.capture_ns = t;
      m.sequence = sequence;
      take(fusion, m, t);
    }
    fusion.fuse(t, static_cast<int64_t>(sequence), t, result);
    monitor.decide(result, t);
    benchmark::DoNotOptimize(result.verdict.speed_scale);
  }
  state.counters["unknown_m"] = result.unknown_distance_m;
}

void BM_FusionInstant(benchmark::State& state) {
  run_instants(state, [](CellFusion& fusion, const CameraMeasurement& m, int64_t t) { fusion.add(m, t); });
}
BENCHMARK(BM_FusionInstant)->Name("Fusion/instant")->ArgNames({"cams", "cubes", "layout"})
    ->Args({3, 264000, 0})->Args({16, 144000, 0})->Args({3, 264000, 1})->Args({16, 144000, 1})->Unit(benchmark::kMicrosecond);

void BM_FusionMessages(benchmark::State& state) {
  ros2::MeasurementBuffers buffers;
  CameraMeasurement received;
  run_instants(state, [&](CellFusion& fusion, const CameraMeasurement& m, int64_t t) {
    const hrcsense_msgs_msg_dds__Measurement_ msg = ros2::measurement_message(m, "base", buffers);
    ros2::camera_measurement_from(msg, received);
    fusion.add(received, t);
  });
}
BENCHMARK(BM_FusionMessages)->Name("Fusion/messages")->ArgNames({"cams", "cubes", "layout"})
    ->Args({3, 264000, 0})->Args({16, 144000, 0})->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
