// SPDX-License-Identifier: Apache-2.0
// Background learning in simulated cells (issue G1 part 6): the Pipeline learns frame by frame
// from the simulator's full D435 model while people move, and the simulator's ground truth says
// who was where. A person seated far beyond the robot who sways a little must not keep learning
// from finishing; the same sway near the robot, or without a robot state (no motion region),
// must; a person walking in the workspace keeps learning from finishing until they leave.
//
// The cell: a UR5 in a fixed pose on a 0.8 m table at the base origin (z up, table top z = 0,
// floor z = -0.75), a back wall, the camera 2 m in front of the base and 1.5 m to its right,
// 1.2 m above the table top, looking back along -x and 20° down. The robot stands left in
// the image and a seat 3 m to the robot's right stands right in it, both about 2.5 m from the
// camera, so that the far and the near person are seen alike.
//
// 424x240 (the D435's smallest mode, the resolution the sdk preset's decimation gives at
// 848x480) and 30 learning frames keep each test to a few hundred small frames. No depth
// filters: these tests are about the learner and its motion region; the sdk chain's effect on
// what counts as motion is described in docs/ARCHITECTURE.md ("Background and foreground").
#include "../support/decide.hpp"
#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr int kLearnFrames = 30;  // background.frames

/// The cell's configuration without people; `wall_x_m` places the back wall (base x).
Config cell_config(float wall_x_m) {
  Config config = load_config("", {"sim.width=424", "sim.height=240", "sim.color=false", "source.seed=3",
                                   "background.frames=" + std::to_string(kLearnFrames), "filters.preset=none",
                                   // Pan 1.94 rad (the arm along -x of base at pan 0): it reaches
                                   // away from the seat, to the left.
                                   "robot.model=ur5", "robot.joints_rad=[1.941593, -1.5, 1.4, -1.5, -1.5708, 0.0]",
                                   "camera.T_base_camera={translation_m: [2.0, 1.5, 1.2], "
                                   "rotation_rpy_deg: [-110, 0, 90]}"});
  SceneObject room;
  room.name = "room";
  room.shapes.push_back(Shape::plane({0.0F, 0.0F, -0.75F}, {0.0F, 0.0F, 1.0F}));  // floor
  room.shapes.push_back(Shape::plane({wall_x_m, 0.0F, 0.0F}, {1.0F, 0.0F, 0.0F}));  // back wall
  room.shapes.push_back(Shape::box({-0.4F, -0.4F, -0.75F}, {0.4F, 0.4F, 0.0F}));   // the robot's table
  config.scene.objects.push_back(room);
  return config;
}

/// A seated person (torso, head, thighs, shins, forearms on the knees) on a static seat whose
/// front edge is at `seat_base` (base frame, on the floor), facing +x, swaying sideways (base y)
/// by ±`sway_m`: at +sway_m at 0.25 s, then alternately −sway_m and +sway_m every 0.5 s.
void add_seated_person(Config& config, const Eigen::Vector3f& seat_base, float sway_m) {
  SceneObject seat;
  seat.name = "seat";
  seat.shapes.push_back(Shape::box(seat_base + Eigen::Vector3f(-0.45F, -0.22F, 0.0F),
                                   seat_base + Eigen::Vector3f(-0.05F, 0.22F, 0.45F)));
  config.scene.objects.push_back(seat);
  SceneObject person;
  person.name = "person";
  person.is_static = false;
  const Eigen::Vector3f hip = seat_base + Eigen::Vector3f(-0.25F, 0.0F, 0.45F);
  person.shapes.push_back(Shape::capsule(hip + Eigen::Vector3f(0, 0, 0.12F), hip + Eigen::Vector3f(0, 0, 0.6F), 0.17F));
  person.shapes.push_back(Shape::sphere(hip + Eigen::Vector3f(0, 0, 0.85F), 0.11F));
  for (const float side : {-0.1F, 0.1F}) {
    const Eigen::Vector3f knee = hip + Eigen::Vector3f(0.45F, side, 0.08F);
    person.shapes.push_back(Shape::capsule(hip + Eigen::Vector3f(0, side, 0.08F), knee, 0.08F));
    person.shapes.push_back(Shape::capsule(knee, knee + Eigen::Vector3f(0, 0, -0.48F), 0.06F));
  }
  for (const float side : {-0.25F, 0.25F}) {
    person.shapes.push_back(
        Shape::capsule(hip + Eigen::Vector3f(0, side, 0.6F), hip + Eigen::Vector3f(0.3F, side, 0.25F), 0.05F));
  }
  person.path.push_back(Waypoint{0.0, Eigen::Vector3f::Zero()});
  for (int k = 0; k < 12; ++k) {
    person.path.push_back(Waypoint{0.25 + 0.5 * k, Eigen::Vector3f(0.0F, k % 2 == 0 ? sway_m : -sway_m, 0.0F)});
  }
  config.scene.objects.push_back(person);
}

