// SPDX-License-Identifier: Apache-2.0
// A scene like config/thesis-box.yaml, built in code so that the benchmarks need no files:
// a wall 2 m ahead, a table, and a small box that appears on the table at frame 100.
#pragma once

#include "hrcsense/pipeline.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/sim/sim.hpp"

#include <stdexcept>
#include <vector>

namespace hrcsense::bench {

inline constexpr int kLearnFrames = 100;

/// The simulator for the thesis box scene at 848x480 with D435-like noise.
inline Simulator thesis_box_simulator() {
  Simulator sim;
  sim.params.width = 848;
  sim.params.height = 480;
  sim.params.frames = 400;
  SceneObject wall;
  wall.name = "wall";
  wall.shapes.push_back(Shape::plane({0.0F, 0.0F, 2.0F}, {0.0F, 0.0F, -1.0F}));
  SceneObject table;
  table.name = "table";
  table.shapes.push_back(Shape::box({-0.8F, 0.05F, 0.6F}, {1.2F, 0.10F, 1.6F}));
  SceneObject box;
  box.name = "box";
  box.is_static = false;
  box.first_frame = kLearnFrames;
  box.shapes.push_back(Shape::box({0.5F, 0.0F, 1.0F}, {0.64F, 0.05F, 1.09F}));
  sim.scene.objects = {wall, table, box};
  Capsule robot_point;
  robot_point.a = robot_point.b = {-0.5F, -0.5F, 0.5F};
  sim.robot.capsules.push_back(robot_point);
  return sim;
}

/// Pipeline parameters matching the simulator (pose, robot).
inline PipelineParams thesis_box_params(const Simulator& sim) {
  PipelineParams params;
  params.T_base_camera = sim.T_base_camera;
  params.robot.points = sim.robot;
  params.background.frames = kLearnFrames;
  return params;
}

/// Renders the learning frames, learns the background, and returns it.
inline BackgroundModel learn_background(const Simulator& sim, const PipelineParams& params) {
  Pipeline pipeline(params);
  Frame frame;
  FrameResult result;
  for (int64_t i = 0; i < 4 * kLearnFrames && !pipeline.background_ready(); ++i) {
    sim.render(i, frame);
    pipeline.process(frame, fixed_robot_state({}), result);
  }
  if (!pipeline.background_ready()) throw std::runtime_error("background did not finish learning");
  return pipeline.background();
}

/// Renders `count` frames with the box present (from frame kLearnFrames on).
inline std::vector<Frame> render_box_frames(const Simulator& sim, int count) {
  std::vector<Frame> frames(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) sim.render(kLearnFrames + i, frames[static_cast<size_t>(i)]);
  return frames;
}

}  // namespace hrcsense::bench
