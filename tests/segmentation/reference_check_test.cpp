// SPDX-License-Identifier: Apache-2.0
// ReferenceCheck (background.reference, issue 30 item 6): a learnt background compared with a
// reference taught with the cell empty, on hand-built backgrounds of a wall 2 m in front of a
// camera at the base origin (identity pose: camera frame = base frame).
#include "synthetic_frames.hpp"

#include "hrcsense/segmentation.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hrcsense {
namespace {

using testing::kFx;
using testing::wall_background;
using testing::wall_frame;

// The learnt background with the rectangle [u0, u0 + w) × [v0, v0 + h) at depth_m: someone who
// stood there, still, while it was learnt.
BackgroundModel learnt_with(int u0, int v0, int w, int h, float depth_m) {
  BackgroundModel model = wall_background();
  for (int v = v0; v < v0 + h; ++v) {
    for (int u = u0; u < u0 + w; ++u) model.mean_m[static_cast<size_t>(v) * model.width + u] = depth_m;
  }
  return model;
}

// A robot point (radius 0) in the base frame.
RobotModel robot_at(const Eigen::Vector3f& p) {
  RobotModel robot;
  robot.capsules.push_back(Capsule{p, p, 0.0F, 0});
  return robot;
}

ReferenceCheck check_against_the_wall() {
  ReferenceCheck check;
  check.set_reference(wall_background());
  check.detection_mm = 40.0F;
  check.max_distance_m = 1.0F;
  return check;
}

// 12 x 20 px at 1.5 m: 2 · sqrt(240 / π) · 1.5 m / 200 px = 131 mm across; its nearest point
// (column 31, x = −0.5 px · 1.5 / 200 = −3.75 mm, at the row nearest the axis) lies 0.5 m in front
// of a robot point at z 1.0 m on the optical axis.
TEST(ReferenceCheck, FindsAStandingObjectNearTheRobotAndNamesItsBoxAndDepth) {
  ReferenceCheck check = check_against_the_wall();
  const ReferenceFinding f =
      check.compare(learnt_with(20, 10, 12, 20, 1.5F), wall_frame(0), Pose::Identity(), robot_at({0, 0, 1.0F}), nullptr);
  ASSERT_TRUE(f.found);
  EXPECT_EQ(f.blobs, 1);
  EXPECT_EQ(f.u_min, 20);
  EXPECT_EQ(f.u_max, 31);
  EXPECT_EQ(f.v_min, 10);
  EXPECT_EQ(f.v_max, 29);
  EXPECT_EQ(f.pixels, 240U);
  EXPECT_NEAR(f.depth_m, 1.5F, 1e-3F);
  EXPECT_NEAR(f.size_mm, 2.0 * std::sqrt(240.0 / 3.14159265358979) * 1.5 / kFx * 1000.0, 0.5);
  EXPECT_NEAR(f.distance_m, 0.5F, 0.01F);
}

TEST(ReferenceCheck, IgnoresObjectsFarFromTheRobot) {
  ReferenceCheck check = check_against_the_wall();
  // The same object, the robot 3 m to its side: beyond max_distance_m.
  const ReferenceFinding far = check.compare(learnt_with(20, 10, 12, 20, 1.5F), wall_frame(0), Pose::Identity(),
                                             robot_at({3.0F, 0, 1.5F}), nullptr);
  EXPECT_FALSE(far.found);
  // A larger limit takes it in.
  check.max_distance_m = 3.5F;
  EXPECT_TRUE(check.compare(learnt_with(20, 10, 12, 20, 1.5F), wall_frame(0), Pose::Identity(),
                            robot_at({3.0F, 0, 1.5F}), nullptr)
                  .found);
}

TEST(ReferenceCheck, IgnoresBlobsBelowTheDetectionSize) {
  ReferenceCheck check = check_against_the_wall();
  // 2 x 2 px at 1.5 m: 2 · sqrt(4 / π) · 7.5 mm = 16.9 mm < 40 mm.
  EXPECT_FALSE(check.compare(learnt_with(28, 20, 2, 2, 1.5F), wall_frame(0), Pose::Identity(), robot_at({0, 0, 1.4F}),
                             nullptr)
                   .found);
  // 6 x 6 px: 2 · sqrt(36 / π) · 7.5 mm = 50.8 mm ≥ 40 mm.
  EXPECT_TRUE(check.compare(learnt_with(28, 20, 6, 6, 1.5F), wall_frame(0), Pose::Identity(), robot_at({0, 0, 1.4F}),
                            nullptr)
                  .found);
}

TEST(ReferenceCheck, DifferencesWithinTheForegroundMarginAreNotObjects) {
  ReferenceCheck check = check_against_the_wall();
  // 2 cm nearer at 2 m: within 4 σ_model (4 · 2² · 0.08 / (200 · 0.05) = 0.128 m).
  EXPECT_FALSE(check.compare(learnt_with(20, 10, 12, 20, 1.98F), wall_frame(0), Pose::Identity(),
                             robot_at({0, 0, 1.5F}), nullptr)
                   .found);
  // Farther than the reference (an object taken away) is never "someone in the cell".
  EXPECT_FALSE(check.compare(learnt_with(20, 10, 12, 20, 2.5F), wall_frame(0), Pose::Identity(),
                             robot_at({0, 0, 1.5F}), nullptr)
                   .found);
  // The same background as the reference: nothing.
  EXPECT_FALSE(check.compare(wall_background(), wall_frame(0), Pose::Identity(), robot_at({0, 0, 1.5F}), nullptr).found);
}

TEST(ReferenceCheck, PixelsTheReferenceNeverMeasuredAreNotCompared) {
  ReferenceCheck check;
  BackgroundModel reference = wall_background();
  for (int v = 10; v < 30; ++v) {
    for (int u = 20; u < 32; ++u) reference.mean_m[static_cast<size_t>(v) * reference.width + u] = 0.0F;
  }
  check.set_reference(reference);
  EXPECT_FALSE(check.compare(learnt_with(20, 10, 12, 20, 1.5F), wall_frame(0), Pose::Identity(),
                             robot_at({0, 0, 1.0F}), nullptr)
                   .found);
}

// Without any robot pose the distance is unknown: every blob of the detection size counts.
TEST(ReferenceCheck, WithoutARobotPoseEveryBlobCounts) {
  ReferenceCheck check = check_against_the_wall();
  const ReferenceFinding f =
      check.compare(learnt_with(20, 10, 12, 20, 1.5F), wall_frame(0), Pose::Identity(), RobotModel{}, nullptr);
  EXPECT_TRUE(f.found);
  EXPECT_TRUE(std::isnan(f.distance_m));
}

// Two objects, the nearer to the robot is named; a reference of another size finds nothing
// (the caller refuses such a reference before).
TEST(ReferenceCheck, NamesTheBlobNearestTheRobot) {
  ReferenceCheck check = check_against_the_wall();
  BackgroundModel learnt = learnt_with(2, 2, 10, 10, 1.5F);
  for (int v = 30; v < 40; ++v) {
    for (int u = 50; u < 60; ++u) learnt.mean_m[static_cast<size_t>(v) * learnt.width + u] = 1.5F;
  }
  // Robot point beside the second blob (u 50..59 → x 0.14..0.21 m at 1.5 m).
  const ReferenceFinding f = check.compare(learnt, wall_frame(0), Pose::Identity(), robot_at({0.2F, 0.1F, 1.3F}), nullptr);
  ASSERT_TRUE(f.found);
  EXPECT_EQ(f.blobs, 2);
  EXPECT_EQ(f.u_min, 50);
  EXPECT_EQ(f.v_min, 30);
  EXPECT_FALSE(
      check.compare(wall_background(32, 24), wall_frame(0, 32, 24), Pose::Identity(), robot_at({0, 0, 1.0F}), nullptr)
          .found);
}

TEST(BackgroundLearner, RefuseStartsLearningOver) {
  BackgroundLearner learner;
  learner.params.frames = 3;
  for (int i = 0; i < 3; ++i) learner.add(wall_frame(i));
  ASSERT_TRUE(learner.ready());
  learner.refuse("someone stood in it");
  EXPECT_FALSE(learner.ready());
  EXPECT_EQ(learner.message(), "someone stood in it");
  EXPECT_EQ(learner.frames_seen(), 0);
  for (int i = 3; i < 6; ++i) learner.add(wall_frame(i));
  EXPECT_TRUE(learner.ready());
  EXPECT_NEAR(learner.model().mean_m[0], 2.0F, 0.003F);
}

}  // namespace
}  // namespace hrcsense