/// A standing 1.78 m person (cell-ur5.yaml's body) walking along base x = `x_m` from y = `y0_m`
/// to `y1_m` in `leg_s` seconds and on to `y_exit_m` in as long.
void add_walker(Config& config, float x_m, float y0_m, float y1_m, float y_exit_m, double leg_s) {
  SceneObject person;
  person.name = "walker";
  person.is_static = false;
  person.shapes.push_back(Shape::capsule({0, 0.1F, 0.08F}, {0, 0.1F, 0.85F}, 0.08F));    // legs
  person.shapes.push_back(Shape::capsule({0, -0.1F, 0.08F}, {0, -0.1F, 0.85F}, 0.08F));
  person.shapes.push_back(Shape::capsule({0, 0, 0.95F}, {0, 0, 1.40F}, 0.17F));          // torso
  person.shapes.push_back(Shape::capsule({0, 0.25F, 1.42F}, {0, 0.3F, 0.85F}, 0.05F));   // arms
  person.shapes.push_back(Shape::capsule({0, -0.25F, 1.42F}, {0, -0.3F, 0.85F}, 0.05F));
  person.shapes.push_back(Shape::sphere({0, 0, 1.67F}, 0.11F));                          // head
  person.path = {Waypoint{0.0, Eigen::Vector3f(x_m, y0_m, -0.75F)}, Waypoint{leg_s, Eigen::Vector3f(x_m, y1_m, -0.75F)},
                 Waypoint{2.0 * leg_s, Eigen::Vector3f(x_m, y_exit_m, -0.75F)}};
  config.scene.objects.push_back(person);
}

/// What a learning run did, and where the people were (from the simulator's ground truth).
struct LearningRun {
  int64_t ready_frame = -1;       ///< the frame that completed the background; -1: none
  int restarts = 0;               ///< batches refused for motion
  int64_t first_seen = -1;        ///< first frame with a person pixel; -1: none
  int64_t last_seen = -1;         ///< last frame with a person pixel
  float min_distance_m = 1e9F;    ///< closest a person's rendered pixel came to the capsules
  double unknown_share = -1.0;    ///< Pipeline::unknown_background_share() at the end
  std::vector<uint16_t> covered;  ///< per pixel: frames of the learnt batch a person covered
  BackgroundModel background;     ///< the learnt model (empty when none)
};

