// SPDX-License-Identifier: Apache-2.0
// Tests of the simulated D435's sensor effects against the formulas of
// specs/d435-sensor-model.md, each on a scene built for it (docs/SIMULATOR.md).

#include "hrcsense/camera.hpp"
#include "hrcsense/sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hrcsense {
namespace {

Shape wall_shape(float z_m) {
  Shape s;
  s.type = Shape::Type::plane;
  s.point = {0, 0, z_m};
  s.normal = {0, 0, -1};
  return s;
}

Shape box_shape(const Eigen::Vector3f& min, const Eigen::Vector3f& max) {
  Shape s;
  s.type = Shape::Type::box;
  s.min = min;
  s.max = max;
  return s;
}

SceneObject object(const Shape& shape, bool is_static, Material material = {}) {
  SceneObject o;
  o.shapes = {shape};
  o.is_static = is_static;
  o.material = material;
  return o;
}

/// fx·B in pixel·metres for the default 848x480 camera.
double fxb(const Simulator& sim) { return sim.intrinsics().fx * static_cast<double>(sim.params.baseline_mm) * 1e-3; }

size_t at(const Frame& f, int u, int v) { return static_cast<size_t>(v) * f.depth.width + u; }

/// Noise-free disparity of pixel i from the truth (0 where nothing was hit).
double true_disparity(const Simulator& sim, const Frame& f, size_t i) {
  const float z = f.truth->depth_m[i];
  return z > 0.0F ? fxb(sim) / z : 0.0;
}

/// Whether pixel (u, v) has a 4-neighbour across a true-disparity step above the edge limit;
/// `far_side` receives whether the pixel is the farther of the pair with the largest step.
bool on_edge(const Simulator& sim, const Frame& f, int u, int v, bool* far_side) {
  const double d = true_disparity(sim, f, at(f, u, v));
  double best = sim.params.edge_jump_px;
  bool found = false;
  const int du[] = {-1, 1, 0, 0};
  const int dv[] = {0, 0, -1, 1};
  for (int k = 0; k < 4; ++k) {
    const int nu = u + du[k], nv = v + dv[k];
    if (nu < 0 || nv < 0 || nu >= f.depth.width || nv >= f.depth.height) continue;
    const double dn = true_disparity(sim, f, at(f, nu, nv));
    if (std::abs(dn - d) > best) {
      best = std::abs(dn - d);
      found = true;
      *far_side = dn > d;
    }
  }
  return found;
}

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

/// A 0.2 m box whose front face is 0.6 m from the camera, centred on the optical axis (so no
/// side face is visible), in front of a wall at 1.2 m.
Simulator shadow_scene(bool noise) {
  Simulator sim;
  sim.params.noise = noise;
  sim.params.seed = 9;
  sim.scene.objects.push_back(object(wall_shape(1.2F), true));
  sim.scene.objects.push_back(object(box_shape({-0.1F, -0.1F, 0.6F}, {0.1F, 0.1F, 0.7F}), false));
  return sim;
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
    EXPECT_NEAR(rows, sim.intrinsics().fy * 0.2 / 0.6, 2.0);  // the box's 70 rows
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

TEST(SimSensor, EdgeDropoutsAndFlyingPixelsAtTheSharesConfigured) {
  Simulator sim = shadow_scene(true);
  sim.params.disparity_noise_px = 0.0F;  // depths exact, so a flying pixel is unmistakable
  sim.params.disparity_step_px = 0.0F;
  sim.params.speckle = 0.0F;
  Frame f, g;
  sim.render(0, f);
  sim.render(1, g);
  size_t edge = 0, dropped = 0, far_kept = 0, far_flying = 0, near_moved = 0, changed = 0;
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < f.depth.width; ++u) {
      bool far_side = false;
      const size_t i = at(f, u, v);
      if (f.truth->depth_m[i] <= 0.0F || !on_edge(sim, f, u, v, &far_side)) continue;
      changed += f.depth.pixels[i] != g.depth.pixels[i] ? 1U : 0U;
      // Not the wall pixels in the band or the shadow (left of the box): those are 0 anyway.
      if (u < 60 || (far_side && f.truth->labels[at(f, u + 1, v)] == 1)) continue;
      ++edge;
      const uint16_t raw = f.depth.pixels[i];
      if (raw == 0) {
        ++dropped;
        continue;
      }
      const double error_m = std::abs(raw * 1e-3 - f.truth->depth_m[i]);
      if (far_side) {
        ++far_kept;
        far_flying += error_m > 0.002 ? 1U : 0U;
      } else {
        near_moved += error_m > 0.001 ? 1U : 0U;
      }
    }
  }
  ASSERT_GT(edge, 500U);
  ASSERT_GT(far_kept, 100U);
  EXPECT_NEAR(static_cast<double>(dropped) / static_cast<double>(edge), sim.params.edge_dropout, 0.05);
  EXPECT_NEAR(static_cast<double>(far_flying) / static_cast<double>(far_kept), sim.params.flying_pixels, 0.06);
  EXPECT_EQ(near_moved, 0U) << "the near side of an edge keeps its depth";
  EXPECT_EQ(changed, 0U) << "a still scene has still holes and flying pixels";
}

