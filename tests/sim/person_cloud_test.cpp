// SPDX-License-Identifier: Apache-2.0
// The synthetic person cloud (person_cloud.hpp) that the proximity benchmarks and Table 4.4 of
// `hrcsense eval` use: the size asked for, the same cloud every time, depth-image order, and
// every point on the camera-facing surface of a person standing 2 m in front of the camera.
#include "hrcsense/sim/person_cloud.hpp"
#include "hrcsense/proximity.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hrcsense {
namespace {

TEST(PersonCloud, HasTheSizeAskedForAndIsTheSameEveryTime) {
  for (const size_t n : {size_t{1}, size_t{100}, size_t{12345}}) {
    const PointCloud a = person_cloud(n);
    const PointCloud b = person_cloud(n);
    ASSERT_EQ(a.size(), n);
    ASSERT_EQ(b.size(), n);
    for (size_t i = 0; i < n; ++i) {
      ASSERT_EQ(a.x[i], b.x[i]);
      ASSERT_EQ(a.z[i], b.z[i]);
    }
  }
}

// A person 2 m away: head top at y = -0.86 m, feet at 1.07 m, hands within 0.35 m of the middle
// (the parts' axes plus radii, worked from the figure in the header); only the half facing the
// camera: the visible edge of a part lies behind its axis (z 2 m) by at most r·sin of the view
// angle, under 4 cm for the head (r 0.11 m, 0.36 rad) and the feet (0.07 m, 0.5 rad); nothing is
// nearer than the forward left hand (z 1.85 m) less its radius.
TEST(PersonCloud, PointsLieOnThePersonsCameraFacingSideInPixelOrder) {
  const PointCloud cloud = person_cloud(20000);
  uint32_t previous_pixel = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_GE(cloud.x[i], -0.36F);
    EXPECT_LE(cloud.x[i], 0.36F);
    EXPECT_GE(cloud.y[i], -0.87F);
    EXPECT_LE(cloud.y[i], 1.08F);
    EXPECT_GE(cloud.z[i], 1.79F);
    EXPECT_LE(cloud.z[i], 2.04F);
    EXPECT_GE(cloud.pixel[i], previous_pixel) << "point " << i;
    previous_pixel = cloud.pixel[i];
  }
}

// The robot point (-0.3, 0.3, 1.6) m is nearest the forward left hand: the arm's end (-0.3, 0.1,
// 1.85) is sqrt(0.2² + 0.25²) = 0.3202 m away, less the arm's radius 0.05 m: 0.2702 m to its
// surface. A dense cloud has a sample within a centimetre of that point, none nearer.
TEST(PersonCloud, TheRobotPointIsBesideThePerson) {
  const Contact contact = closest_contact_brute(person_cloud(50000), PointCloud{}, person_cloud_robot_point());
  ASSERT_TRUE(contact.valid);
  EXPECT_GE(contact.distance_m, 0.2702F - 1e-4F);
  EXPECT_LT(contact.distance_m, 0.2702F + 0.01F);
  EXPECT_EQ(person_cloud_robot_arm8().capsules.size(), 8U);
}

}  // namespace
}  // namespace hrcsense
