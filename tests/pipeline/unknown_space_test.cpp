// SPDX-License-Identifier: Apache-2.0
// Unknown space (unknown_space.hpp) on images and capsules laid out by hand: the segment to
// capsule distance, each kind of pixel (no depth, hidden behind foreground, never valid, the
// robot's envelope and its stereo shadow, a fresh dropout), and the distance they give.

#include "unknown_space_row.hpp"
#include "hrcsense/unknown_space.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hrcsense {
namespace {

RobotModel one_capsule(Eigen::Vector3f a, Eigen::Vector3f b, float radius_m) {
  RobotModel robot;
  robot.capsules.push_back(test::capsule(a, b, radius_m));
  return robot;
}

TEST(UnknownSpace, SegmentToCapsuleDistance) {
  // A vertical capsule at x = 0.1, z = 1 (radius 0.02) and the z axis from 0.2 to 2 m: 0.08 m.
  const RobotModel robot = one_capsule({0.1F, -1.0F, 1.0F}, {0.1F, 1.0F, 1.0F}, 0.02F);
  EXPECT_NEAR(segment_capsule_distance({0, 0, 0.2F}, {0, 0, 2.0F}, robot), 0.08, 1e-6);
  // The segment ends before the capsule: from (0, 0, 0.5) to (0, 0, 0.9), the corner (0.1, 0.1).
  EXPECT_NEAR(segment_capsule_distance({0, 0, 0.2F}, {0, 0, 0.9F}, robot), std::sqrt(0.02) - 0.02, 1e-6);
  // Through the capsule: 0.
  EXPECT_EQ(segment_capsule_distance({0.1F, 0, 0.2F}, {0.1F, 0, 2.0F}, robot), 0.0F);
  EXPECT_TRUE(std::isinf(segment_capsule_distance({0, 0, 0}, {0, 0, 1}, RobotModel{})));
}

TEST(UnknownSpace, RaySegmentThroughAPixel) {
  Intrinsics in;
  in.fx = in.fy = 100.0F;
  in.ppx = 10.0F;
  in.ppy = 5.0F;
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(1, 0, 0);
  const RaySegment s = ray_segment(in, T, 20, 5, 0.5F, 2.0F);  // x = (20 − 10)/100 · z
  EXPECT_NEAR(s.from_base.x(), 1.05, 1e-6);
  EXPECT_NEAR(s.from_base.z(), 0.5, 1e-6);
  EXPECT_NEAR(s.to_base.x(), 1.2, 1e-6);
  EXPECT_NEAR(s.to_base.y(), 0.0, 1e-6);
}

// One row of 12 pixels, no pixel without depth yet (unknown_space_row.hpp).
struct Row : test::UnknownSpaceRow<12> {
  Row() : UnknownSpaceRow(0) {}
};

TEST(UnknownSpace, NothingUnknownInAClearFrame) {
  Row row;
  const UnknownSpace u = row.run(false);
  EXPECT_TRUE(std::isnan(u.distance_m));
  EXPECT_EQ(u.no_depth_pixels + u.hidden_pixels + u.never_valid_pixels, 0U);
}

TEST(UnknownSpace, NoDepthForThreeFramesIsUnknownAndMeasured) {
  Row row;
  row.depth.pixels[2] = 0;  // ray x = 0.02·z: at z = 1 it is 0.28 m from the axis, 0.23 m from the surface
  row.no_depth_frames[2] = 3;
  const UnknownSpace u = row.run(false);
  EXPECT_EQ(u.no_depth_pixels, 1U);
  // Closest approach of the segment z ∈ [0.2, 2] on x = 0.02·z to the line x = 0.3, z = 1:
  // the distance in the x-z plane from (0.3, 1) to the line through (0, 0) and (0.02, 1).
  const double along = (0.3 * 0.02 + 1.0) / std::sqrt(0.02 * 0.02 + 1.0);
  const double d = std::sqrt(0.3 * 0.3 + 1.0 - along * along) - 0.05;
  EXPECT_NEAR(u.distance_m, d, 1e-5);
  row.no_depth_frames[2] = 2;  // a fresh gap: a dropout
  const UnknownSpace fresh = row.run(false);
  EXPECT_EQ(fresh.dropout_pixels, 1U);
  EXPECT_TRUE(std::isnan(fresh.distance_m));
}

TEST(UnknownSpace, HiddenBehindForegroundFromItsDepthToTheBackground) {
  Row row;
  row.depth.pixels[3] = 1500;  // foreground at 1.5 m: hidden from 1.5 to 2 m
  row.mask[3] = 1;
  const UnknownSpace u = row.run(false);
  EXPECT_EQ(u.hidden_pixels, 1U);
  // The segment's near end (0.045, 0, 1.5) is the closest point to the line x = 0.3, z = 1.
  EXPECT_NEAR(u.distance_m, std::sqrt(0.255 * 0.255 + 0.25) - 0.05, 1e-5);
}

TEST(UnknownSpace, NeverValidAndFlickeringBackgroundAreReportedApart) {
  Row row;
  row.depth.pixels[4] = row.depth.pixels[5] = 0;
  row.no_depth_frames[4] = row.no_depth_frames[5] = 10;
  row.background.mean_m[4] = 0.0F;      // never valid
  row.background.valid_ratio[5] = 0.9F;  // valid in 90 % of the learning frames only
  const UnknownSpace u = row.run(false);
  EXPECT_EQ(u.never_valid_pixels, 2U);
  EXPECT_TRUE(std::isnan(u.distance_m));
}

TEST(UnknownSpace, TheEnvelopeAndItsStereoShadowAreNotUnknown) {
  Row row;
  // The robot's envelope at pixels 8-9, its front at 1 m; its shadow on the 2 m background is
  // fx·B·(1/1 − 1/2) = 2.5 px, so up to 3 + 1 = 4 px left of it: pixels 4-7. Pixel 3 is beyond.
  for (int u : {8, 9}) row.from[u] = 1000, row.to[u] = 1100, row.depth.pixels[u] = 0;
  for (int u : {3, 4, 7}) row.depth.pixels[u] = 0;
  for (int u : {3, 4, 7, 8, 9}) row.no_depth_frames[u] = 5;
  const UnknownSpace u = row.run(true);
  EXPECT_EQ(u.robot_shadow_pixels, 2U);  // 4 and 7
  EXPECT_EQ(u.no_depth_pixels, 1U);      // 3
  // Without the envelope all five are unknown.
  EXPECT_EQ(row.run(false).no_depth_pixels, 5U);
}

}  // namespace
}  // namespace hrcsense
