// SPDX-License-Identifier: Apache-2.0
// Foreground extraction on hand-built frames: the background test, speckle removal by physical
// size (disc diameter), the workspace rule for unknown background, deprojection and the base frame.

#include "synthetic_frames.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/segmentation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace hrcsense {
namespace {

using namespace hrcsense::testing;

size_t count_ones(const std::vector<uint8_t>& mask) {
  size_t n = 0;
  for (const uint8_t m : mask) n += m;
  return n;
}

Foreground extract(const Frame& frame, const ForegroundParams& params = {},
                   const BackgroundModel& background = wall_background(), const Pose& pose = Pose::Identity()) {
  ForegroundExtractor extractor;
  extractor.params = params;
  extractor.set_background(background, frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
  Foreground out;
  EXPECT_TRUE(extractor.extract(frame, pose, out));
  return out;
}

// The noisy wall itself is never foreground.
TEST(ForegroundExtractor, EmptySceneHasNoForeground) {
  for (int f = 0; f < 20; ++f) {
    const Foreground fg = extract(wall_frame(f));
    EXPECT_EQ(count_ones(fg.mask), 0U);
    EXPECT_TRUE(fg.points_camera.empty());
    EXPECT_TRUE(fg.points_base.empty());
  }
}

// A 10x10 patch 0.3 m in front of the wall: foreground exactly there. Its margin is
// max(4 · 1.4 mm, 4 · σ_model(1.7 m) = 4 · 1.7² · 0.08 / (200 · 0.05) = 92.5 mm, 20 mm) < 0.3 m.
TEST(ForegroundExtractor, NearerPatchIsFoundExactly) {
  Frame frame = wall_frame(3);
  fill_rect(frame, 20, 15, 10, 10, 1700);
  const Foreground fg = extract(frame);
  EXPECT_EQ(fg.mask, rect_mask(20, 15, 10, 10));
  EXPECT_EQ(fg.points_camera.size(), 100U);
  EXPECT_EQ(fg.points_base.size(), 100U);
}

// The margin grows with the noise model: 0.08 m nearer than the wall is foreground at k_sigma 2
// (margin 2 · σ_model(1.92 m) = 59 mm) but not at the default k_sigma 4 (118 mm).
TEST(ForegroundExtractor, MarginFollowsNoiseModel) {
  Frame frame = wall_frame(4);
  fill_rect(frame, 20, 15, 10, 10, 1920);
  EXPECT_EQ(count_ones(extract(frame).mask), 0U);
  ForegroundParams sensitive;
  sensitive.k_sigma = 2.0F;
  EXPECT_EQ(extract(frame, sensitive).mask, rect_mask(20, 15, 10, 10));
}

// Size of a blob = the diameter of the disc of its area, 2 · sqrt(pixels / π) · mean z / fx. At
// 1 m with fx = 200 px (5 mm per pixel): a single pixel is 2 · sqrt(1 / π) · 5 = 5.6 mm, 2x2 is
// 11.3 mm, 7x7 is 2 · sqrt(49 / π) · 5 = 39.5 mm (all below min_object_mm = 40 → removed) and
// 9x9 is 50.8 mm (kept). (Recomputed by hand for the disc rule; the square rule gave 5, 10, 35
// and 45 mm, the same verdicts. min_object_mm 40 named here: the default is 32.)
TEST(ForegroundExtractor, SpecklesBelowMinObjectSizeAreRemoved) {
  Frame frame = wall_frame(5);
  fill_rect(frame, 2, 2, 1, 1, 1000);
  fill_rect(frame, 10, 2, 2, 2, 1000);
  fill_rect(frame, 20, 2, 7, 7, 1000);
  fill_rect(frame, 40, 30, 9, 9, 1000);
  ForegroundParams at_40;
  at_40.min_object_mm = 40.0F;
  EXPECT_EQ(extract(frame, at_40).mask, rect_mask(40, 30, 9, 9));

  // With min_object_mm = 30 the 7x7 blob (39.5 mm) survives too; the speckles do not.
  ForegroundParams lenient;
  lenient.min_object_mm = 30.0F;
  const Foreground fg = extract(frame, lenient);
  EXPECT_EQ(count_ones(fg.mask), 49U + 81U);
  EXPECT_EQ(fg.mask[static_cast<size_t>(2) * kWidth + 2], 0);
  EXPECT_EQ(fg.mask[static_cast<size_t>(2) * kWidth + 10], 0);
}

// Blobs are 8-connected but split at depth jumps over max(5 cm, 4 σ_model(z)); min_object_mm 40.
TEST(ForegroundExtractor, BlobsAreEightConnectedAndSplitAtDepthJumps) {
  ForegroundParams at_40;
  at_40.min_object_mm = 40.0F;
  // Two 6x6 squares at 1 m touching only at a corner: one blob of 2 · sqrt(72 / π) · 5 mm =
  // 47.9 mm (alone, each would be 2 · sqrt(36 / π) · 5 = 33.9 mm and removed).
  Frame diagonal = wall_frame(6);
  fill_rect(diagonal, 10, 10, 6, 6, 1000);
  fill_rect(diagonal, 16, 16, 6, 6, 1000);
  EXPECT_EQ(count_ones(extract(diagonal, at_40).mask), 72U);

  // A 14x7 strip at 1 m is one blob of 2 · sqrt(98 / π) · 5 mm = 55.9 mm (kept). With its right
  // half at 1.2 m the step (0.2 m) exceeds max(0.05, 4 · 1.2² · 0.08 / 10 = 46 mm): two blobs of
  // 39.5 mm and 2 · sqrt(49 / π) · 1.2 / 200 = 47.4 mm, so only the farther half survives.
  Frame strip = wall_frame(7);
  fill_rect(strip, 20, 20, 14, 7, 1000);
  EXPECT_EQ(extract(strip, at_40).mask, rect_mask(20, 20, 14, 7));
  fill_rect(strip, 27, 20, 7, 7, 1200);
  EXPECT_EQ(extract(strip, at_40).mask, rect_mask(27, 20, 7, 7));
  // A 4 cm step stays within one blob (jump limit 5 cm): mean 1.02 m, 57.0 mm, all kept.
  fill_rect(strip, 27, 20, 7, 7, 1040);
  EXPECT_EQ(extract(strip, at_40).mask, rect_mask(20, 20, 14, 7));
}

// Where the background was never valid, a valid pixel counts only inside workspace_base.
TEST(ForegroundExtractor, UnknownBackgroundCountsOnlyInsideWorkspace) {
  BackgroundModel background = wall_background();
  for (int v = 18; v < 30; ++v) {
    for (int u = 26; u < 38; ++u) background.mean_m[static_cast<size_t>(v) * kWidth + u] = 0.0F;
  }
  Frame frame = wall_frame(8);
  fill_rect(frame, 26, 18, 12, 12, 1500);
  fill_rect(frame, 0, 0, 5, 5, 0);  // invalid raw depth is never foreground

  // Default workspace: everything, so the unknown pixels count (2 · sqrt(144 / π) · 1.5 / 200 =
  // 101.6 mm).
  EXPECT_EQ(extract(frame, {}, background).mask, rect_mask(26, 18, 12, 12));

  // Only x >= 0 (base = camera frame here): x = (u − 31.5) / 200 · z >= 0 for u >= 32,
  // i.e. columns 32..37 (6x12 px, 2 · sqrt(72 / π) · 7.5 mm = 71.8 mm, kept).
  ForegroundParams right_half;
  right_half.workspace_base.min.x() = 0.0F;
  EXPECT_EQ(extract(frame, right_half, background).mask, rect_mask(32, 18, 6, 12));

  // A workspace ending at z = 1.4 m excludes the unknown pixels at 1.5 m, but not a pixel that
  // is nearer than a known background (the workspace only speaks for unknown background).
  ForegroundParams near;
  near.workspace_base.max.z() = 1.4F;
  fill_rect(frame, 2, 30, 12, 12, 1500);
  EXPECT_EQ(extract(frame, near, background).mask, rect_mask(2, 30, 12, 12));
}

// Camera points follow the pinhole formula x = (u − ppx) / fx · z, y = (v − ppy) / fy · z;
// the points come in raster order with pixel = v · width + u.
TEST(ForegroundExtractor, DeprojectsWithPinholeFormula) {
  Frame frame = wall_frame(9);
  fill_rect(frame, 50, 5, 10, 10, 1250);
  const Foreground fg = extract(frame);
  ASSERT_EQ(fg.points_camera.size(), 100U);
  for (size_t i = 0; i < fg.points_camera.size(); ++i) {
    const uint32_t pixel = fg.points_camera.pixel[i];
    const int u = static_cast<int>(pixel % kWidth);
    const int v = static_cast<int>(pixel / kWidth);
    EXPECT_EQ(pixel, static_cast<uint32_t>((5 + i / 10) * kWidth + 50 + i % 10));
    EXPECT_NEAR(fg.points_camera.x[i], (u - 31.5) / 200.0 * 1.25, 1e-6);
    EXPECT_NEAR(fg.points_camera.y[i], (v - 23.5) / 200.0 * 1.25, 1e-6);
    EXPECT_NEAR(fg.points_camera.z[i], 1.25, 1e-6);
  }
  // Two pixels by hand: (50, 5) → (0.115625, −0.115625, 1.25); (59, 14) → (0.171875, −0.059375, 1.25).
  EXPECT_NEAR(fg.points_camera.x.front(), 0.115625, 1e-6);
  EXPECT_NEAR(fg.points_camera.y.front(), -0.115625, 1e-6);
  EXPECT_NEAR(fg.points_camera.x.back(), 0.171875, 1e-6);
  EXPECT_NEAR(fg.points_camera.y.back(), -0.059375, 1e-6);
}

// With real distortion the points are those of deproject() (the SDK's inverse).
TEST(ForegroundExtractor, DeprojectsThroughDistortionModel) {
  Frame frame = wall_frame(10);
  frame.intrinsics.model = Distortion::brown_conrady;
  frame.intrinsics.coeffs = {0.1F, -0.05F, 0.001F, 0.002F, 0.01F};
  fill_rect(frame, 0, 0, 12, 12, 1100);  // a corner, where distortion matters most
  const Foreground fg = extract(frame);
  ASSERT_EQ(fg.points_camera.size(), 144U);
  for (size_t i = 0; i < fg.points_camera.size(); ++i) {
    const uint32_t pixel = fg.points_camera.pixel[i];
    const auto expected = deproject(frame.intrinsics,
                                    Eigen::Vector2f(static_cast<float>(pixel % kWidth), static_cast<float>(pixel / kWidth)),
                                    1.1F);
    ASSERT_TRUE(expected.has_value());
    EXPECT_NEAR((fg.points_camera.point(i) - *expected).norm(), 0.0, 1e-6) << "pixel " << pixel;
  }
}

// Base-frame points are T_base_camera · camera points.
TEST(ForegroundExtractor, BasePointsAreTransformedCameraPoints) {
  Pose T_base_camera = Pose::Identity();
  T_base_camera.linear() = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(-2.0, Eigen::Vector3d::UnitX()) *
                            Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()))
                               .toRotationMatrix();
  T_base_camera.translation() = Eigen::Vector3d(0.5, -1.2, 2.1);
  Frame frame = wall_frame(11);
  fill_rect(frame, 3, 30, 12, 12, 1500);
  const Foreground fg = extract(frame, {}, wall_background(), T_base_camera);
  ASSERT_EQ(fg.points_base.size(), 144U);
  for (size_t i = 0; i < fg.points_base.size(); ++i) {
    const Eigen::Vector3d expected = T_base_camera * fg.points_camera.point(i).cast<double>();
    EXPECT_NEAR((fg.points_base.point(i).cast<double>() - expected).norm(), 0.0, 1e-5);
    EXPECT_EQ(fg.points_base.pixel[i], fg.points_camera.pixel[i]);
  }
}

