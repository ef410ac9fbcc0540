// SPDX-License-Identifier: Apache-2.0
// Tests of the simulated D435's sensor effects against the formulas of
// specs/d435-sensor-model.md, each on a scene built for it (docs/SIMULATOR.md), and that each
// effect's switch removes it: the holes and outliers (edges, flying pixels, materials, speckle, correlated noise) and determinism.

#include "sim_sensor_scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hrcsense {
namespace {

using namespace sim_test;

/// The shadow scene with exact depths (no disparity noise or quantisation, so that a flying
/// pixel is unmistakable) and no speckle: beside the box every artefact is an edge effect.
Simulator exact_edge_scene() {
  Simulator sim = shadow_scene(true);
  sim.params.disparity_noise_px = 0.0F;
  sim.params.disparity_step_px = 0.0F;
  sim.params.speckle = 0.0F;
  return sim;
}

TEST(SimSensor, EdgeDropoutsAndFlyingPixelsAtTheSharesConfigured) {
  const Simulator sim = exact_edge_scene();
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

TEST(SimSensor, EdgeDropoutAndFlyingPixelsOfZeroSwitchThemOff) {
  // The box's rim without depth (the near side only drops out) and the wall's pixels beside the
  // box more than 2 mm off the truth (the far side flies); left of the box the wall is shadowed.
  const auto dropped = [](const Frame& f, int u, int v) { return on_rim(f, u, v, 1, 0) && no_depth(f, u, v); };
  const auto flying = [](const Frame& f, int u, int v) {
    const size_t i = at(f, u, v);
    const double error_m = std::abs(f.depth.pixels[i] * 1e-3 - f.truth->depth_m[i]);
    return on_rim(f, u, v, 0, 1) && !no_depth(f, u, v) && error_m > 0.002;
  };
  Simulator sim = exact_edge_scene();
  // By hand: the box covers 139 × 139 pixels (u 355–493, v 169–307), a rim of 552, 25 % of it
  // dropped: 138, standard deviation 10. The wall pixels above, below and right of it: 3 × 139,
  // 75 % kept and 15 % of those flying: 47, standard deviation 6.5.
  EXPECT_NEAR(static_cast<double>(count_pixels(sim, dropped)), 138.0, 40.0);
  EXPECT_NEAR(static_cast<double>(count_pixels(sim, flying)), 47.0, 26.0);
  sim.params.edge_dropout = 0.0F;
  EXPECT_EQ(count_pixels(sim, dropped), 0U);
  sim.params.flying_pixels = 0.0F;
  EXPECT_EQ(count_pixels(sim, flying), 0U);
}

/// A 0.4 m box of `material` 1 m from the camera (label 1) before a wall at 2 m.
Simulator material_scene(const Material& material) {
  Simulator sim;
  sim.scene.objects = {object(wall_shape(2.0F), true),
                       object(Shape::box({-0.2F, -0.2F, 1.0F}, {0.2F, 0.2F, 1.1F}), false, material)};
  return sim;
}

/// Share of the box's interior, 3 px inside its edges (no edge effects there), without depth in frame 0.
double box_interior_hole_share(const Simulator& sim) {
  Frame f;
  sim.render(0, f);
  size_t pixels = 0, zeros = 0;
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < f.depth.width; ++u) {
      bool interior = true;
      for (int k = -3; k <= 3 && interior; ++k) {
        interior = u + k >= 0 && u + k < f.depth.width && v + k >= 0 && v + k < f.depth.height &&
                   f.truth->labels[at(f, u + k, v)] == 1 && f.truth->labels[at(f, u, v + k)] == 1;
      }
      if (!interior) continue;
      ++pixels;
      zeros += no_depth(f, u, v) ? 1U : 0U;
    }
  }
  EXPECT_GT(pixels, 20000U);  // 161 px square
  return static_cast<double>(zeros) / static_cast<double>(pixels);
}

TEST(SimSensor, MaterialsDropOutInPatchesAtTheirRatesAndNotAtRateZero) {
  struct Case {
    Material material;
    float SimParams::*rate;
  };
  const Case cases[] = {{Material{true, false, false}, &SimParams::dark_dropout},
                        {Material{false, true, false}, &SimParams::shiny_dropout},
                        {Material{false, false, true}, &SimParams::low_texture_dropout}};
  for (const Case& c : cases) {
    Simulator sim = material_scene(c.material);
    sim.params.speckle = 0.0F;  // every hole inside the box is then a material patch
    // ~1600 independent 4x4 patches: the share's standard error is ≤ 1.3 %.
    EXPECT_NEAR(box_interior_hole_share(sim), sim.params.*c.rate, 0.05) << "rate " << sim.params.*c.rate;
    sim.params.*c.rate = 0.0F;
    EXPECT_EQ(box_interior_hole_share(sim), 0.0) << "rate 0: the flagged surface keeps its depth";
  }
  // An unflagged box loses only speckle (0.2 % of ~26000 pixels: 52, standard deviation 7).
  EXPECT_NEAR(box_interior_hole_share(material_scene(Material{})), SimParams{}.speckle, 0.001);
}

TEST(SimSensor, SpeckleIsRareNewEveryFrameAndSwitchesOff) {
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
  sim.params.speckle = 0.0F;
  EXPECT_EQ(count_pixels(sim, no_depth), 21U * 480U) << "speckle 0: only the left band (columns 0-20)";
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
