// SPDX-License-Identifier: Apache-2.0
// The foreground rules on frames small enough to work out by hand: every expected mask, point
// and count below is derived in the comments from the documented rules (segmentation.hpp,
// docs/ARCHITECTURE.md "Background and foreground", docs/CONFIG.md "foreground"), not from the
// extractor's code:
// - a pixel is foreground when its depth is valid (raw ≠ 0) and nearer than the background by
//   more than max(k_sigma · spread, k_sigma · σ_model(z), min_margin_m), σ_model(z) =
//   z² · s / (fx · B) only when the baseline B is known, z the pixel's measured depth;
// - where the background is unknown (mean 0: never valid), a valid pixel counts only inside
//   workspace_base, a box in the base frame (default: everywhere);
// - 8-connected blobs whose size, the diameter of the disc of their pixel area at their mean
//   depth, 2 · sqrt(pixels / π) · mean z / fx, is below min_object_mm are removed (neighbours a
//   few cm apart in depth join: the jump limit is 5 cm without a baseline);
// - the rest is deprojected with the pinhole formula x = (u − ppx) / fx · z, y = (v − ppy) / fy · z
//   in raster order, and mapped into the base frame by T_base_camera.
// Masks are written as rows of text, '#' foreground and '.' not, so that a failure shows the
// picture. ForegroundExtractor has no disparity-domain variant (segmentation.hpp), so there is
// none to test here.

#include "hrcsense/segmentation.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr int kW = 8;  // most frames here are 8x6
constexpr int kH = 6;

/// A pinhole frame of `width` x `height` with the given raw depths (row-major).
Frame frame_of(int width, int height, const std::vector<uint16_t>& raw, float fx = 100.0F, float fy = 100.0F,
               float ppx = 3.5F, float ppy = 2.5F, float depth_scale_m = 0.001F, float baseline_mm = 0.0F) {
  Frame frame;
  frame.depth.resize(width, height);
  frame.depth.depth_scale_m = depth_scale_m;
  frame.depth.pixels = raw;
  frame.intrinsics = Intrinsics{width, height, fx, fy, ppx, ppy, Distortion::none, {}};
  frame.stereo_baseline_mm = baseline_mm;
  return frame;
}

/// A background of one mean and spread everywhere, valid in every learning frame.
BackgroundModel uniform_background(int width, int height, float mean_m, float spread_m) {
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  BackgroundModel model;
  model.width = width;
  model.height = height;
  model.mean_m.assign(n, mean_m);
  model.spread_m.assign(n, spread_m);
  model.valid_ratio.assign(n, 1.0F);
  return model;
}

/// Marks pixel (u, v) of `model` as never valid while learning: unknown background.
void make_unknown(BackgroundModel& model, int u, int v) {
  const size_t i = static_cast<size_t>(v) * static_cast<size_t>(model.width) + static_cast<size_t>(u);
  model.mean_m[i] = 0.0F;
  model.spread_m[i] = 0.0F;
  model.valid_ratio[i] = 0.0F;
}

