// SPDX-License-Identifier: Apache-2.0
// The simulator's sensor models (`sim.sensor`, docs/SIMULATOR.md): the default d435 renders
// exactly what the simulator rendered before there was a choice.

#include "../support/scenes.hpp"
#include "sim_sensor_scenes.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace hrcsense {
namespace {

using test::scene_path;

using namespace sim_test;

/// FNV-1a over the depth and colour bytes of frames `first`, `first + step`, ... (`count` of them).
uint64_t frames_checksum(const Simulator& sim, int64_t first, int64_t step, int count) {
  uint64_t h = 0xCBF29CE484222325ULL;
  const auto add = [&h](uint8_t byte) {
    h ^= byte;
    h *= 0x100000001B3ULL;
  };
  Frame f;
  for (int k = 0; k < count; ++k) {
    sim.render(first + k * step, f);
    for (const uint16_t raw : f.depth.pixels) {
      add(static_cast<uint8_t>(raw & 0xFFU));
      add(static_cast<uint8_t>(raw >> 8));
    }
    if (f.color) {
      for (const uint8_t byte : f.color->rgb) add(byte);
    }
  }
  return h;
}

/// The shadow scene with a dark box, a shiny ball and a low-texture panel added: every D435
/// effect (band, shadow, edges, flying pixels, three materials, speckle, noise) has pixels.
Simulator every_effect_scene() {
  Simulator sim = shadow_scene(true);
  sim.scene.objects.push_back(object(Shape::box({-0.6F, 0.1F, 0.9F}, {-0.3F, 0.3F, 1.0F}), true, {true, false, false}));
  sim.scene.objects.push_back(object(Shape::sphere({0.4F, -0.2F, 0.8F}, 0.1F), true, {false, true, false}));
  sim.scene.objects.push_back(object(Shape::box({0.2F, 0.1F, 1.0F}, {0.6F, 0.3F, 1.05F}), true, {false, false, true}));
  return sim;
}

TEST(SimSensorModels, D435FramesAreTheUnchangedSimulators) {
  // The expected sums are the output of the unchanged simulator: recorded on main at caed12b,
  // before `sim.sensor` existed, in the Release build (depth and colour bytes). A new sensor
  // model must not move a single D435 pixel, with every effect on, with correlated noise, without
  // noise, and in two shipped scenes (walk with its person, cell-ur5-moving with its moving arm).
  const Simulator every = every_effect_scene();
  Simulator correlated = every;
  correlated.params.correlated_noise_px = 0.1F;
  Simulator exact = every;
  exact.params.noise = false;
  const Simulator walk = make_simulator(load_config(scene_path("walk.yaml"), {}));
  const Simulator cell = make_simulator(load_config(scene_path("cell-ur5-moving.yaml"), {}));
  EXPECT_EQ(frames_checksum(every, 0, 1, 3), 0x5c6fb096c6bcb46fULL);
  EXPECT_EQ(frames_checksum(correlated, 0, 1, 2), 0x736bff35de293a92ULL);
  EXPECT_EQ(frames_checksum(exact, 0, 1, 1), 0xf944ee820acb789fULL);
  EXPECT_EQ(frames_checksum(walk, 0, 150, 2), 0x6088b86b0a7b324aULL);
  EXPECT_EQ(frames_checksum(cell, 150, 150, 2), 0xfb37684ab3060d48ULL);
}

TEST(SimSensorModels, NamesAreTheConfigurations) {
  // The configuration parses them (tests/config/sim_sensor_config_test.cpp refuses others).
  EXPECT_STREQ(sim_sensor_name(SimSensor::d435), "d435");
  EXPECT_STREQ(sim_sensor_name(SimSensor::structured_light), "structured_light");
}

TEST(SimSensorModels, StructuredLightIsAPrimeSenseClassCamera) {
  SimParams p;
  p.fps = 15.0;
  p.frames = 42;
  p.seed = 7;
  p.noise = false;
  apply_sim_sensor(SimSensor::structured_light, p);
  EXPECT_EQ(p.sensor, SimSensor::structured_light);
  EXPECT_EQ(p.width, 640);
  EXPECT_EQ(p.height, 480);
  EXPECT_FLOAT_EQ(p.baseline_mm, 75.0F);
  EXPECT_FLOAT_EQ(p.disparity_step_px, 0.125F);
  EXPECT_FLOAT_EQ(p.depth_scale_m, 0.001F);
  EXPECT_FALSE(p.left_band);
  EXPECT_FLOAT_EQ(p.min_range_m, 0.5F);
  EXPECT_FLOAT_EQ(p.max_range_m, 4.5F);
  EXPECT_GT(p.edge_flicker, 0.0F);
  // What a sensor preset leaves alone.
  EXPECT_EQ(p.fps, 15.0);
  EXPECT_EQ(p.frames, 42);
  EXPECT_EQ(p.seed, 7U);
  EXPECT_FALSE(p.noise);
  // Intrinsics: fx = fy = 570 px at 640x480, scaled with the width; the centre (size − 1) / 2.
  const std::optional<Intrinsics> vga = structured_light_intrinsics(640, 480);
  ASSERT_TRUE(vga);
  EXPECT_FLOAT_EQ(vga->fx, 570.0F);
  EXPECT_FLOAT_EQ(vga->fy, 570.0F);
  EXPECT_FLOAT_EQ(vga->ppx, 319.5F);
  EXPECT_FLOAT_EQ(vga->ppy, 239.5F);
  EXPECT_EQ(vga->model, Distortion::none);
  const std::optional<Intrinsics> qvga = structured_light_intrinsics(320, 240);
  ASSERT_TRUE(qvga);
  EXPECT_FLOAT_EQ(qvga->fx, 285.0F);
  EXPECT_FLOAT_EQ(qvga->ppx, 159.5F);
  EXPECT_FLOAT_EQ(structured_light_intrinsics(848, 480)->fx, 755.25F);  // 570 · 848/640
  EXPECT_FALSE(structured_light_intrinsics(1000, 1000));
  Simulator sim;
  sim.params = p;
  EXPECT_FLOAT_EQ(sim.intrinsics().fx, 570.0F);
  sim.params.width = 1000;
  EXPECT_THROW((void)sim.intrinsics(), std::invalid_argument);
}

TEST(SimSensorModels, BackToD435RendersTheD435Again) {
  // The preset and back: every value the D435 renders with is restored.
  Simulator there_and_back = every_effect_scene();
  apply_sim_sensor(SimSensor::structured_light, there_and_back.params);
  apply_sim_sensor(SimSensor::d435, there_and_back.params);
  EXPECT_EQ(frames_checksum(there_and_back, 0, 1, 3), frames_checksum(every_effect_scene(), 0, 1, 3));
}

TEST(SimSensorModels, StructuredLightFramesDependOnlyOnSeedAndIndex) {
  // Flicker and far dropouts are new every frame, yet frame i is the same whenever it is
  // rendered, and another seed gives other frames.
  Simulator sim;
  apply_sim_sensor(SimSensor::structured_light, sim.params);
  // A box 1 m away (edges) before a wall 3.4–4.3 m away (range dropouts).
  sim.scene.objects.push_back(object(Shape::plane({0, 0, 3.8F}, {0.2F, 0, -1}), true));
  sim.scene.objects.push_back(object(Shape::box({-0.2F, -0.2F, 1.0F}, {0.2F, 0.2F, 1.2F}), false));
  const uint64_t forwards = frames_checksum(sim, 1, 2, 2);     // frames 1, 3
  Simulator other_order = sim;
  Frame f;
  other_order.render(3, f);
  other_order.render(0, f);
  EXPECT_EQ(frames_checksum(other_order, 1, 2, 2), forwards);
  EXPECT_NE(frames_checksum(sim, 1, 1, 1), frames_checksum(sim, 2, 1, 1));
  sim.params.seed = 10;
  EXPECT_NE(frames_checksum(sim, 1, 2, 2), forwards);
}

TEST(SimSensorModels, SourceReportsTheSensorModel) {
  Simulator sim;
  sim.params.frames = 1;
  EXPECT_EQ(SimSource(sim).info().sensor_model, "d435");
  apply_sim_sensor(SimSensor::structured_light, sim.params);
  const SourceInfo info = SimSource(sim).info();
  EXPECT_EQ(info.sensor_model, "structured_light");
  EXPECT_FLOAT_EQ(info.stereo_baseline_mm, 75.0F);
  EXPECT_FLOAT_EQ(info.intrinsics.fx, 570.0F);
  EXPECT_EQ(info.intrinsics.width, 640);
}

}  // namespace
}  // namespace hrcsense
