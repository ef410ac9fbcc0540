// SPDX-License-Identifier: Apache-2.0
// Tests of the simulated structured-light camera (`sim.sensor: structured_light`,
// docs/SIMULATOR.md "Sensor models") against numbers worked out by hand: fx = 570 px at 640x480,
// B = 75 mm, so fx·B = 42.75 px·m, and disparity steps of 1/8 px.

#include "sim_sensor_scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

namespace hrcsense {
namespace {

using namespace sim_test;

/// The structured-light preset with `seed`, depth only.
Simulator structured_light(uint64_t seed = 3) {
  Simulator sim;
  apply_sim_sensor(SimSensor::structured_light, sim.params);
  sim.params.seed = seed;
  sim.params.color = false;
  return sim;
}

/// The plane z = z0 + slope·x: its depth runs from z0/(1 + slope·|X|) to z0/(1 − slope·|X|)
/// across the image (X = x/z of the ray), so it covers a band of depths around z0.
Shape slanted_wall(float z0_m, float slope) { return Shape::plane({0, 0, z0_m}, {slope, 0, -1}); }

/// The raw values of frame 0 whose true depth is within `band_m` of z_m, sorted and distinct.
std::vector<int> values_near(const Simulator& sim, float z_m, float band_m) {
  Frame f;
  sim.render(0, f);
  std::set<int> seen;
  for (size_t i = 0; i < f.depth.pixels.size(); ++i) {
    if (f.depth.pixels[i] != 0 && std::abs(f.truth->depth_m[i] - z_m) < band_m) seen.insert(f.depth.pixels[i]);
  }
  return {seen.begin(), seen.end()};
}

bool contains(const std::vector<int>& values, int value) {
  return std::find(values.begin(), values.end(), value) != values.end();
}

size_t valid_pixels(const Frame& f) {
  return static_cast<size_t>(std::count_if(f.depth.pixels.begin(), f.depth.pixels.end(), [](uint16_t r) { return r != 0; }));
}

TEST(StructuredLight, DepthStepIsZSquaredTimesAnEighthPixelOverFxB) {
  // Noise-free (σ = 0): the depth is fx·B / d with d a whole number of 1/8 px. By hand, with
  // fx·B = 570 · 0.075 = 42.75 px·m:
  //   1 m: d = 42.75 px = 342/8; 341/8 → 42.75/42.625 = 1.00293 m → 1003 mm, 343/8 → 0.99708 m
  //        → 997 mm. Δz = z²·(1/8)/(fx·B) = 0.125/42.75 = 2.92 mm.
  //   3 m: d = 14.25 px = 114/8; 113/8 → 42.75/14.125 = 3.02655 m → 3027 mm, 115/8 → 2.97391 m
  //        → 2974 mm. Δz = 9 · 0.125/42.75 = 26.3 mm.
  Simulator sim = structured_light();
  sim.params.disparity_noise_px = 0.0F;
  sim.params.speckle = 0.0F;
  sim.params.range_dropout = 0.0F;
  struct Case {
    float z_m;
    int below_mm, at_mm, above_mm;
    double step_mm;
  };
  for (const Case c : {Case{1.0F, 997, 1000, 1003, 2.92}, Case{3.0F, 2974, 3000, 3027, 26.3}}) {
    sim.scene.objects = {object(slanted_wall(c.z_m, 0.2F), true)};
    const std::vector<int> values = values_near(sim, c.z_m, 0.02F * c.z_m);
    ASSERT_GT(values.size(), 4U) << c.z_m;
    // The three steps around z0 are there, and nothing between them.
    EXPECT_TRUE(contains(values, c.below_mm) && contains(values, c.at_mm) && contains(values, c.above_mm)) << c.z_m;
    for (const int v : values) {
      EXPECT_FALSE(v > c.below_mm && v < c.at_mm) << v << " between the steps at " << c.z_m << " m";
      EXPECT_FALSE(v > c.at_mm && v < c.above_mm) << v << " between the steps at " << c.z_m << " m";
    }
    // Every value is a whole number of 1/8 px, and successive values are one step apart.
    double gaps_mm = 0.0;
    for (size_t k = 0; k < values.size(); ++k) {
      const double eighths = 8.0 * 42.75 / (values[k] * 1e-3);
      EXPECT_NEAR(eighths, std::round(eighths), 8.0 * 42.75 * 0.5e-3 / (values[k] * 1e-3 * values[k] * 1e-3) + 1e-3)
          << values[k] << " mm is no whole number of 1/8 px";
      if (k > 0) gaps_mm += values[k] - values[k - 1];
    }
    EXPECT_NEAR(gaps_mm / static_cast<double>(values.size() - 1), c.step_mm, 0.1 * c.step_mm) << c.z_m;
  }
}

TEST(StructuredLight, NoLeftBandMillimetreUnitsAndItsOwnIntrinsics) {
  Simulator sim = structured_light();
  sim.params.noise = false;
  sim.scene.objects = {object(wall_shape(1.0F), true)};
  Frame f;
  sim.render(0, f);
  ASSERT_EQ(f.depth.width, 640);
  ASSERT_EQ(f.depth.height, 480);
  // Every pixel, the first columns too (a D435 would miss its first fx·B/Z = 21 columns).
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < f.depth.width; ++u) ASSERT_EQ(f.depth.at(u, v), 1000) << u << "," << v;
  }
  EXPECT_FLOAT_EQ(f.depth.depth_scale_m, 0.001F);
  EXPECT_FLOAT_EQ(f.stereo_baseline_mm, 75.0F);
  EXPECT_FLOAT_EQ(f.intrinsics.fx, 570.0F);
  EXPECT_FLOAT_EQ(f.intrinsics.ppx, 319.5F);
  // With the full model the first columns are as full as the rest (speckle 0.1 % apart).
  sim.params.noise = true;
  sim.render(0, f);
  size_t valid = 0;
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < 40; ++u) valid += f.depth.at(u, v) != 0 ? 1U : 0U;
  }
  EXPECT_GT(static_cast<double>(valid) / (40.0 * f.depth.height), 0.995);
}