/// Prepares an extractor for `frame`'s camera against `background` and extracts the frame.
Foreground extract(const Frame& frame, const BackgroundModel& background, const ForegroundParams& params,
                   const Pose& T_base_camera = Pose::Identity()) {
  ForegroundExtractor extractor;
  extractor.params = params;
  extractor.set_background(background, frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
  Foreground out;
  EXPECT_TRUE(extractor.extract(frame, T_base_camera, out));
  return out;
}

/// The mask as rows of '#' (foreground) and '.'.
std::vector<std::string> rows(const std::vector<uint8_t>& mask, int width) {
  std::vector<std::string> out;
  for (size_t i = 0; i < mask.size(); i += static_cast<size_t>(width)) {
    std::string row;
    for (size_t j = i; j < i + static_cast<size_t>(width); ++j) row += mask[j] != 0 ? '#' : '.';
    out.push_back(row);
  }
  return out;
}

/// Parameters where every blob survives (size ≥ 0 mm), for the tests of the per-pixel rules.
ForegroundParams no_speckle_removal() {
  ForegroundParams params;
  params.min_object_mm = 0.0F;
  return params;
}

/// Default parameters with speckle removal at `min_object_mm`: the tests of the size rule name
/// their threshold rather than lean on the default.
ForegroundParams speckle_removal_at(float min_object_mm) {
  ForegroundParams params;
  params.min_object_mm = min_object_mm;
  return params;
}

/// Base frame of a camera looking along base +x from 1 m behind the origin, 1.5 m up: camera x
/// (right) is base −y, camera y (down) is base −z, camera z (forward) is base +x, so
/// p_base = (z − 1, −x, 1.5 − y).
Pose camera_facing_base_x() {
  Pose T_base_camera = Pose::Identity();
  T_base_camera.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T_base_camera.translation() = Eigen::Vector3d(-1.0, 0.0, 1.5);
  return T_base_camera;
}

// Wall at 2.000 m, no baseline (no σ_model), k_sigma 4, min_margin 20 mm. The spread differs
// per column pair, so the margin max(4 · spread, 20 mm) is:
//   columns 0-1: spread 0      → max(0, 20)      = 20 mm  → foreground iff z < 1.980 m
//   columns 2-3: spread 4 mm   → max(16, 20)     = 20 mm  → z < 1.980 m (min_margin wins)
//   columns 4-5: spread 10 mm  → max(40, 20)     = 40 mm  → z < 1.960 m (k_sigma wins)
//   columns 6-7: spread 30 mm  → max(120, 20)    = 120 mm → z < 1.880 m
// Each row is 1 mm on either side of one of those boundaries.
TEST(ForegroundByHand, MarginIsTheLargerOfKSigmaSpreadAndMinMargin) {
  BackgroundModel background = uniform_background(kW, kH, 2.0F, 0.0F);
  const float spread_of_column[kW] = {0.0F, 0.0F, 0.004F, 0.004F, 0.010F, 0.010F, 0.030F, 0.030F};
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) background.spread_m[static_cast<size_t>(v * kW + u)] = spread_of_column[u];
  }
  // clang-format off
  const std::vector<uint16_t> raw = {
      1979, 1979, 1979, 1979, 1979, 1979, 1979, 1979,   // 21 mm nearer: beyond 20, within 40 and 120
      1981, 1981, 1981, 1981, 1981, 1981, 1981, 1981,   // 19 mm nearer: within every margin
      1959, 1959, 1959, 1959, 1959, 1959, 1959, 1959,   // 41 mm: beyond 20 and 40, within 120
      1961, 1961, 1961, 1961, 1961, 1961, 1961, 1961,   // 39 mm: beyond 20 only
      1879, 1879, 1879, 1879, 1879, 1879, 1879, 1879,   // 121 mm: beyond every margin
      1881, 1881, 1881, 1881, 1881, 1881, 1881, 1881};  // 119 mm: beyond 20 and 40
  // clang-format on
  const Foreground fg = extract(frame_of(kW, kH, raw), background, no_speckle_removal());
  EXPECT_EQ(rows(fg.mask, kW), (std::vector<std::string>{"####....",  //
                                                         "........",  //
                                                         "######..",  //
                                                         "####....",  //
                                                         "########",  //
                                                         "######.."}));
  EXPECT_EQ(fg.points_camera.size(), 4U + 0U + 6U + 4U + 8U + 6U);
  EXPECT_EQ(fg.points_base.size(), 28U);
}