/// Drives the Pipeline with frames 0 .. max_frames-1 of the configured cell until the
/// background is ready; the truth (who was seen where) covers all max_frames frames. With
/// `robot_state` the fixed UR5 pose is given (motion counts near it); without, every frame's
/// state is invalid, so that motion counts everywhere.
LearningRun learn(const Config& config, int64_t max_frames, bool robot_state = true) {
  const Simulator sim = make_simulator(config);
  Pipeline pipeline(config.pipeline);
  const RobotState state = robot_state ? fixed_robot_state(config.robot_state.joints_rad) : RobotState{};
  LearningRun run;
  Frame frame;
  FrameResult result;
  for (int64_t i = 0; i < max_frames; ++i) {
    sim.render(i, frame);
    const bool learning = !pipeline.background_ready();
    const std::vector<uint16_t>& labels = frame.truth->labels;
    if (run.covered.empty()) run.covered.assign(labels.size(), 0);
    if (learning && i % kLearnFrames == 0) std::fill(run.covered.begin(), run.covered.end(), 0);
    bool seen = false;
    for (size_t k = 0; k < labels.size(); ++k) {
      const bool person = labels[k] != kStaticLabel;
      if (learning) run.covered[k] += person ? 1 : 0;
      seen = seen || person;
    }
    if (seen) {
      if (run.first_seen < 0) run.first_seen = i;
      run.last_seen = i;
    }
    if (frame.truth->contact.valid) run.min_distance_m = std::min(run.min_distance_m, frame.truth->contact.distance_m);
    if (!learning) continue;
    test::process_and_decide(pipeline, frame, state, result);
    EXPECT_EQ(result.verdict.code, ReasonCode::learning_background) << "frame " << i;
    if (pipeline.background_ready()) run.ready_frame = i;
    // A batch ends every kLearnFrames frames; ending without a model means it was refused.
    if (i % kLearnFrames == kLearnFrames - 1 && !pipeline.background_ready()) ++run.restarts;
  }
  run.unknown_share = pipeline.unknown_background_share();
  if (pipeline.background_ready()) run.background = pipeline.background();
  return run;
}

// Where the seat's front edge stands: 3 m to the robot's right (base +y), or 1.2 m.
const Eigen::Vector3f kFarSeat(0.0F, 3.0F, -0.75F);
const Eigen::Vector3f kNearSeat(0.0F, 1.2F, -0.75F);
constexpr float kSwayM = 0.05F;  // ±5 cm: 10 cm from side to side, about 5 px at 2.5 m

TEST(LearningScenes, SeatedPersonSwayingFarBeyondTheRobotLetsLearningComplete) {
  Config config = cell_config(-1.2F);
  add_seated_person(config, kFarSeat, kSwayM);
  const LearningRun run = learn(config, 2 * kLearnFrames);
  // The premise, from the truth: the person is in view from the first frame and every one of
  // their pixels is farther than background.motion_max_distance_m from the padded capsules.
  ASSERT_EQ(run.first_seen, 0);
  ASSERT_GT(run.min_distance_m, config.pipeline.background.motion_max_distance_m + 0.3F);
  ASSERT_GE(run.ready_frame, 0) << "not learnt within 2 x background.frames (" << run.restarts << " restarts)";
  EXPECT_LE(run.ready_frame, 2 * kLearnFrames - 1);
  EXPECT_GE(run.last_seen, run.ready_frame);  // learnt while the person was in view

  // What moved far away was not learnt: compared with the same cell without the person, the
  // extra pixels of unknown background lie where the person was in some frame of the batch
  // (or next to such a pixel: the mean there mixes person and wall).
  Config empty = cell_config(-1.2F);
  SceneObject seat = config.scene.objects[1];
  empty.scene.objects.push_back(seat);
  const LearningRun still = learn(empty, kLearnFrames);
  ASSERT_EQ(still.ready_frame, kLearnFrames - 1);
  EXPECT_GT(run.unknown_share, still.unknown_share);
  const int width = config.sim.width;
  const int height = config.sim.height;
  size_t extra_unknown = 0;
  size_t outside_person = 0;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      if (run.background.mean_m[i] > 0.0F || !(still.background.mean_m[i] > 0.0F)) continue;
      ++extra_unknown;
      bool near_person = false;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const int nu = std::clamp(u + du, 0, width - 1);
          const int nv = std::clamp(v + dv, 0, height - 1);
          near_person = near_person || run.covered[static_cast<size_t>(nv) * width + nu] > 0;
        }
      }
      outside_person += near_person ? 0 : 1;
    }
  }
  EXPECT_GT(extra_unknown, 100U);
  EXPECT_EQ(outside_person, 0U) << "of " << extra_unknown << " pixels of unknown background";
}

// The control for the test above: the same person and sway, and the motion does restart
// learning when it counts (the test above could fail).
TEST(LearningScenes, SameSwayFarAwayRestartsLearningWithoutARobotState) {
  Config config = cell_config(-1.2F);
  add_seated_person(config, kFarSeat, kSwayM);
  const LearningRun run = learn(config, 2 * kLearnFrames, /*robot_state=*/false);
  EXPECT_EQ(run.ready_frame, -1);
  EXPECT_EQ(run.restarts, 2);
}

