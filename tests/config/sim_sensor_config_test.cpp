// SPDX-License-Identifier: Apache-2.0
// Tests of `sim.sensor` (docs/CONFIG.md, docs/SIMULATOR.md "Sensor models"): the preset it
// names, and sim.* keys given beside it overriding the preset's values.
#include "config_test_util.hpp"

#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

TEST(SimSensorConfig, DefaultIsTheD435) {
  const Config config = load_config("", {});
  EXPECT_EQ(config.sim.sensor, SimSensor::d435);
  EXPECT_EQ(config.sim.width, 848);
  EXPECT_FLOAT_EQ(config.sim.baseline_mm, kD435BaselineMm);
  EXPECT_NE(config.canonical_yaml.find("sensor: d435"), std::string::npos) << config.canonical_yaml;
  EXPECT_EQ(load_config("", {"sim.sensor=d435"}).canonical_yaml, config.canonical_yaml);
}

TEST(SimSensorConfig, StructuredLightSetsItsPreset) {
  const Config config = load_config("", {"sim.sensor=structured_light"});
  SimParams expected;
  apply_sim_sensor(SimSensor::structured_light, expected);
  const SimParams& p = config.sim;
  EXPECT_EQ(p.sensor, SimSensor::structured_light);
  EXPECT_EQ(p.width, 640);
  EXPECT_EQ(p.height, 480);
  EXPECT_FLOAT_EQ(p.baseline_mm, 75.0F);
  EXPECT_FLOAT_EQ(p.disparity_step_px, 0.125F);
  EXPECT_FLOAT_EQ(p.disparity_noise_px, expected.disparity_noise_px);
  EXPECT_FALSE(p.left_band);
  EXPECT_FLOAT_EQ(p.min_range_m, 0.5F);
  EXPECT_FLOAT_EQ(p.max_range_m, 4.5F);
  EXPECT_FLOAT_EQ(p.range_dropout, expected.range_dropout);
  EXPECT_FLOAT_EQ(p.range_dropout_start_m, expected.range_dropout_start_m);
  EXPECT_FLOAT_EQ(p.edge_flicker, expected.edge_flicker);
  EXPECT_FLOAT_EQ(p.flying_pixels, expected.flying_pixels);
  EXPECT_FLOAT_EQ(p.dark_dropout, expected.dark_dropout);
  EXPECT_FLOAT_EQ(p.shiny_dropout, expected.shiny_dropout);
  EXPECT_FLOAT_EQ(p.low_texture_dropout, expected.low_texture_dropout);
  EXPECT_EQ(p.material_cell_px, expected.material_cell_px);
  // The effective configuration names the sensor and writes the preset's values out.
  EXPECT_NE(config.canonical_yaml.find("sensor: structured_light"), std::string::npos) << config.canonical_yaml;
  EXPECT_NE(config.canonical_yaml.find("max_range_m: 4.5"), std::string::npos) << config.canonical_yaml;
  EXPECT_NE(config_hash(config), config_hash(load_config("", {})));
}

TEST(SimSensorConfig, KeysGivenOverrideThePresetInAnyOrder) {
  TempDir dir;
  // A scene file written for the D435 (848x480, its noise) run with the other sensor: the keys
  // it gives win, the rest is the preset's, whether sim.sensor comes first or last.
  const std::string last = dir.write("a.yaml", "sim: {width: 848, height: 480, disparity_noise_px: 0.08, sensor: structured_light}\n");
  const std::string first = dir.write("b.yaml", "sim: {sensor: structured_light, width: 848, height: 480, disparity_noise_px: 0.08}\n");
  for (const std::string& path : {last, first}) {
    const SimParams p = load_config(path, {}).sim;
    EXPECT_EQ(p.width, 848) << path;
    EXPECT_FLOAT_EQ(p.disparity_noise_px, 0.08F) << path;
    EXPECT_FLOAT_EQ(p.baseline_mm, 75.0F) << path;     // the preset's
    EXPECT_FALSE(p.left_band) << path;                  // the preset's
  }
  // --set overrides on top of a file, as for every key.
  const Config set = load_config(first, {"sim.left_band=true", "sim.max_range_m=3.5", "sim.range_dropout_start_m=2"});
  EXPECT_TRUE(set.sim.left_band);
  EXPECT_FLOAT_EQ(set.sim.max_range_m, 3.5F);
  // And a D435 configuration can borrow single effects of the other model.
  const SimParams d435 = load_config("", {"sim.edge_flicker=0.5", "sim.max_range_m=6"}).sim;
  EXPECT_EQ(d435.sensor, SimSensor::d435);
  EXPECT_FLOAT_EQ(d435.edge_flicker, 0.5F);
  EXPECT_FLOAT_EQ(d435.max_range_m, 6.0F);
}

TEST(SimSensorConfig, TheEffectiveConfigurationReadsBackToTheSameSensor) {
  // canonical_yaml writes the sensor and every value in effect; read again, the preset and
  // the keys give the same values, so the same hash.
  TempDir dir;
  const Config config = load_config("", {"sim.sensor=structured_light", "sim.width=320", "sim.height=240",
                                         "sim.edge_flicker=0.3"});
  const Config again = load_config(dir.write("effective.yaml", config.canonical_yaml), {});
  EXPECT_EQ(again.canonical_yaml, config.canonical_yaml);
  EXPECT_EQ(config_hash(again), config_hash(config));
  EXPECT_EQ(again.sim.sensor, SimSensor::structured_light);
  EXPECT_EQ(again.sim.width, 320);
  EXPECT_FLOAT_EQ(again.sim.edge_flicker, 0.3F);
}

TEST(SimSensorConfig, OtherNamesAndResolutionsAreRefusedNamingTheKey) {
  expect_config_error("", {"sim.sensor=kinect"}, {"'sim.sensor'", "d435, structured_light", "'kinect'"});
  expect_config_error("", {"sim.sensor=D435"}, {"'sim.sensor'", "'D435'"});
  // PrimeSense's own modes and the D435's are accepted; others are not.
  EXPECT_EQ(load_config("", {"sim.sensor=structured_light", "sim.width=320", "sim.height=240"}).sim.width, 320);
  EXPECT_EQ(load_config("", {"sim.sensor=structured_light", "sim.width=1280", "sim.height=720"}).sim.width, 1280);
  expect_config_error("", {"sim.sensor=structured_light", "sim.width=1000", "sim.height=1000"},
                      {"'sim.width'", "'sim.height'", "structured_light", "320x240"});
  expect_config_error("", {"sim.width=320", "sim.height=240"}, {"'sim.width'", "not a D435 depth resolution"});
}

TEST(SimSensorConfig, WorkingRangeKeysAreChecked) {
  expect_config_error("", {"sim.max_range_m=0.4", "sim.min_range_m=0.5"}, {"'sim.min_range_m'", "'sim.max_range_m'"});
  // Range dropouts need a far end to grow towards.
  expect_config_error("", {"sim.range_dropout=0.2"}, {"'sim.range_dropout'", "'sim.max_range_m'"});
  expect_config_error("", {"sim.sensor=structured_light", "sim.range_dropout_start_m=5"},
                      {"'sim.range_dropout'", "'sim.max_range_m'"});
  expect_config_error("", {"sim.range_dropout=1.5", "sim.max_range_m=4"}, {"'sim.range_dropout'", "between 0 and 1"});
  expect_config_error("", {"sim.edge_flicker=-0.1"}, {"'sim.edge_flicker'"});
}

}  // namespace
}  // namespace hrcsense