// "Nearer by more than the margin": exactly the margin is not foreground. Binary depth units
// (1/1024 m) and margins make the comparison exact in float: wall at 2 m, min_margin
// 1/64 m = 15.625 mm, k_sigma 4; columns 0-3 spread 0 (margin 15.625 mm, boundary 2 − 1/64 =
// 1.984375 m = raw 2032), columns 4-7 spread 1/128 m (margin 4/128 = 31.25 mm, boundary
// 1.96875 m = raw 2016).
TEST(ForegroundByHand, NearerByExactlyTheMarginIsNotForeground) {
  BackgroundModel background = uniform_background(kW, kH, 2.0F, 0.0F);
  for (int v = 0; v < kH; ++v) {
    for (int u = 4; u < kW; ++u) background.spread_m[static_cast<size_t>(v * kW + u)] = 1.0F / 128.0F;
  }
  std::vector<uint16_t> raw(kW * kH, 0);
  const uint16_t row_raw[4] = {2031, 2032, 2015, 2016};
  for (int v = 0; v < 4; ++v) {
    for (int u = 0; u < kW; ++u) raw[static_cast<size_t>(v * kW + u)] = row_raw[v];
  }
  ForegroundParams params = no_speckle_removal();
  params.min_margin_m = 1.0F / 64.0F;
  const Foreground fg =
      extract(frame_of(kW, kH, raw, 100.0F, 100.0F, 3.5F, 2.5F, 1.0F / 1024.0F), background, params);
  EXPECT_EQ(rows(fg.mask, kW), (std::vector<std::string>{"####....",  // 2031: 1 unit beyond 15.625 mm only
                                                         "........",  // 2032: exactly 15.625 mm nearer
                                                         "########",  // 2015: beyond 31.25 mm too
                                                         "####....",  // 2016: exactly 31.25 mm nearer
                                                         "........",  // raw 0
                                                         "........"}));
}

// With a baseline the margin follows the noise model at the pixel's own depth. fx 100 px,
// B 50 mm, s 0.08 px: σ_model(z) = z² · 0.08 / (100 · 0.05 m) = 0.016 z², k_sigma 4 → 0.064 z².
// Wall at 1.0645 m, spread 1 mm (4 mm), min_margin 20 mm, so the model's margin (≥ 62 mm here)
// decides:
//   z 0.990: margin 0.064 · 0.9801   = 62.7 mm, nearer by 74.5 mm → foreground
//   z 1.000: margin 0.064 · 1        = 64.0 mm, nearer by 64.5 mm → foreground
//   z 1.001: margin 0.064 · 1.002001 = 64.1 mm, nearer by 63.5 mm → not
//   z 1.030: margin 0.064 · 1.0609   = 67.9 mm, nearer by 34.5 mm → not
// (σ_model at the background's 1.0645 m would be 72.5 mm and exclude z 1.000 too.) Without a
// baseline the margin is max(4, 20) mm and all four are foreground.
TEST(ForegroundByHand, NoiseModelMarginAtThePixelDepth) {
  const BackgroundModel background = uniform_background(kW, kH, 1.0645F, 0.001F);
  std::vector<uint16_t> raw(kW * kH, 0);
  const uint16_t row_raw[4] = {990, 1000, 1001, 1030};
  for (int v = 0; v < 4; ++v) {
    for (int u = 0; u < kW; ++u) raw[static_cast<size_t>(v * kW + u)] = row_raw[v];
  }
  const Frame with_baseline = frame_of(kW, kH, raw, 100.0F, 100.0F, 3.5F, 2.5F, 0.001F, 50.0F);
  EXPECT_EQ(rows(extract(with_baseline, background, no_speckle_removal()).mask, kW),
            (std::vector<std::string>{"########", "########", "........", "........", "........", "........"}));
  const Frame without_baseline = frame_of(kW, kH, raw);
  EXPECT_EQ(rows(extract(without_baseline, background, no_speckle_removal()).mask, kW),
            (std::vector<std::string>{"########", "########", "########", "########", "........", "........"}));
}