// After the first frame the extractor reuses its buffers and the caller's (no allocation).
TEST(ForegroundExtractor, ReusesBuffersAfterFirstFrame) {
  ForegroundExtractor extractor;
  Foreground out;
  const BackgroundModel background = wall_background();
  Frame frame = wall_frame(12);
  fill_rect(frame, 10, 10, 20, 20, 1000);
  extractor.set_background(background, kFx, kBaselineMm, frame.depth.depth_scale_m);
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), out));
  ASSERT_EQ(out.points_camera.size(), 400U);
  const uint8_t* mask = out.mask.data();
  const float* x = out.points_camera.x.data();
  const uint32_t* pixel = out.points_base.pixel.data();
  for (int f = 13; f < 16; ++f) {
    Frame bigger = wall_frame(f);
    fill_rect(bigger, 0, 0, 40 + f, 40, 1000);  // more points than the first frame
    ASSERT_TRUE(extractor.extract(bigger, Pose::Identity(), out));
    EXPECT_EQ(out.points_camera.size(), static_cast<size_t>((40 + f) * 40));
    EXPECT_EQ(out.mask.data(), mask);
    EXPECT_EQ(out.points_camera.x.data(), x);
    EXPECT_EQ(out.points_base.pixel.data(), pixel);
  }
}

}  // namespace
}  // namespace hrcsense