TEST(SimSensor, MaterialsDropOutInPatchesAtTheirRates) {
  struct Case {
    Material material;
    float rate;
  };
  Simulator sim;
  const Case cases[] = {{Material{true, false, false}, sim.params.dark_dropout},
                        {Material{false, true, false}, sim.params.shiny_dropout},
                        {Material{false, false, true}, sim.params.low_texture_dropout},
                        {Material{}, 0.0F}};
  for (const Case& c : cases) {
    sim.scene.objects = {object(wall_shape(2.0F), true),
                         object(box_shape({-0.2F, -0.2F, 1.0F}, {0.2F, 0.2F, 1.1F}), false, c.material)};
    Frame f;
    sim.render(0, f);
    size_t pixels = 0, zeros = 0;
    // The box's interior, 3 px inside its edges (no edge effects there).
    for (int v = 0; v < f.depth.height; ++v) {
      for (int u = 0; u < f.depth.width; ++u) {
        bool interior = true;
        for (int k = -3; k <= 3 && interior; ++k) {
          interior = u + k >= 0 && u + k < f.depth.width && v + k >= 0 && v + k < f.depth.height &&
                     f.truth->labels[at(f, u + k, v)] == 1 && f.truth->labels[at(f, u, v + k)] == 1;
        }
        if (!interior) continue;
        ++pixels;
        zeros += f.depth.pixels[at(f, u, v)] == 0 ? 1U : 0U;
      }
    }
    ASSERT_GT(pixels, 20000U);  // 167 px square
    const double share = static_cast<double>(zeros) / static_cast<double>(pixels);
    // ~1700 independent 4x4 patches: the share's standard error is ≤ 1.3 %.
    EXPECT_NEAR(share, c.rate + (1.0F - c.rate) * sim.params.speckle, 0.05) << "rate " << c.rate;
  }
}

TEST(SimSensor, SpeckleIsRareAndNewEveryFrame) {
  Simulator sim;
  sim.scene.objects.push_back(object(wall_shape(1.0F), true));
  Frame f, g;
  sim.render(10, f);
  sim.render(11, g);
  size_t zeros = 0, both = 0, pixels = 0;
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 30; u < f.depth.width; ++u) {  // beyond the 21 px band
      const bool zf = f.depth.at(u, v) == 0, zg = g.depth.at(u, v) == 0;
      zeros += zf ? 1U : 0U;
      both += zf && zg ? 1U : 0U;
      ++pixels;
    }
  }
  // 0.2 % of ~393k pixels: 786 expected, standard deviation 28.
  EXPECT_NEAR(static_cast<double>(zeros) / static_cast<double>(pixels), sim.params.speckle, 0.0004);
  EXPECT_LT(both, 10U) << "speckle is drawn anew each frame";
}

TEST(SimSensor, CorrelatedNoiseIsSmoothFixedAndOfTheConfiguredSize) {
  Simulator sim;
  sim.params.disparity_noise_px = 0.0F;
  sim.params.disparity_step_px = 0.0F;
  sim.params.speckle = 0.0F;
  sim.params.correlated_noise_px = 0.1F;
  sim.scene.objects.push_back(object(wall_shape(2.0F), true));
  Frame f, g;
  sim.render(0, f);
  sim.render(7, g);
  EXPECT_EQ(f.depth.pixels, g.depth.pixels) << "fixed per seed, not per frame";
  const double d0 = fxb(sim) / 2.0;
  double sum = 0.0, sum_sq = 0.0, sum_step_sq = 0.0;
  size_t n = 0;
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 20; u + 1 < f.depth.width; ++u) {
      // Disparity error from the depth; 1 mm rounding at 2 m is 0.005 px.
      const double e = fxb(sim) / (f.depth.at(u, v) * 1e-3) - d0;
      const double e_next = fxb(sim) / (f.depth.at(u + 1, v) * 1e-3) - d0;
      sum += e;
      sum_sq += e * e;
      sum_step_sq += (e_next - e) * (e_next - e);
      ++n;
    }
  }
  const double mean = sum / static_cast<double>(n);
  const double sigma = std::sqrt(sum_sq / static_cast<double>(n) - mean * mean);
  EXPECT_NEAR(sigma, 0.1, 0.03);  // ~400 grid nodes: a sample, not the expectation
  EXPECT_LT(std::abs(mean), 0.03);
  // Smooth: neighbours differ by far less than the field itself varies.
  EXPECT_LT(std::sqrt(sum_step_sq / static_cast<double>(n)), 0.2 * sigma);
}

TEST(SimSensor, NoNoiseLeavesOnlyTheGeometricHoles) {
  Simulator sim = shadow_scene(false);
  Material dark;
  dark.dark = true;
  sim.scene.objects[1].material = dark;
  Frame f;
  sim.render(0, f);
  for (size_t i = 0; i < f.depth.pixels.size(); ++i) {
    if (f.depth.pixels[i] == 0) continue;
    ASSERT_EQ(f.depth.pixels[i], static_cast<uint16_t>(std::lround(f.truth->depth_m[i] * 1e3))) << i;
  }
  size_t box_valid = 0;
  for (size_t i = 0; i < f.depth.pixels.size(); ++i) box_valid += f.truth->labels[i] == 1 && f.depth.pixels[i] != 0;
  EXPECT_EQ(box_valid, std::count(f.truth->labels.begin(), f.truth->labels.end(), 1)) << "no material dropouts";
}

TEST(SimSensor, SameSeedGivesBitIdenticalFramesWithEveryEffect) {
  Simulator a = shadow_scene(true);
  a.params.seed = 77;
  a.params.correlated_noise_px = 0.03F;
  Material shiny;
  shiny.shiny = true;
  a.scene.objects[1].material = shiny;
  Simulator b = a;
  Frame fa, fb;
  a.render(12, fa);
  b.render(3, fb);  // a copy with another history
  b.render(12, fb);
  EXPECT_EQ(fa.depth.pixels, fb.depth.pixels);
  Simulator c = a;
  c.params.seed = 78;
  c.render(12, fb);
  EXPECT_NE(fa.depth.pixels, fb.depth.pixels);
}

}  // namespace
}  // namespace hrcsense