// Unknown background and missing depth. Columns 0-3 were never valid while learning (mean 0:
// unknown); columns 4-7 are a wall at 2.000 m, spread 1 mm (margin max(4, 20) = 20 mm), column
// 4 unreliable (valid in 30 % of the frames) but filled from its neighbours, which the extractor
// treats like any known background. Default workspace: everywhere. Raw 0 is never foreground,
// whatever the background; any valid depth over unknown background is, even farther than the
// wall.
TEST(ForegroundByHand, UnknownBackgroundAndZeroDepth) {
  BackgroundModel background = uniform_background(kW, kH, 2.0F, 0.001F);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < 4; ++u) make_unknown(background, u, v);
    background.valid_ratio[static_cast<size_t>(v * kW + 4)] = 0.3F;
  }
  // clang-format off
  const std::vector<uint16_t> raw = {
      2500, 2500, 2500, 2500, 2500, 2500, 2500, 2500,   // farther than the wall
         0,    0,    0,    0,    0,    0,    0,    0,   // no depth
      1500, 1500, 1500, 1500, 1500, 1500, 1500, 1500,   // 0.5 m nearer
      2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000,   // on the wall
         0, 1500,    0, 1500,    0, 1500,    0, 1500,
      1979, 1981,    0, 2000, 1979, 1981,    0, 2000};  // 21 and 19 mm nearer than the wall
  // clang-format on
  const Foreground fg = extract(frame_of(kW, kH, raw), background, no_speckle_removal());
  EXPECT_EQ(rows(fg.mask, kW), (std::vector<std::string>{"####....",  //
                                                         "........",  //
                                                         "########",  //
                                                         "####....",  //
                                                         ".#.#.#.#",  //
                                                         "##.##..."}));
  // One point per foreground pixel, each at its pixel's (non-zero) depth.
  ASSERT_EQ(fg.points_camera.size(), 4U + 0U + 8U + 4U + 4U + 4U);
  for (size_t i = 0; i < fg.points_camera.size(); ++i) {
    EXPECT_EQ(fg.points_camera.z[i], static_cast<float>(raw[fg.points_camera.pixel[i]]) * 0.001F);
  }
}

