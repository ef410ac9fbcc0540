// SPDX-License-Identifier: Apache-2.0
// Tests of the brute-force proximity search against hand-computed values and a double reference.

#include "hrcsense/proximity.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace hrcsense {
namespace {

Capsule capsule(Eigen::Vector3f a, Eigen::Vector3f b, float radius_m, int link = 0) {
  Capsule c;
  c.a = a;
  c.b = b;
  c.radius_m = radius_m;
  c.link = link;
  return c;
}

PointCloud cloud_of(std::initializer_list<Eigen::Vector3f> points) {
  PointCloud cloud;
  uint32_t pixel = 100;
  for (const Eigen::Vector3f& p : points) cloud.push_back(p.x(), p.y(), p.z(), pixel++);
  return cloud;
}

TEST(PointCapsuleDistance, PointToPoint) {
  // A zero-length, zero-radius capsule is the thesis's robot point: plain Euclidean distance.
  const Capsule c = capsule({1, 2, 3}, {1, 2, 3}, 0.0F);
  Eigen::Vector3f closest;
  EXPECT_FLOAT_EQ(point_capsule_distance({4, 6, 3}, c, &closest), 5.0F);  // 3-4-5
  EXPECT_TRUE(closest.isApprox(Eigen::Vector3f(1, 2, 3)));
}

TEST(PointCapsuleDistance, SegmentInteriorAndEnds) {
  const Capsule c = capsule({0, 0, 0}, {2, 0, 0}, 0.25F);
  Eigen::Vector3f closest;
  // Beside the interior: perpendicular distance 1, minus the radius.
  EXPECT_FLOAT_EQ(point_capsule_distance({0.5F, 1, 0}, c, &closest), 0.75F);
  EXPECT_TRUE(closest.isApprox(Eigen::Vector3f(0.5F, 0.25F, 0)));
  // Beyond end b: distance to b (3-4-5 triangle in x/z), minus the radius.
  EXPECT_FLOAT_EQ(point_capsule_distance({5, 0, 4}, c, &closest), 4.75F);
  EXPECT_TRUE(closest.isApprox(Eigen::Vector3f(2 + 0.25F * 0.6F, 0, 0.25F * 0.8F)));
  // Before end a.
  EXPECT_FLOAT_EQ(point_capsule_distance({-1, 0, 0}, c, &closest), 0.75F);
  EXPECT_TRUE(closest.isApprox(Eigen::Vector3f(-0.25F, 0, 0)));
}

TEST(PointCapsuleDistance, InsideIsZero) {
  const Capsule c = capsule({0, 0, 0}, {0, 0, 1}, 0.1F);
  Eigen::Vector3f closest;
  const Eigen::Vector3f p(0.05F, 0, 0.5F);
  EXPECT_EQ(point_capsule_distance(p, c, &closest), 0.0F);
  EXPECT_TRUE(closest.isApprox(p));
  // On the axis itself.
  EXPECT_EQ(point_capsule_distance({0, 0, 0.3F}, c), 0.0F);
}

TEST(PointCapsuleDistance, DegenerateCapsuleIsSphere) {
  const Capsule c = capsule({1, 1, 1}, {1, 1, 1}, 0.5F);
  Eigen::Vector3f closest;
  EXPECT_FLOAT_EQ(point_capsule_distance({1, 1, 3}, c, &closest), 1.5F);
  EXPECT_TRUE(closest.isApprox(Eigen::Vector3f(1, 1, 1.5F)));
  EXPECT_EQ(point_capsule_distance({1, 1.2F, 1}, c), 0.0F);
}

TEST(ClosestContactBrute, EmptyInputsAreInvalid) {
  RobotModel robot;
  robot.capsules.push_back(capsule({0, 0, 0}, {0, 0, 0}, 0.0F));
  const PointCloud empty;
  EXPECT_FALSE(closest_contact_brute(empty, empty, robot).valid);
  const PointCloud one = cloud_of({{1, 0, 0}});
  EXPECT_FALSE(closest_contact_brute(one, empty, RobotModel{}).valid);
}

TEST(ClosestContactBrute, HandComputedContact) {
  RobotModel robot;
  robot.capsules.push_back(capsule({0, 0, 0}, {0, 0, 1}, 0.1F, 3));   // vertical link
  robot.capsules.push_back(capsule({5, 0, 0}, {5, 0, 0}, 0.0F, 7));   // far point
  const PointCloud base = cloud_of({{2, 0, 0.5F}, {0, 0.6F, 1.5F}, {4, 0, 0}});
  PointCloud camera = cloud_of({{9, 9, 9}, {8, 8, 8}, {7, 7, 7}});
  const Contact c = closest_contact_brute(base, camera, robot);
  // Point 1: to end b (0,0,1) the distance is sqrt(0.36 + 0.25) - 0.1; point 2: 1 to the far
  // point; point 0: 1.9 to the vertical link.
  const float expected = std::sqrt(0.61F) - 0.1F;
  ASSERT_TRUE(c.valid);
  EXPECT_NEAR(c.distance_m, expected, 1e-6F);
  EXPECT_TRUE(c.closest_base.isApprox(Eigen::Vector3f(0, 0.6F, 1.5F)));
  EXPECT_TRUE(c.closest_camera.isApprox(Eigen::Vector3f(8, 8, 8)));
  EXPECT_EQ(c.robot_link, 3);
  EXPECT_EQ(c.pixel, 101);
  const Eigen::Vector3f dir = Eigen::Vector3f(0, 0.6F, 0.5F).normalized();
  EXPECT_TRUE(c.closest_robot_base.isApprox(Eigen::Vector3f(0, 0, 1) + 0.1F * dir, 1e-5F));
  EXPECT_NEAR((c.closest_base - c.closest_robot_base).norm(), c.distance_m, 1e-5F);
}

TEST(ClosestContactBrute, WithoutCameraCloudLeavesCameraPointZero) {
  RobotModel robot;
  robot.capsules.push_back(capsule({0, 0, 0}, {0, 0, 0}, 0.0F));
  const Contact c = closest_contact_brute(cloud_of({{0, 0, 2}}), PointCloud{}, robot);
  ASSERT_TRUE(c.valid);
  EXPECT_FLOAT_EQ(c.distance_m, 2.0F);
  EXPECT_EQ(c.closest_camera, Eigen::Vector3f::Zero());
}

TEST(ClosestContactBrute, TiesPreferLowestPointThenLowestCapsule) {
  RobotModel robot;
  // Two capsules symmetric about the origin, both 1 m from points on the z axis.
  robot.capsules.push_back(capsule({-1, 0, 0}, {-1, 0, 0}, 0.0F, 4));
  robot.capsules.push_back(capsule({1, 0, 0}, {1, 0, 0}, 0.0F, 5));
  // Point 0 is farther; points 1 and 2 are equally close (1.0 exactly) to both capsules.
  const PointCloud base = cloud_of({{0, 0, 3}, {0, 0, 0}, {0, 0, 0}});
  const Contact c = closest_contact_brute(base, PointCloud{}, robot);
  ASSERT_TRUE(c.valid);
  EXPECT_EQ(c.distance_m, 1.0F);
  EXPECT_EQ(c.pixel, 101);     // lowest point index among the tied points
  EXPECT_EQ(c.robot_link, 4);  // lowest capsule index among the tied capsules

  // Only the second capsule at the minimum for the lowest point: it must be chosen even
  // though the first capsule reaches the same distance at a higher point index.
  RobotModel robot2;
  robot2.capsules.push_back(capsule({0, 0, 10}, {0, 0, 10}, 0.0F, 1));
  robot2.capsules.push_back(capsule({0, 0, -10}, {0, 0, -10}, 0.0F, 2));
  const PointCloud base2 = cloud_of({{0, 0, -9}, {0, 0, 9}});
  const Contact c2 = closest_contact_brute(base2, PointCloud{}, robot2);
  EXPECT_EQ(c2.pixel, 100);
  EXPECT_EQ(c2.robot_link, 2);
}

// Straightforward double-precision reference, written independently of the implementation.
struct BruteReference {
  double distance = std::numeric_limits<double>::infinity();
  size_t point = 0;
  size_t capsule = 0;
};

BruteReference brute_reference_contact(const PointCloud& cloud, const RobotModel& robot) {
  BruteReference best;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.point(i).cast<double>();
    for (size_t c = 0; c < robot.capsules.size(); ++c) {
      const Eigen::Vector3d a = robot.capsules[c].a.cast<double>();
      const Eigen::Vector3d b = robot.capsules[c].b.cast<double>();
      const Eigen::Vector3d ab = b - a;
      double t = ab.squaredNorm() > 0 ? (p - a).dot(ab) / ab.squaredNorm() : 0.0;
      t = std::clamp(t, 0.0, 1.0);
      const double d = std::max(0.0, (p - (a + t * ab)).norm() - robot.capsules[c].radius_m);
      if (d < best.distance) best = {d, i, c};
    }
  }
  return best;
}

