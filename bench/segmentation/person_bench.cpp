// SPDX-License-Identifier: Apache-2.0
// Background/subtract_person/848x480: foreground extraction with a person in view, as in
// config/walk.yaml at its closest approach (~20k foreground pixels, where the flood fill
// matters); Background/prepare/848x480: the once-per-background set-up of the extractor.

#include "../common/thesis_scene.hpp"

#include <benchmark/benchmark.h>

namespace hrcsense {
namespace {

constexpr int kPersonFrame = bench::kLearnFrames;

/// The walk scene (camera frame = base frame): floor, walls, a workbench, the robot's pedestal,
/// and from frame kPersonFrame a person standing 2.06 m away right behind the robot point.
Simulator person_simulator() {
  Simulator sim;
  sim.params.width = 848;
  sim.params.height = 480;
  sim.params.frames = 400;
  SceneObject room;
  room.name = "room";
  room.shapes = {Shape::plane({0.0F, 1.2F, 0.0F}, {0.0F, -1.0F, 0.0F}),
                 Shape::plane({0.0F, 0.0F, 3.5F}, {0.0F, 0.0F, -1.0F}),
                 Shape::plane({-2.0F, 0.0F, 0.0F}, {1.0F, 0.0F, 0.0F}),
                 Shape::box({-1.9F, 0.45F, 2.6F}, {-1.1F, 1.2F, 3.4F}),
                 Shape::box({-0.45F, 0.5F, 1.45F}, {-0.15F, 1.2F, 1.75F})};
  SceneObject person;
  person.name = "person";
  person.is_static = false;
  person.first_frame = kPersonFrame;
  const Eigen::Vector3f at(-0.3F, 0.0F, 2.06F);
  person.shapes = {Shape::capsule(at + Eigen::Vector3f(-0.1F, 1.12F, 0.0F), at + Eigen::Vector3f(-0.1F, 0.35F, 0.0F), 0.08F),
                   Shape::capsule(at + Eigen::Vector3f(0.1F, 1.12F, 0.0F), at + Eigen::Vector3f(0.1F, 0.35F, 0.0F), 0.08F),
                   Shape::capsule(at + Eigen::Vector3f(0.0F, 0.25F, 0.0F), at + Eigen::Vector3f(0.0F, -0.2F, 0.0F), 0.17F),
                   Shape::capsule(at + Eigen::Vector3f(-0.25F, -0.22F, 0.0F), at + Eigen::Vector3f(-0.3F, 0.35F, 0.0F), 0.05F),
                   Shape::capsule(at + Eigen::Vector3f(0.25F, -0.22F, 0.0F), at + Eigen::Vector3f(0.3F, 0.35F, 0.0F), 0.05F)};
  person.shapes.push_back(Shape::sphere(at + Eigen::Vector3f(0.0F, -0.47F, 0.0F), 0.11F));
  sim.scene.objects = {room, person};
  Capsule robot_point;
  robot_point.a = robot_point.b = {-0.3F, 0.3F, 1.6F};
  sim.robot.capsules.push_back(robot_point);
  return sim;
}

/// An extractor prepared for `sim`'s frames against `background`.
ForegroundExtractor prepared_extractor(const Simulator& sim, const PipelineParams& params,
                                       const BackgroundModel& background) {
  ForegroundExtractor extractor;
  extractor.params = params.foreground;
  extractor.set_background(background, sim.intrinsics().fx, sim.params.baseline_mm, sim.params.depth_scale_m);
  return extractor;
}

void BM_SubtractPerson(benchmark::State& state) {
  const Simulator sim = person_simulator();
  const PipelineParams params = bench::thesis_box_params(sim);
  const BackgroundModel background = bench::learn_background(sim, params);
  std::vector<Frame> frames(16);
  for (size_t i = 0; i < frames.size(); ++i) sim.render(kPersonFrame + static_cast<int64_t>(i), frames[i]);
  ForegroundExtractor extractor = prepared_extractor(sim, params, background);
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

void BM_Prepare(benchmark::State& state) {
  const Simulator sim = person_simulator();
  const PipelineParams params = bench::thesis_box_params(sim);
  const BackgroundModel background = bench::learn_background(sim, params);
  ForegroundExtractor extractor = prepared_extractor(sim, params, background);
  for (auto _ : state) {
    extractor.set_background(background, sim.intrinsics().fx, sim.params.baseline_mm, sim.params.depth_scale_m);
    benchmark::ClobberMemory();
  }
}

BENCHMARK(BM_SubtractPerson)->Name("Background/subtract_person/848x480")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Prepare)->Name("Background/prepare/848x480")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