// The workspace box speaks for unknown background only, in the base frame. Every pixel's
// background is unknown except (7, 0), a wall at 2.5 m. fx = fy = 100 px, ppx 3.5, ppy 2.5,
// camera_facing_base_x(): p_base = (z − 1, −x, 1.5 − y). Depth 2.0 m except row 5 at 3.0 m:
//   rows 0-4: x = (u − 3.5) · 0.02, y = (v − 2.5) · 0.02, so base x = 1.0,
//             base y = 0.07, 0.05, 0.03, 0.01, −0.01, −0.03, −0.05, −0.07 for u = 0..7,
//             base z = 1.55, 1.53, 1.51, 1.49, 1.47 for v = 0..4;
//   row 5:    base x = 2.0.
// Box x ∈ [0.5, 1.5], y ∈ [−0.04, 1], z ∈ [1, 1.5]: rows 3-4 (z 1.49, 1.47), columns 0-5
// (y ≥ −0.03), not row 5 (x 2.0). Pixel (7, 0) lies outside the box (y −0.07, z 1.55) but is
// 0.5 m nearer than its known background: foreground. In the camera frame the box would hold
// no pixel (camera x ≤ 0.105 m < 0.5).
TEST(ForegroundByHand, WorkspaceBoxInTheBaseFrame) {
  BackgroundModel background = uniform_background(kW, kH, 2.5F, 0.001F);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      if (u != 7 || v != 0) make_unknown(background, u, v);
    }
  }
  std::vector<uint16_t> raw(kW * kH, 2000);
  for (int u = 0; u < kW; ++u) raw[static_cast<size_t>(5 * kW + u)] = 3000;
  const Frame frame = frame_of(kW, kH, raw);
  ForegroundParams params = no_speckle_removal();
  params.workspace_base.min = Eigen::Vector3f(0.5F, -0.04F, 1.0F);
  params.workspace_base.max = Eigen::Vector3f(1.5F, 1.0F, 1.5F);
  const Foreground fg = extract(frame, background, params, camera_facing_base_x());
  EXPECT_EQ(rows(fg.mask, kW), (std::vector<std::string>{".......#",  //
                                                         "........",  //
                                                         "........",  //
                                                         "######..",  //
                                                         "######..",  //
                                                         "........"}));
  ASSERT_EQ(fg.points_base.size(), 13U);
  // Raster order: (7, 0) first, at camera (0.07, −0.05, 2.0) → base (1.0, −0.07, 1.55); then
  // (0, 3) at camera (−0.07, 0.01, 2.0) → base (1.0, 0.07, 1.49); (5, 3) is the 7th point, at
  // camera (0.03, 0.01, 2.0) → base (1.0, −0.03, 1.49).
  const uint32_t pixels[3] = {7, 3 * kW + 0, 3 * kW + 5};
  const float base[3][3] = {{1.0F, -0.07F, 1.55F}, {1.0F, 0.07F, 1.49F}, {1.0F, -0.03F, 1.49F}};
  const size_t index[3] = {0, 1, 6};
  for (int k = 0; k < 3; ++k) {
    const size_t i = index[k];
    EXPECT_EQ(fg.points_base.pixel[i], pixels[k]);
    EXPECT_NEAR(fg.points_base.x[i], base[k][0], 1e-6);
    EXPECT_NEAR(fg.points_base.y[i], base[k][1], 1e-6);
    EXPECT_NEAR(fg.points_base.z[i], base[k][2], 1e-6);
  }

  // The default workspace (everywhere) keeps every pixel: the box was what excluded them.
  EXPECT_EQ(extract(frame, background, no_speckle_removal(), camera_facing_base_x()).points_base.size(),
            static_cast<size_t>(kW * kH));
}

// Speckle removal by physical size, the disc diameter 2 · sqrt(pixels / π) · mean z / fx, at
// min_object_mm 40, fx 100 px, on a 12x8 frame over a wall at 2 m (margin 20 mm, every
// blob is candidate). A 3x3 blob is 2 · sqrt(9 / π) = 3.38514 px across, so the boundary lies at
// z = 40 · 100 / 3.38514 = 1181.64 mm. (Recomputed by hand for the disc rule; under the old
// square rule, 3 · z / fx, the boundary was at 1333.3 mm and these depths were 1333 / 1334.)
//   A, 3x3 at 1.181 m: 3.38514 · 1181 / 100 = 39.978 mm → removed
//   B, 3x3 at 1.182 m: 3.38514 · 1182 / 100 = 40.012 mm → kept
//   C, 3x3, eight pixels at 1.178 m and its last one at 1.218 m (a 40 mm step, one blob): mean
//      (8 · 1178 + 1218) / 9 = 1182.44 mm → 40.027 mm → kept, although at 1.178 m alone it
//      would be 39.877 mm
//   D, one pixel at 0.5 m: 2 · sqrt(1 / π) · 500 / 100 = 5.64 mm → removed
TEST(ForegroundByHand, BlobsJustBelowMinObjectSizeAreRemovedJustAboveKept) {
  constexpr int w = 12;
  constexpr int h = 8;
  // clang-format off
  const std::vector<uint16_t> raw = {
      2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000,
      2000, 1181, 1181, 1181, 2000, 2000, 2000, 1182, 1182, 1182, 2000, 2000,
      2000, 1181, 1181, 1181, 2000, 2000, 2000, 1182, 1182, 1182, 2000, 2000,
      2000, 1181, 1181, 1181, 2000, 2000, 2000, 1182, 1182, 1182, 2000, 2000,
      2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000,
      2000, 1178, 1178, 1178, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000,
      2000, 1178, 1178, 1178, 2000, 2000, 2000, 2000, 2000, 2000,  500, 2000,
      2000, 1178, 1178, 1218, 2000, 2000, 2000, 2000, 2000, 2000, 2000, 2000};
  // clang-format on
  const Foreground fg =
      extract(frame_of(w, h, raw, 100.0F, 100.0F, 5.5F, 3.5F), uniform_background(w, h, 2.0F, 0.001F),
              speckle_removal_at(40.0F));
  EXPECT_EQ(rows(fg.mask, w), (std::vector<std::string>{"............",  //
                                                        ".......###..",  //
                                                        ".......###..",  //
                                                        ".......###..",  //
                                                        "............",  //
                                                        ".###........",  //
                                                        ".###........",  //
                                                        ".###........"}));
  EXPECT_EQ(fg.points_camera.size(), 18U);
}