TEST(ClosestContactBrute, RandomCloudsMatchDoubleReference) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> coord(-2.0F, 2.0F);
  std::uniform_real_distribution<float> radius(0.0F, 0.15F);
  for (int trial = 0; trial < 40; ++trial) {
    RobotModel robot;
    const int capsules = 1 + trial % 8;
    for (int c = 0; c < capsules; ++c) {
      const Eigen::Vector3f a(coord(rng), coord(rng), coord(rng));
      // Every fourth capsule degenerate, to cover the sphere case in the vector loop.
      const Eigen::Vector3f b = c % 4 == 3 ? a : Eigen::Vector3f(coord(rng), coord(rng), coord(rng));
      robot.capsules.push_back(capsule(a, b, radius(rng), 10 + c));
    }
    PointCloud cloud;
    const int points = 1 + (trial * 137) % 3000;  // odd sizes exercise the loop remainders
    for (int i = 0; i < points; ++i) {
      cloud.push_back(coord(rng) + 3.0F, coord(rng), coord(rng), static_cast<uint32_t>(i));
    }
    const BruteReference ref = brute_reference_contact(cloud, robot);
    const Contact c = closest_contact_brute(cloud, cloud, robot);
    ASSERT_TRUE(c.valid);
    EXPECT_NEAR(c.distance_m, ref.distance, 1e-5) << "trial " << trial;
    EXPECT_EQ(c.pixel, static_cast<int>(ref.point)) << "trial " << trial;
    EXPECT_EQ(c.robot_link, 10 + static_cast<int>(ref.capsule)) << "trial " << trial;
    EXPECT_TRUE(c.closest_base.isApprox(cloud.point(ref.point)));
    // The robot point lies on the capsule surface, at the reported distance from the cloud point.
    EXPECT_NEAR((c.closest_base - c.closest_robot_base).norm(), c.distance_m, 1e-5);
  }
}

}  // namespace
}  // namespace hrcsense
