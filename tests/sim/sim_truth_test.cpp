// SPDX-License-Identifier: Apache-2.0
// The ground truth's closest contact over rendered points (rendered_truth_contact), worked by
// hand: it must not share code with src/proximity, whose searches are tested against it.
#include "src/sim/sim_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hrcsense {
namespace {

Capsule capsule(Eigen::Vector3f a, Eigen::Vector3f b, float radius_m, int link) {
  Capsule c;
  c.a = a;
  c.b = b;
  c.radius_m = radius_m;
  c.link = link;
  return c;
}

TEST(RenderedTruth, HandWorkedClosestPairAgainstTwoCapsules) {
  PointCloud base, camera;
  base.push_back(0.0F, 2.0F, 0.5F, 7);   // 2 m above the segment x in [0, 1] on the floor: 2 - 0.1 = 1.9
  base.push_back(3.0F, 0.0F, 0.0F, 9);   // 2 m beyond its end (1, 0, 0): 2 - 0.1 = 1.9 (a tie, later point)
  base.push_back(0.5F, 0.0F, 1.3F, 11);  // 1.3 m above the segment's middle: 1.2, the closest
  camera = base;
  RobotModel robot;
  robot.capsules.push_back(capsule({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F, 0.0F}, 0.1F, 3));
  robot.capsules.push_back(capsule({10.0F, 0.0F, 0.0F}, {10.0F, 0.0F, 0.0F}, 0.0F, 5));  // a far point
  const Contact c = sim_detail::rendered_truth_contact(base, camera, robot);
  ASSERT_TRUE(c.valid);
  EXPECT_FLOAT_EQ(c.distance_m, 1.2F);
  EXPECT_FALSE(c.inside);
  EXPECT_EQ(c.pixel, 11);
  EXPECT_EQ(c.robot_link, 3);
  EXPECT_NEAR((c.closest_robot_base - Eigen::Vector3f(0.5F, 0.0F, 0.1F)).norm(), 0.0F, 1e-6F);
  EXPECT_EQ(c.closest_base, Eigen::Vector3f(0.5F, 0.0F, 1.3F));
}

TEST(RenderedTruth, TiesKeepTheFirstPointAndAPointInsideIsDistanceZero) {
  PointCloud base;
  base.push_back(0.0F, 2.0F, 0.0F, 1);
  base.push_back(0.0F, -2.0F, 0.0F, 2);  // the same 2 m from the point robot
  RobotModel robot;
  robot.capsules.push_back(capsule({0.0F, 0.0F, 0.0F}, {0.0F, 0.0F, 0.0F}, 0.0F, 0));
  Contact c = sim_detail::rendered_truth_contact(base, PointCloud{}, robot);
  ASSERT_TRUE(c.valid);
  EXPECT_FLOAT_EQ(c.distance_m, 2.0F);
  EXPECT_EQ(c.pixel, 1);

  base.push_back(0.05F, 0.0F, 0.0F, 3);  // inside a 0.1 m ball
  robot.capsules[0].radius_m = 0.1F;
  c = sim_detail::rendered_truth_contact(base, PointCloud{}, robot);
  EXPECT_EQ(c.distance_m, 0.0F);
  EXPECT_TRUE(c.inside);
  EXPECT_EQ(c.pixel, 3);
}

TEST(RenderedTruth, EmptyCloudOrRobotIsInvalid) {
  PointCloud base;
  base.push_back(1.0F, 0.0F, 0.0F, 0);
  EXPECT_FALSE(sim_detail::rendered_truth_contact(base, PointCloud{}, RobotModel{}).valid);
  RobotModel robot;
  robot.capsules.push_back(capsule({0.0F, 0.0F, 0.0F}, {0.0F, 0.0F, 0.0F}, 0.0F, 0));
  EXPECT_FALSE(sim_detail::rendered_truth_contact(PointCloud{}, PointCloud{}, robot).valid);
}

}  // namespace
}  // namespace hrcsense