// At the boundary itself (min_object_mm 40) one raw unit decides. Binary units: 1/1024 m per raw unit and fx
// 125 px, so a raw unit at the blob's depth is 1000 / 1024 / 125 = 1/128 mm per pixel; a 4x4
// blob is 2 · sqrt(16 / π) = 8 / sqrt(π) = 4.51352 px across, 4.51352 · raw / 128 mm: raw 1135
// (1.108 m) gives 40.022 mm (kept), raw 1134 gives 39.987 mm (removed). (Recomputed by hand for
// the disc rule: under the old square rule a 4x4 blob at raw 1280 was 40 mm exactly; a disc's
// diameter, with its factor 2 / sqrt(π), can never come out exactly 40 mm at an integer depth.)
TEST(ForegroundByHand, BlobOneRawUnitAboveMinObjectSizeIsKeptOneBelowRemoved) {
  const BackgroundModel background = uniform_background(kW, kH, 2.0F, 0.001F);
  for (const uint16_t blob_raw : {uint16_t{1135}, uint16_t{1134}}) {
    std::vector<uint16_t> raw(kW * kH, 2048);  // the wall, 2 m
    for (int v = 1; v < 5; ++v) {
      for (int u = 2; u < 6; ++u) raw[static_cast<size_t>(v * kW + u)] = blob_raw;
    }
    const Frame frame = frame_of(kW, kH, raw, 125.0F, 125.0F, 3.5F, 2.5F, 1.0F / 1024.0F);
    EXPECT_EQ(extract(frame, background, speckle_removal_at(40.0F)).points_camera.size(), blob_raw == 1135 ? 16U : 0U)
        << "raw " << blob_raw;
  }
}

// The disc rule on a disc: the 13 pixels within 2 px of a centre pixel (u² + v² ≤ 4: rows of
// 1, 3, 5, 3 and 1 pixels), the pixel picture of a 40 mm test piece seen 1 m away at fx 100 px
// (4 px across, π · 2² = 12.6 px). Its disc diameter is 2 · sqrt(13 / π) = 4.06843 px, so at
// min_object_mm 40 the boundary lies at z = 40 · 100 / 4.06843 = 983.18 mm:
//   at 1.000 m: 4.06843 · 1000 / 100 = 40.684 mm → kept (the old square rule, sqrt(13) · 10 =
//               36.06 mm, removed it: a 40 mm ball measured 35-36 mm)
//   at 0.984 m: 40.033 mm → kept
//   at 0.983 m: 39.993 mm → removed
// Wall at 2 m (margin 20 mm), 9x7 frame, the disc centred at (4, 3).
TEST(ForegroundByHand, DiscOfFortyMillimetresIsKeptJustSmallerRemoved) {
  constexpr int w = 9;
  constexpr int h = 7;
  const BackgroundModel background = uniform_background(w, h, 2.0F, 0.001F);
  for (const uint16_t disc_raw : {uint16_t{1000}, uint16_t{984}, uint16_t{983}}) {
    std::vector<uint16_t> raw(static_cast<size_t>(w * h), 2000);
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        if ((u - 4) * (u - 4) + (v - 3) * (v - 3) <= 4) raw[static_cast<size_t>(v * w + u)] = disc_raw;
      }
    }
    const Foreground fg = extract(frame_of(w, h, raw, 100.0F, 100.0F, 4.0F, 3.0F), background, speckle_removal_at(40.0F));
    const bool kept = disc_raw >= 984;
    EXPECT_EQ(rows(fg.mask, w), kept ? (std::vector<std::string>{".........",  //
                                                                  "....#....",  //
                                                                  "...###...",  //
                                                                  "..#####..",  //
                                                                  "...###...",  //
                                                                  "....#....",  //
                                                                  "........."})
                                     : (std::vector<std::string>(h, std::string(w, '.'))))
        << "disc at raw " << disc_raw;
    EXPECT_EQ(fg.points_camera.size(), kept ? 13U : 0U) << "disc at raw " << disc_raw;
  }
}