TEST(StructuredLight, NothingValidNearerThanHalfAMetreOrBeyondFourAndAHalf) {
  Simulator sim = structured_light();
  Frame f;
  // Walls just outside the range have no depth at all, walls just inside have depth.
  for (const float z_m : {0.48F, 4.6F}) {
    sim.scene.objects = {object(wall_shape(z_m), true)};
    sim.render(0, f);
    EXPECT_EQ(valid_pixels(f), 0U) << z_m;
  }
  for (const float z_m : {0.52F, 4.4F}) {
    sim.scene.objects = {object(wall_shape(z_m), true)};
    sim.render(0, f);
    EXPECT_GT(valid_pixels(f), f.depth.pixels.size() / 2) << z_m;
  }
  // A slope seen from 0.435 m (top row) to 5 m (bottom row): y = 0.5·z − 0.4, so on the row
  // with y/z = Y = (v − 239.5) / 570 (±0.42) the depth is z = 0.4 / (0.5 − Y).
  // every value read lies in [500, 4500] mm, over several frames of noise.
  sim.scene.objects = {object(Shape::plane({0, 0.1F, 1.0F}, {0, -1, 0.5F}), true)};
  int min_mm = 65535, max_mm = 0;
  for (int64_t i = 0; i < 5; ++i) {
    sim.render(i, f);
    for (const uint16_t raw : f.depth.pixels) {
      if (raw == 0) continue;
      min_mm = std::min<int>(min_mm, raw);
      max_mm = std::max<int>(max_mm, raw);
    }
  }
  EXPECT_GE(min_mm, 500);
  EXPECT_LT(min_mm, 520);  // the floor does reach the near limit
  EXPECT_LE(max_mm, 4500);
  EXPECT_GT(max_mm, 4300);  // and the far one
}