TEST(LearningScenes, SameSwayNearTheRobotRestartsLearning) {
  Config config = cell_config(-1.2F);
  add_seated_person(config, kNearSeat, kSwayM);
  const LearningRun run = learn(config, 2 * kLearnFrames);
  ASSERT_EQ(run.first_seen, 0);
  ASSERT_LT(run.min_distance_m, config.pipeline.background.motion_max_distance_m - 0.5F);
  EXPECT_EQ(run.ready_frame, -1);
  EXPECT_EQ(run.restarts, 2);
}

// A person walks into the workspace in front of the robot (0.9 m from the base, between it
// and the camera), along it and out again. Batches are consecutive and kLearnFrames long, so
// the batch holding the last frame L in which any pixel of the person is seen ends by
// L + kLearnFrames - 1, and the clean batch after it by L + 2 kLearnFrames - 1: the
// background must be ready after L and by then.
TEST(LearningScenes, PersonWalkingInTheWorkspaceKeepsLearningUntilTheyLeave) {
  Config config = cell_config(-1.2F);
  add_walker(config, 0.9F, -0.6F, 2.2F, -0.6F, 2.0);
  const LearningRun run = learn(config, 200);
  // The premise: they come within 2 m of the capsules, are seen in at least three batches and
  // leave before the end.
  ASSERT_LT(run.min_distance_m, config.pipeline.background.motion_max_distance_m);
  ASSERT_GE(run.first_seen, 0);
  ASSERT_LT(run.first_seen, kLearnFrames);
  ASSERT_GE(run.last_seen, 3 * kLearnFrames);
  ASSERT_GE(run.ready_frame, 0) << "never learnt after they left at frame " << run.last_seen;
  EXPECT_GT(run.ready_frame, run.last_seen);
  EXPECT_LE(run.ready_frame, run.last_seen + 2 * kLearnFrames - 1);
  // Every batch before the one that completed was refused.
  EXPECT_EQ(run.restarts, static_cast<int>(run.ready_frame / kLearnFrames));
  // The batch that was learnt did not see the person.
  EXPECT_EQ(*std::max_element(run.covered.begin(), run.covered.end()), 0);
}

// The motion of the walker of the next test is plain to the learner when it counts everywhere.
TEST(LearningScenes, PersonWalkingBehindTheRobotRestartsLearningWithoutARobotState) {
  Config config = cell_config(-2.5F);
  add_walker(config, -0.8F, -1.8F, 1.0F, -3.5F, 2.0);
  const LearningRun run = learn(config, 2 * kLearnFrames, /*robot_state=*/false);
  ASSERT_EQ(run.first_seen, 0);
  EXPECT_EQ(run.ready_frame, -1);
  EXPECT_EQ(run.restarts, 2);
}

// A person walking 0.8 m behind the robot base, within 1 m of its capsules, with a wall 1.7 m
// behind them. A pixel the walker covers in a few of the batch's frames has its mean near the
// wall, beyond background.motion_max_distance_m; its nearest sample is the walker, near the
// robot, and that is what must count (placing pixels at their mean alone accepted the first
// batch at frame 29 while the walker was in view until frame 100).
TEST(LearningScenes, PersonWalkingBehindTheRobotKeepsLearningUntilTheyLeave) {
  Config config = cell_config(-2.5F);
  add_walker(config, -0.8F, -1.8F, 1.0F, -3.5F, 2.0);
  const LearningRun run = learn(config, 200);
  ASSERT_LT(run.min_distance_m, 1.0F);
  ASSERT_EQ(run.first_seen, 0);
  ASSERT_GE(run.last_seen, 3 * kLearnFrames);
  ASSERT_GE(run.ready_frame, 0) << "never learnt after they left at frame " << run.last_seen;
  EXPECT_GT(run.ready_frame, run.last_seen);
  EXPECT_LE(run.ready_frame, run.last_seen + 2 * kLearnFrames - 1);
}

}  // namespace
}  // namespace hrcsense