// Deprojection with fx 400, fy 500, ppx 3.2, ppy 2.7 and 0.1 mm depth units; two pixels in
// front of a wall at 2 m, the rest without depth:
//   (6, 1) at raw 12500 = 1.25 m: x = (6 − 3.2) / 400 · 1.25 = 0.00875,
//          y = (1 − 2.7) / 500 · 1.25 = −0.00425, pixel index 1 · 8 + 6 = 14;
//   (1, 4) at raw 8000 = 0.8 m:   x = (1 − 3.2) / 400 · 0.8 = −0.0044,
//          y = (4 − 2.7) / 500 · 0.8 = 0.00208, pixel index 4 · 8 + 1 = 33.
// In the base frame of camera_facing_base_x(), (z − 1, −x, 1.5 − y): (0.25, −0.00875, 1.50425)
// and (−0.2, 0.0044, 1.49792).
TEST(ForegroundByHand, DeprojectsPixelsWithKnownIntrinsics) {
  std::vector<uint16_t> raw(kW * kH, 0);
  raw[1 * kW + 6] = 12500;
  raw[4 * kW + 1] = 8000;
  const Frame frame = frame_of(kW, kH, raw, 400.0F, 500.0F, 3.2F, 2.7F, 0.0001F);
  const Foreground fg =
      extract(frame, uniform_background(kW, kH, 2.0F, 0.001F), no_speckle_removal(), camera_facing_base_x());
  ASSERT_EQ(fg.points_camera.size(), 2U);
  ASSERT_EQ(fg.points_base.size(), 2U);
  const float camera[2][3] = {{0.00875F, -0.00425F, 1.25F}, {-0.0044F, 0.00208F, 0.8F}};
  const float base[2][3] = {{0.25F, -0.00875F, 1.50425F}, {-0.2F, 0.0044F, 1.49792F}};
  const uint32_t pixels[2] = {14, 33};
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(fg.points_camera.pixel[i], pixels[i]);
    EXPECT_EQ(fg.points_base.pixel[i], pixels[i]);
    EXPECT_NEAR(fg.points_camera.x[i], camera[i][0], 1e-6) << "point " << i;
    EXPECT_NEAR(fg.points_camera.y[i], camera[i][1], 1e-6) << "point " << i;
    EXPECT_NEAR(fg.points_camera.z[i], camera[i][2], 1e-6) << "point " << i;
    EXPECT_NEAR(fg.points_base.x[i], base[i][0], 1e-6) << "point " << i;
    EXPECT_NEAR(fg.points_base.y[i], base[i][1], 1e-6) << "point " << i;
    EXPECT_NEAR(fg.points_base.z[i], base[i][2], 1e-6) << "point " << i;
  }
  EXPECT_EQ(rows(fg.mask, kW), (std::vector<std::string>{"........",  //
                                                         "......#.",  //
                                                         "........",  //
                                                         "........",  //
                                                         ".#......",  //
                                                         "........"}));
}

}  // namespace
}  // namespace hrcsense