TEST(StructuredLight, RangeDropoutsGrowTowardsTheFarEndAndComeAndGo) {
  Simulator sim = structured_light();
  sim.params.speckle = 0.0F;
  // Missing share 0.3 · ((z − 3) / 1.5)² from 3 m: 0 at 2 m, 0.3 · 0.16 = 0.048 at 3.6 m,
  // 0.3 · 0.751 = 0.225 at 4.3 m.
  struct Case {
    float z_m;
    double missing, tolerance;
  };
  for (const Case c : {Case{2.0F, 0.0, 0.001}, Case{3.6F, 0.048, 0.01}, Case{4.3F, 0.225, 0.02}}) {
    sim.scene.objects = {object(wall_shape(c.z_m), true)};
    Frame f, g;
    sim.render(0, f);
    sim.render(1, g);
    const double n = static_cast<double>(f.depth.pixels.size());
    size_t both = 0;
    for (size_t i = 0; i < f.depth.pixels.size(); ++i) both += f.depth.pixels[i] == 0 && g.depth.pixels[i] == 0 ? 1U : 0U;
    EXPECT_NEAR(1.0 - static_cast<double>(valid_pixels(f)) / n, c.missing, c.tolerance) << c.z_m;
    // Drawn anew every frame: a pixel missing in one frame is missing in the next at the
    // share's rate (0.225² = 0.05 at 4.3 m), not always.
    EXPECT_LE(static_cast<double>(both) / n, c.missing * c.missing + c.tolerance) << c.z_m;
  }
}

/// Per pixel of `f`: 1 where it lies on a depth edge (sim_test::on_edge), else 0.
std::vector<uint8_t> edge_mask(const Simulator& sim, const Frame& f) {
  std::vector<uint8_t> mask(f.depth.pixels.size(), 0);
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < f.depth.width; ++u) {
      bool far_side = false;
      mask[at(f, u, v)] = on_edge(sim, f, u, v, &far_side) ? 1 : 0;
    }
  }
  return mask;
}

/// 20 frames of a 0.3 m box whose front face is 1 m away, before a slanted wall 1.8–2.25 m
/// away (z = 2 / (1 − 0.2·X), X = (u − 319.5) / 570), with frame 0's edge pixels.
struct BoxBeforeWall {
  static constexpr int kFrames = 20;
  Simulator sim = structured_light();
  std::vector<Frame> frames;
  std::vector<uint8_t> edges;

  BoxBeforeWall() : frames(kFrames) {
    sim.params.speckle = 0.0F;
    sim.scene.objects = {object(slanted_wall(2.0F, 0.2F), true),
                         object(Shape::box({-0.15F, -0.15F, 1.0F}, {0.15F, 0.15F, 1.2F}), true)};
    for (int k = 0; k < kFrames; ++k) sim.render(k, frames[static_cast<size_t>(k)]);
    edges = edge_mask(sim, frames[0]);
  }
  int width() const { return frames[0].depth.width; }
  int height() const { return frames[0].depth.height; }
  /// No depth in any frame: the projector's shadow left of the box.
  bool shadow(size_t i) const {
    return std::all_of(frames.begin(), frames.end(), [i](const Frame& f) { return f.depth.pixels[i] == 0; });
  }
  /// No edge within two pixels of (u, v), which lies at least two pixels inside the image.
  bool interior(int u, int v) const {
    for (int dv = -2; dv <= 2; ++dv) {
      for (int du = -2; du <= 2; ++du) {
        if (edges[at(frames[0], u + du, v + dv)] != 0) return false;
      }
    }
    return true;
  }
};

