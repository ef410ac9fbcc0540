// SPDX-License-Identifier: Apache-2.0
// The simulator's sensor models (`sim.sensor`, docs/SIMULATOR.md): the default d435 renders
// exactly what the simulator rendered before there was a choice.

#include "sim_sensor_scenes.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace hrcsense {
namespace {

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

std::string scene_path(const char* name) { return std::string(HRCSENSE_SOURCE_DIR) + "/config/" + name; }

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

}  // namespace
}  // namespace hrcsense
