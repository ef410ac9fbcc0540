// SPDX-License-Identifier: Apache-2.0
// Tests of the simulated D435's sensor effects against the formulas of
// specs/d435-sensor-model.md, each on a scene built for it (docs/SIMULATOR.md), and that each
// effect's switch removes it: the geometry (left band, occlusion shadows, minimum range, depth noise).

#include "sim_sensor_scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hrcsense {
namespace {

using namespace sim_test;

TEST(SimSensor, LeftBandIsFxBOverZColumnsWide) {
  for (const float z_m : {0.5F, 1.0F, 2.0F}) {
    Simulator sim;  // the full model, noise and all
    sim.params.seed = 5;
    sim.scene.objects.push_back(object(wall_shape(z_m), true));
    Frame f;
    sim.render(0, f);
    const double expected_px = fxb(sim) / z_m;  // 41.7, 20.9, 10.4 px
    // The band: the leading columns invalid in every row (speckle elsewhere is isolated).
    int band = 0;
    for (bool all_zero = true; all_zero && band < f.depth.width; band += all_zero ? 1 : 0) {
      for (int v = 0; v < f.depth.height && all_zero; ++v) all_zero = f.depth.at(band, v) == 0;
    }
    EXPECT_NEAR(band, expected_px, 1.0) << "wall at " << z_m << " m";
    size_t valid_after_band = 0, after_band = 0;
    for (int v = 0; v < f.depth.height; ++v) {
      for (int u = band; u < f.depth.width; ++u) {
        valid_after_band += f.depth.at(u, v) != 0 ? 1U : 0U;
        ++after_band;
      }
    }
    // Beyond the band only speckle (0.2 %) is missing.
    EXPECT_GT(static_cast<double>(valid_after_band) / static_cast<double>(after_band), 0.995) << z_m;
  }
}

TEST(SimSensor, OcclusionShadowIsLeftOfTheBoxAndFxBDeltaInverseZWide) {
  for (const bool noise : {false, true}) {
    const Simulator sim = shadow_scene(noise);
    Frame f;
    sim.render(0, f);
    const double expected_px = fxb(sim) * (1.0 / 0.6 - 1.0 / 1.2);  // 17.4 px
    int rows = 0;
    for (int v = 0; v < f.depth.height; ++v) {
      int first = -1, last = -1;
      for (int u = 0; u < f.depth.width; ++u) {
        if (f.truth->labels[at(f, u, v)] == 0) continue;
        if (first < 0) first = u;
        last = u;
      }
      if (first < 0) continue;
      ++rows;
      int left = 0;
      while (f.depth.at(first - 1 - left, v) == 0) ++left;
      int right = 0;
      while (f.depth.at(last + 1 + right, v) == 0) ++right;
      EXPECT_NEAR(left, expected_px, 2.0) << "row " << v << (noise ? " (noise)" : "");
      // Right of the box the wall is seen by both imagers: at most the one edge pixel drops.
      EXPECT_LE(right, noise ? 1 : 0) << "row " << v;
    }
    EXPECT_NEAR(rows, sim.intrinsics().fy * 0.2 / 0.6, 2.0);  // the box's 139 rows
  }
}

TEST(SimSensor, OcclusionShadowsSwitchOff) {
  // Right of the wall's 17-column left band, only the shadow has no depth.
  const auto hole = [](const Frame& f, int u, int v) { return u >= 30 && no_depth(f, u, v); };
  for (const bool noise : {false, true}) {
    Simulator sim = geometric_holes_only(shadow_scene(noise));
    // By hand: the box's left edge projects to u = 424.158 − 418.265·0.1/0.6 = 354.45 on its
    // rows 169–307 (v = 238.24 ± 69.71). Its first pixel, 355, meets the right image at
    // 355 − 34.76 = 320.24, so wall pixels with u − 17.38 > 320.24 (u = 338–354) are hidden.
    EXPECT_EQ(count_pixels(sim, hole), 17U * 139U) << (noise ? "noise" : "no noise");
    sim.params.occlusion_shadows = false;
    EXPECT_EQ(count_pixels(sim, hole), 0U) << (noise ? "noise" : "no noise");
  }
}

TEST(SimSensor, NothingNearerThanTheMinimumRange) {
  Simulator sim;
  const double min_m = fxb(sim) / 110.0;  // 0.190 m at 848x480
  // A floor-like plane sloping from 0.1 m (bottom rows) to far away (top rows).
  Shape slope;
  slope.type = Shape::Type::plane;
  slope.point = {0, 0.05F, 0.1F};
  slope.normal = Eigen::Vector3f(0, -1, -0.4F).normalized();
  sim.scene.objects.push_back(object(slope, true));
  for (const float override_m : {0.0F, 0.3F}) {
    sim.params.min_range_m = override_m;
    const double limit_m = override_m > 0.0F ? override_m : min_m;
    Frame f;
    sim.render(0, f);
    size_t near = 0, beyond = 0, beyond_valid = 0;
    for (int v = 0; v < f.depth.height; ++v) {
      for (int u = 60; u < f.depth.width; ++u) {  // right of the left band (≤ 60 px beyond 0.35 m)
        const size_t i = at(f, u, v);
        const double z = f.truth->depth_m[i];
        if (z <= 0.0 || z > 3.0) continue;
        if (z < limit_m * 0.999) {
          ASSERT_EQ(f.depth.pixels[i], 0) << "z " << z << " at " << u << "," << v;
          ++near;
        } else if (z > limit_m * 1.001 && z > 0.35) {
          ++beyond;
          beyond_valid += f.depth.pixels[i] != 0 ? 1U : 0U;
        }
      }
    }
    EXPECT_GT(near, 1000U) << override_m;
    EXPECT_GT(static_cast<double>(beyond_valid) / static_cast<double>(beyond), 0.99) << override_m;
  }
  EXPECT_NEAR(min_m, 0.1896, 5e-4);
}

TEST(SimSensor, MaxDisparityZeroSwitchesTheMinimumRangeOff) {
  // Right of the wall's left band (20.86 / 0.15 = 139 columns).
  const auto hole = [](const Frame& f, int u, int v) { return u >= 150 && no_depth(f, u, v); };
  for (const bool noise : {false, true}) {
    Simulator sim = geometric_holes_only(Simulator{});
    sim.params.noise = noise;
    sim.scene.objects.push_back(object(wall_shape(0.15F), true));  // nearer than fx·B/110 = 0.190 m
    EXPECT_EQ(count_pixels(sim, hole), (848U - 150U) * 480U) << (noise ? "noise" : "no noise");
    sim.params.max_disparity_px = 0.0F;  // min_range_m stays 0: no minimum range at all
    EXPECT_EQ(count_pixels(sim, hole), 0U) << (noise ? "noise" : "no noise");
  }
}

TEST(SimSensor, DepthNoiseOnAWallFollowsTheStereoModel) {
  for (const float z_m : {1.0F, 2.0F, 3.0F}) {
    Simulator sim;
    sim.params.seed = 17;
    sim.scene.objects.push_back(object(wall_shape(z_m), true));
    double sum = 0.0, sum_sq = 0.0;
    size_t n = 0;
    Frame f;
    for (const int64_t index : {3, 4}) {
      sim.render(index, f);
      for (const uint16_t raw : f.depth.pixels) {
        if (raw == 0) continue;
        const double z = raw * 1e-3;
        sum += z;
        sum_sq += z * z;
        ++n;
      }
    }
    const double mean = sum / static_cast<double>(n);
    const double sigma = std::sqrt(sum_sq / static_cast<double>(n) - mean * mean);
    const double expected = stereo_depth_sigma_m(z_m, f.intrinsics.fx, sim.params.baseline_mm, 0.08);
    EXPECT_NEAR(sigma, expected, 0.15 * expected) << "wall at " << z_m << " m";  // 3.8, 15.3, 34.5 mm
    if (z_m == 1.0F) {
      EXPECT_NEAR(mean, 1.0, 1e-3);
    }
  }
}

}  // namespace
}  // namespace hrcsense