TEST(StructuredLight, EdgePixelsFlickerBetweenTheNearAndTheFarDepth) {
  const BoxBeforeWall scene;
  size_t edge = 0, edge_both = 0, samples = 0, near_samples = 0, far_samples = 0, none_samples = 0;
  for (int v = 0; v < scene.height(); ++v) {
    for (int u = 0; u < scene.width(); ++u) {
      const size_t i = at(scene.frames[0], u, v);
      if (scene.edges[i] == 0 || scene.shadow(i)) continue;
      // The two sides by hand: the box's face at 1000 mm, the wall's depth at this column (a
      // pixel's neighbour across the edge is within 1.4 mm of it). A step at 2.25 m is 14.8 mm
      // and the noise adds a few more; 1 m and 2 m are far apart.
      const double wall_mm = 2000.0 / (1.0 - 0.2 * (u - 319.5) / 570.0);
      int near_seen = 0, far_seen = 0;
      for (const Frame& f : scene.frames) {
        const int raw = f.depth.pixels[i];
        const bool near = std::abs(raw - 1000) <= 15;
        const bool far = std::abs(raw - wall_mm) <= 60.0;
        EXPECT_TRUE(raw == 0 || near || far) << raw << " mm at an edge is on neither side, pixel " << u << "," << v;
        near_seen += near ? 1 : 0;
        far_seen += far ? 1 : 0;
        none_samples += raw == 0 ? 1U : 0U;
        ++samples;
      }
      near_samples += static_cast<size_t>(near_seen);
      far_samples += static_cast<size_t>(far_seen);
      ++edge;
      edge_both += near_seen > 0 && far_seen > 0 ? 1U : 0U;
    }
  }
  ASSERT_GT(edge, 1000U);
  // Each frame one in five edge pixels has no depth and the rest toss a coin between the sides:
  // 0.2 none, 0.4 near, 0.4 far.
  const auto share = [samples](size_t n) { return static_cast<double>(n) / static_cast<double>(samples); };
  EXPECT_NEAR(share(none_samples), 0.2, 0.03);
  EXPECT_NEAR(share(near_samples), 0.4, 0.04);
  EXPECT_NEAR(share(far_samples), 0.4, 0.04);
  // Over 20 frames nearly every edge pixel shows both depths (never the near one: 0.6^20 ≈ 4e-5).
  EXPECT_GT(static_cast<double>(edge_both) / static_cast<double>(edge), 0.99);
}

TEST(StructuredLight, InteriorPixelsOfStillSurfacesMoveOnlyByTheNoise) {
  const BoxBeforeWall scene;
  size_t interior = 0, wide = 0, samples = 0;
  double square_px = 0.0;
  for (int v = 2; v + 2 < scene.height(); ++v) {
    for (int u = 2; u + 2 < scene.width(); ++u) {
      const size_t i = at(scene.frames[0], u, v);
      if (!scene.interior(u, v) || scene.shadow(i)) continue;
      // Measured in disparity, where steps and noise are the same at every depth.
      const double d_true = 42.75 / scene.frames[0].truth->depth_m[i];
      double d_min = 1e9, d_max = 0.0;
      for (const Frame& f : scene.frames) {
        const int raw = f.depth.pixels[i];
        if (raw == 0) continue;
        const double d = 42.75 / (raw * 1e-3);
        d_min = std::min(d_min, d);
        d_max = std::max(d_max, d);
        square_px += (d - d_true) * (d - d_true);
        ++samples;
      }
      ++interior;
      // σ 0.06 px and 1/8 px steps: 20 draws span about 0.22 px, two or three steps, and now and
      // then four (±2 steps needs |g| > 3.1 twice); five (0.625 px, a span of over 8 σ) never.
      // The 1 mm rounding of the output moves a disparity by at most 0.02 px at either end.
      wide += d_max - d_min > 4 * 0.125 + 0.05 ? 1U : 0U;
    }
  }
  ASSERT_GT(interior, 100000U);
  EXPECT_EQ(wide, 0U);
  // RMS error in disparity: √(0.06² + 0.125²/12) = 0.070 px by hand (noise plus rounding).
  EXPECT_NEAR(std::sqrt(square_px / static_cast<double>(samples)), 0.070, 0.01);
}

TEST(StructuredLight, DarkAndShinySurfacesLoseThePatternLowTextureDoesNot) {
  Simulator sim = structured_light();
  sim.params.speckle = 0.0F;
  struct Case {
    Material material;
    double missing;
  };
  // Patches of 8x8 pixels: 4800 of them in the image, so a share is known to about ±0.01.
  for (const Case c : {Case{{true, false, false}, 0.7}, Case{{false, true, false}, 0.5}, Case{{false, false, true}, 0.0}}) {
    sim.scene.objects = {object(wall_shape(1.5F), true, c.material)};
    Frame f;
    sim.render(0, f);
    EXPECT_NEAR(1.0 - static_cast<double>(valid_pixels(f)) / static_cast<double>(f.depth.pixels.size()), c.missing,
                0.03);
  }
}

}  // namespace
}  // namespace hrcsense
