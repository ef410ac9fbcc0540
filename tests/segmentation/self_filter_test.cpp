// SPDX-License-Identifier: Apache-2.0
// The self-filter on a pinhole camera small enough to work out by hand. The expected depths
// come from the geometry written in the comments (a ray's distance to a capsule's axis solved
// as a quadratic in the ray's depth), not from the filter's ray-capsule code, and the rules from
// self_filter.hpp: a pixel is the robot's when its depth lies in [nearest padded surface −
// max(margin_m, min_margin_m, k_sigma · σ(z)), farthest padded surface], over the union of the
// remembered poses, with the silhouette dilated by dilate_px.

#include "hrcsense/self_filter.hpp"

#include "hrcsense/segmentation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace hrcsense {
namespace {

constexpr int kSize = 101;        // 101 x 101 pixels, the optical axis through pixel (50, 50)
constexpr float kFocalPx = 100.0F;

Frame camera_frame(float baseline_mm = 0.0F) {
  Frame frame;
  frame.depth.resize(kSize, kSize);
  frame.depth.depth_scale_m = 0.001F;
  frame.intrinsics = Intrinsics{kSize, kSize, kFocalPx, kFocalPx, 50.0F, 50.0F, Distortion::none, {}};
  frame.stereo_baseline_mm = baseline_mm;
  return frame;
}

/// A horizontal bar 2 m in front of the camera: axis from x = −0.2 to 0.2 m at y = 0, z = z_m
/// (camera frame = base frame here), radius 0.1 m.
RobotModel bar_at(float z_m, float y_m = 0.0F) {
  RobotModel robot;
  Capsule c;
  c.a = Eigen::Vector3f(-0.2F, y_m, z_m);
  c.b = Eigen::Vector3f(0.2F, y_m, z_m);
  c.radius_m = 0.1F;
  robot.capsules.push_back(c);
  return robot;
}

size_t index(int u, int v) { return static_cast<size_t>(v) * kSize + static_cast<size_t>(u); }

/// Depths where the ray through pixel (50, v) meets the cylinder of radius r about the line
/// y = 0, z = z_axis: with y = t·(v − 50)/f and z = t, (t·s)² + (t − z_axis)² = r², s = (v − 50)/f.
std::pair<double, double> ray_meets_bar(int v, double z_axis, double r) {
  const double s = (v - 50) / static_cast<double>(kFocalPx);
  const double a = 1.0 + s * s, b = -2.0 * z_axis, c = z_axis * z_axis - r * r;
  const double disc = b * b - 4.0 * a * c;
  return {(-b - std::sqrt(disc)) / (2.0 * a), (-b + std::sqrt(disc)) / (2.0 * a)};
}

SelfFilter filter_with(int dilate_px, float margin_m = 0.03F, int memory = 1) {
  SelfFilter filter;
  filter.params.dilate_px = dilate_px;
  filter.params.margin_m = margin_m;
  filter.params.memory_frames = memory;
  return filter;
}

TEST(SelfFilter, CentrePixelSpansTheBarFromItsFrontToItsBack) {
  SelfFilter filter = filter_with(0);
  filter.add_pose(bar_at(2.0F));
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  // The optical axis meets the bar's front at 2.0 − 0.1 and its back at 2.0 + 0.1.
  EXPECT_NEAR(filter.surface_depth_m()[index(50, 50)], 1.9, 1e-5);
  const RobotPixels robot = filter.robot_pixels();
  // Without a baseline the margin is max(margin_m 0.03, min_margin_m 0.02): from 1.87 m.
  EXPECT_NEAR(robot.from_raw[index(50, 50)], 1870, 1);
  EXPECT_NEAR(robot.to_raw[index(50, 50)], 2100, 1);
  EXPECT_TRUE(robot.contains(index(50, 50), 1900));  // the arm's own surface
  EXPECT_TRUE(robot.contains(index(50, 50), 1880));  // within the margin in front
  EXPECT_FALSE(robot.contains(index(50, 50), 1800)); // a hand 10 cm in front of the arm
  EXPECT_FALSE(robot.contains(index(50, 50), 2150)); // something beyond the padded body
  EXPECT_FALSE(robot.contains(index(50, 50), 0));    // no data is never the robot's
}

TEST(SelfFilter, OffAxisPixelsFollowTheCylindersCurve) {
  SelfFilter filter = filter_with(0);
  filter.add_pose(bar_at(2.0F));
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  for (int v : {47, 52, 54}) {
    const auto [front, back] = ray_meets_bar(v, 2.0, 0.1);
    EXPECT_NEAR(filter.surface_depth_m()[index(50, v)], front, 1e-4) << "v = " << v;
    EXPECT_NEAR(filter.robot_pixels().to_raw[index(50, v)], std::floor(back * 1000.0), 1.0) << "v = " << v;
  }
  // The silhouette's half-height: tan(asin(0.1 / 2)) · f = 5.006 px, so rows 45..55 only.
  EXPECT_NE(filter.robot_pixels().from_raw[index(50, 55)], 0);
  EXPECT_EQ(filter.robot_pixels().from_raw[index(50, 56)], 0);
  EXPECT_EQ(filter.robot_pixels().from_raw[index(50, 44)], 0);
  // Column 90 looks 0.8 m beside the optical axis at 2 m, far past the bar's end at x = 0.3.
  EXPECT_EQ(filter.robot_pixels().from_raw[index(90, 50)], 0);
  EXPECT_EQ(filter.silhouette_pixels(), static_cast<size_t>(std::count_if(
                                            filter.robot_pixels().from_raw, filter.robot_pixels().from_raw + kSize * kSize,
                                            [](uint16_t x) { return x != 0; })));
}

TEST(SelfFilter, DilationGrowsTheSilhouetteWithTheNeighboursDepths) {
  SelfFilter filter = filter_with(2);
  filter.add_pose(bar_at(2.0F));
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  // Rows 56 and 57 are within 2 px of row 55, the last one inside; each takes the nearest front
  // of the 5x5 square around it: rows 55..59 hold only row 55's, rows 54..58 also row 54's,
  // which is nearer (closer to the axis).
  const double front_55 = ray_meets_bar(55, 2.0, 0.1).first;
  const double front_54 = ray_meets_bar(54, 2.0, 0.1).first;
  // Row 55 grazes the bar, where float's square root of a small discriminant leaves ~0.1 mm.
  EXPECT_NEAR(filter.surface_depth_m()[index(50, 57)], front_55, 5e-4);
  EXPECT_NEAR(filter.surface_depth_m()[index(50, 56)], front_54, 5e-4);
  EXPECT_EQ(filter.robot_pixels().from_raw[index(50, 58)], 0);
  EXPECT_TRUE(std::isinf(filter.surface_depth_m()[index(50, 58)]));
}

TEST(SelfFilter, MarginIsNeverBelowTheForegroundsNoiseTest) {
  // ForegroundParams' defaults: k_sigma 4, min_margin_m 0.02, subpixel 0.08 px. With a D435-like
  // baseline the stereo σ at 2 m is z² · 0.08 / (f · B) = 4 · 0.08 / (100 ·
  // 0.05) = 0.064 m; k_sigma 4 makes the margin 0.256 m, far above margin_m.
  SelfFilter filter = filter_with(0);
  filter.add_pose(bar_at(2.0F));
  filter.render(camera_frame(50.0F), Pose::Identity(), ForegroundParams{});
  const double front = 1.9;
  const double sigma = front * front * 0.08 / (kFocalPx * 0.05);
  EXPECT_NEAR(filter.robot_pixels().from_raw[index(50, 50)], std::ceil((front - 4.0 * sigma) * 1000.0), 1.0);
}

TEST(SelfFilter, RemembersTheUnionOfTheLastPoses) {
  // The arm moves away from the camera, 2 cm a frame: the filtered image still shows it where it
  // was (the temporal filter's lag), so the nearest remembered front counts.
  SelfFilter filter = filter_with(0, 0.03F, 3);
  const float depths[] = {2.00F, 2.02F, 2.04F, 2.06F};
  for (float z : depths) filter.add_pose(bar_at(z));
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  EXPECT_EQ(filter.poses(), 3);
  // Remembered: 2.02, 2.04, 2.06 (the oldest, 2.00, forgotten): front 1.92, back 2.16.
  EXPECT_NEAR(filter.surface_depth_m()[index(50, 50)], 1.92, 1e-5);
  EXPECT_NEAR(filter.robot_pixels().to_raw[index(50, 50)], 2160, 1);
  // Where the arm was two frames ago (2.02 − 0.1 = 1.92) is still the robot's.
  EXPECT_TRUE(filter.robot_pixels().contains(index(50, 50), 1925));
  filter.clear_poses();
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  EXPECT_EQ(filter.robot_pixels().from_raw[index(50, 50)], 0);
  EXPECT_EQ(filter.silhouette_pixels(), 0U);
}

TEST(SelfFilter, ARenderForgetsTheLastOnesPixels) {
  SelfFilter filter = filter_with(1);
  filter.add_pose(bar_at(2.0F, 0.3F));  // up in the image: rows around 50 + 0.3 / 2 · 100 = 65
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  EXPECT_NE(filter.robot_pixels().from_raw[index(50, 65)], 0);
  filter.add_pose(bar_at(2.0F, -0.3F));  // memory 1: only this pose, rows around 35
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  EXPECT_EQ(filter.robot_pixels().from_raw[index(50, 65)], 0);
  EXPECT_TRUE(std::isinf(filter.surface_depth_m()[index(50, 65)]));
  EXPECT_NE(filter.robot_pixels().from_raw[index(50, 35)], 0);
}

// RobotPixels' rectangle holds every pixel of the robot (a reader may skip the rest) and stays
// near the bar: at z ≈ 2 m, x within ±0.3 m and y 0.2-0.4 m project to columns 50 ± 16 and
// rows 60-70 (f = 100 px), grown here by at most the dilation, a pixel of slack and the
// nearer surface's larger scale. Without a pose it is empty.
TEST(SelfFilter, TheRectangleHoldsEveryRobotPixel) {
  SelfFilter filter = filter_with(2);
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  RobotPixels robot = filter.robot_pixels();
  EXPECT_TRUE(robot.u0 >= robot.u1 || robot.v0 >= robot.v1) << "no pose, yet a rectangle";
  filter.add_pose(bar_at(2.0F, 0.3F));
  filter.render(camera_frame(), Pose::Identity(), ForegroundParams{});
  robot = filter.robot_pixels();
  int inside = 0;
  for (int v = 0; v < kSize; ++v) {
    for (int u = 0; u < kSize; ++u) {
      if (robot.from_raw[index(u, v)] == 0) continue;
      ++inside;
      EXPECT_TRUE(u >= robot.u0 && u < robot.u1 && v >= robot.v0 && v < robot.v1) << u << ", " << v;
    }
  }
  EXPECT_GT(inside, 100);
  EXPECT_GE(robot.u0, 28);
  EXPECT_LE(robot.u1, 73);
  EXPECT_GE(robot.v0, 54);
  EXPECT_LE(robot.v1, 77);
}

TEST(SelfFilter, CameraPoseMovesTheArmIntoTheCameraFrame) {
  // The bar given in a base frame whose origin is 1 m behind the camera along its axis.
  SelfFilter filter = filter_with(0);
  filter.add_pose(bar_at(3.0F));
  Pose T_base_camera = Pose::Identity();
  T_base_camera.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);  // the camera at z = 1 in the base
  filter.render(camera_frame(), T_base_camera, ForegroundParams{});
  EXPECT_NEAR(filter.surface_depth_m()[index(50, 50)], 1.9, 1e-5);
}

// The foreground keeps a hand 10 cm in front of the arm and drops the arm itself.
/// The learnt background of a flat wall 3 m in front of the camera.
BackgroundModel wall_at_3m() {
  BackgroundModel background;
  background.width = background.height = kSize;
  background.mean_m.assign(kSize * kSize, 3.0F);
  background.spread_m.assign(kSize * kSize, 0.005F);
  background.valid_ratio.assign(kSize * kSize, 1.0F);
  return background;
}

/// The wall at 3 m, and the bar's rows 45..55 at 1 cm behind its rendered front surface.
void draw_wall_and_bar(const SelfFilter& filter, Frame& frame) {
  frame.depth.pixels.assign(kSize * kSize, 3000);
  for (int v = 45; v <= 55; ++v) {
    for (int u = 0; u < kSize; ++u) {
      const double front = filter.surface_depth_m()[index(u, v)];
      if (std::isfinite(front)) frame.depth.pixels[index(u, v)] = static_cast<uint16_t>(std::lround(front * 1000.0 + 10.0));
    }
  }
}

TEST(SelfFilter, ForegroundKeepsAHandInFrontOfTheArmAndDropsTheArm) {
  SelfFilter filter = filter_with(1);
  filter.add_pose(bar_at(2.0F));
  Frame frame = camera_frame();
  filter.render(frame, Pose::Identity(), ForegroundParams{});
  // Background: a wall at 3 m. The bar's own rows 45..55 at the bar's depth, and a 10 x 10 px
  // hand 10 cm in front of the bar's front at columns 40..49, rows 46..55.
  const BackgroundModel background = wall_at_3m();
  draw_wall_and_bar(filter, frame);
  for (int v = 46; v <= 55; ++v) {
    for (int u = 40; u <= 49; ++u) frame.depth.pixels[index(u, v)] = 1800;
  }
  ForegroundExtractor extractor;
  extractor.params.min_object_mm = 0.0F;
  extractor.set_background(background, kFocalPx, 0.0F, 0.001F);
  Foreground fg;
  const RobotPixels robot = filter.robot_pixels();
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), fg, &robot));
  EXPECT_EQ(fg.points_camera.size(), 100U);  // the hand, nothing of the arm
  for (size_t k = 0; k < fg.points_camera.size(); ++k) EXPECT_NEAR(fg.points_camera.z[k], 1.8F, 1e-4F);
  // Every other pixel of the bar's rows was the arm's: removed and counted.
  size_t arm = 0;
  for (int v = 45; v <= 55; ++v) {
    for (int u = 0; u < kSize; ++u) arm += frame.depth.pixels[index(u, v)] != 3000 && frame.depth.pixels[index(u, v)] != 1800;
  }
  EXPECT_EQ(fg.self_filtered_pixels, arm);
  // Without the self-filter the arm is foreground too.
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), fg));
  EXPECT_EQ(fg.points_camera.size(), 100U + arm);
  EXPECT_EQ(fg.self_filtered_pixels, 0U);
}


// The depth filters smear the arm's rim into what lies behind it: decimation's median of four
// and the spatial filter give rim pixels depths between the arm and the wall, beyond the padded
// body's far side, where no surface is. Such a pixel, with the arm nearer and the wall (or no
// depth) farther within dilate_px, is the arm's; a body behind the arm keeps every pixel whose
// neighbourhood holds only the arm and itself.
TEST(SelfFilter, TheArmsRimMixedWithTheWallIsTheArmsAndABodyBehindItStays) {
  SelfFilter filter = filter_with(2);
  filter.add_pose(bar_at(2.0F));
  Frame frame = camera_frame();
  filter.render(frame, Pose::Identity(), ForegroundParams{});
  // The wall at 3 m; the bar's rows 45..55 at its front + 1 cm (its cylinder covers columns
  // 40..60 at 1.9-2 m: x = ±0.2 m); rows 43..57 are its silhouette dilated by 2 px.
  const BackgroundModel background = wall_at_3m();
  draw_wall_and_bar(filter, frame);
  // Row 44 is outside the bar, inside the dilated silhouette, and its far side there is the
  // bar's back near its rim, about 2.0 m (ray_meets_bar(46, ...).second). 2.5 m is beyond it.
  ASSERT_LT(ray_meets_bar(46, 2.0, 0.1).second, 2.5);
  // Four mixed rim pixels at columns 43..46 of row 44: the arm below, the wall above.
  for (int u = 43; u <= 46; ++u) frame.depth.pixels[index(u, 44)] = 2500;
  // A body 50 cm behind the bar's front at columns 51..59, rows 40..44 (45 pixels): rows 40..42
  // lie outside the silhouette. In rows 43 and 44 the columns 51, 52, 58 and 59 have the wall
  // within 2 px beside them (columns 49, 50 and 60, 61): mixes by the rule, 8 pixels. Columns
  // 53..57 see only the body and the arm: 10 pixels, kept.
  for (int v = 40; v <= 44; ++v) {
    for (int u = 51; u <= 59; ++u) frame.depth.pixels[index(u, v)] = 2500;
  }
  ForegroundExtractor extractor;
  extractor.params.min_object_mm = 0.0F;
  extractor.set_background(background, kFocalPx, 0.0F, 0.001F);
  Foreground fg;
  RobotPixels robot = filter.robot_pixels();
  EXPECT_EQ(robot.smear_px, 2);
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), fg, &robot));
  EXPECT_EQ(fg.points_camera.size(), 27U + 10U);
  for (int v = 43; v <= 44; ++v) {
    for (int u = 53; u <= 57; ++u) EXPECT_EQ(fg.mask[index(u, v)], 1) << u << ", " << v;  // the body's nearest row stays
    for (int u : {43, 44, 45, 46, 51, 52, 58, 59}) EXPECT_EQ(fg.mask[index(u, v)], 0) << u << ", " << v;
  }
  // Without the rule (smear 0) the mixes and the body's corners are foreground: 4 + 45.
  robot.smear_px = 0;
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), fg, &robot));
  EXPECT_EQ(fg.points_camera.size(), 4U + 45U);

  // No depth above the rim (the sensor's edge dropouts) is as good as the wall behind it.
  robot.smear_px = 2;
  for (int v = 41; v <= 43; ++v) {
    for (int u = 40; u <= 49; ++u) frame.depth.pixels[index(u, v)] = 0;
  }
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), fg, &robot));
  for (int u = 43; u <= 46; ++u) EXPECT_EQ(fg.mask[index(u, 44)], 0) << u;
  // Without the arm nearer (its pixels lost) a pixel beyond the far side is never a mix.
  for (int u = 40; u <= 49; ++u) {
    for (int v = 45; v <= 46; ++v) frame.depth.pixels[index(u, v)] = 0;
  }
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), fg, &robot));
  for (int u = 43; u <= 46; ++u) EXPECT_EQ(fg.mask[index(u, 44)], 1) << u;
}

}  // namespace
}  // namespace hrcsense
