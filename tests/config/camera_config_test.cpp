// SPDX-License-Identifier: Apache-2.0
// Tests of the live camera's keys: source.serial/width/height/fps, source.color.*,
// source.options.* (the SDK's names and ranges) and source.settle_frames.
#include "config_test_util.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

TEST(CameraConfig, Defaults) {
  const SourceConfig source = load_config("", {}).source;
  EXPECT_EQ(source.serial, "");
  EXPECT_EQ(source.width, 848);
  EXPECT_EQ(source.height, 480);
  EXPECT_EQ(source.fps, 30);
  EXPECT_FALSE(source.color.enabled);
  EXPECT_EQ(source.color.width, 848);
  EXPECT_EQ(source.color.height, 480);
  EXPECT_EQ(source.color.fps, 30);
  EXPECT_TRUE(source.options.empty());
  EXPECT_EQ(source.settle_frames, 30);
}

TEST(CameraConfig, ReadsAFile) {
  TempDir dir;
  const std::string file = dir.write("cell.yaml",
                                     "source:\n"
                                     "  type: realsense\n"
                                     "  serial: '825312072719'\n"
                                     "  fps: 90\n"
                                     "  color: {enabled: true, width: 1280, height: 720, fps: 15}\n"
                                     "  options: {visual_preset: high_accuracy, laser_power: 150, emitter_enabled: true}\n"
                                     "  settle_frames: 10\n");
  const SourceConfig source = load_config(file, {}).source;
  EXPECT_EQ(source.type, SourceType::realsense);
  EXPECT_EQ(source.serial, "825312072719");  // quoted: a serial is text, leading zeros and all
  EXPECT_EQ(source.fps, 90);
  EXPECT_TRUE(source.color.enabled);
  EXPECT_EQ(source.color.width, 1280);
  EXPECT_EQ(source.color.height, 720);
  EXPECT_EQ(source.color.fps, 15);
  EXPECT_EQ(source.settle_frames, 10);
  // In the SDK's order: the preset first, as its rs2_rs400_visual_preset number (3).
  ASSERT_EQ(source.options.size(), 3U);
  EXPECT_EQ(source.options[0].name, "visual_preset");
  EXPECT_EQ(source.options[0].value, 3.0F);
  EXPECT_EQ(source.options[1].name, "emitter_enabled");
  EXPECT_EQ(source.options[1].value, 1.0F);
  EXPECT_EQ(source.options[2].name, "laser_power");
  EXPECT_EQ(source.options[2].value, 150.0F);
}

TEST(CameraConfig, TheAssemblyGivesTheAdapterTheseValues) {
  // The SDK adapter never sees a Config: realsense_params copies source.* into its own params.
  const Config config = load_config("", {"source.type=realsense", "source.serial='825312072719'", "source.fps=60",
                                         "source.width=640", "source.height=480",
                                         "source.color={enabled: true, width: 1280, height: 720, fps: 15}",
                                         "source.options={laser_power: 150}", "source.settle_frames=12",
                                         "source.path=cell.bag", "source.loop=true"});
  std::atomic<bool> stop{false};
  const RealSenseParams params = realsense_params(config.source, &stop);
  EXPECT_EQ(params.serial, "825312072719");
  EXPECT_EQ(params.width, 640);
  EXPECT_EQ(params.height, 480);
  EXPECT_EQ(params.fps, 60);
  EXPECT_TRUE(params.color);
  EXPECT_EQ(params.color_width, 1280);
  EXPECT_EQ(params.color_height, 720);
  EXPECT_EQ(params.color_fps, 15);
  ASSERT_EQ(params.options.size(), 1U);
  EXPECT_EQ(params.options[0].name, "laser_power");
  EXPECT_EQ(params.options[0].value, 150.0F);
  EXPECT_EQ(params.settle_frames, 12);
  EXPECT_EQ(params.path, "cell.bag");
  EXPECT_TRUE(params.loop);
  EXPECT_EQ(params.stop_requested, &stop);
}

TEST(CameraConfig, VisualPresetsAreTheSdkNumbers) {
  const std::vector<std::string> names = {"custom", "default", "hand", "high_accuracy", "high_density",
                                          "medium_density"};
  for (size_t i = 0; i < names.size(); ++i) {
    const SourceConfig source = load_config("", {"source.options.visual_preset=" + names[i]}).source;
    ASSERT_EQ(source.options.size(), 1U);
    EXPECT_EQ(source.options[0].value, static_cast<float>(i)) << names[i];
  }
  expect_config_error("", {"source.options.visual_preset=max_range"},
                      {"'source.options.visual_preset'", "custom, default, hand, high_accuracy", "'max_range'"});
}

TEST(CameraConfig, ManualExposureSwitchesAutoExposureOff) {
  const SourceConfig source = load_config("", {"source.options.exposure=8500"}).source;
  ASSERT_EQ(source.options.size(), 2U);
  EXPECT_EQ(source.options[0].name, "enable_auto_exposure");
  EXPECT_EQ(source.options[0].value, 0.0F);
  EXPECT_EQ(source.options[1].name, "exposure");
  EXPECT_EQ(source.options[1].value, 8500.0F);
  const SourceConfig off = load_config("", {"source.options.enable_auto_exposure=false"}).source;
  ASSERT_EQ(off.options.size(), 1U);
  EXPECT_EQ(off.options[0].value, 0.0F);
  expect_config_error("", {"source.options.exposure=8500", "source.options.enable_auto_exposure=true"},
                      {"'source.options.enable_auto_exposure'", "'source.options.exposure'", "auto exposure off"});
}

TEST(CameraConfig, EmitterIsOnOrOff) {
  for (const auto& [text, value] : std::vector<std::pair<std::string, float>>{
           {"0", 0.0F}, {"1", 1.0F}, {"true", 1.0F}, {"false", 0.0F}}) {
    const SourceConfig source = load_config("", {"source.options.emitter_enabled=" + text}).source;
    ASSERT_EQ(source.options.size(), 1U) << text;
    EXPECT_EQ(source.options[0].value, value) << text;
  }
  expect_config_error("", {"source.options.emitter_enabled=2"}, {"'source.options.emitter_enabled'", "laser auto"});
  expect_config_error("", {"source.options.emitter_enabled=3"}, {"'source.options.emitter_enabled'", "'3'"});
}

TEST(CameraConfig, OutOfRangeValuesNameTheKey) {
  expect_config_error("", {"source.fps=25"}, {"'source.fps'", "6, 15, 30, 60, 90", "got 25"});
  expect_config_error("", {"source.color.fps=90"}, {"'source.color.fps'", "6, 15, 30, 60", "got 90"});
  expect_config_error("", {"source.width=0"}, {"'source.width'", "[1, 4096]"});
  expect_config_error("", {"source.color.height=5000"}, {"'source.color.height'", "[1, 4096]"});
  expect_config_error("", {"source.options.laser_power=400"}, {"'source.options.laser_power'", "360"});
  expect_config_error("", {"source.options.laser_power=100"}, {"'source.options.laser_power'", "multiple of 30"});
  expect_config_error("", {"source.options.exposure=0"}, {"'source.options.exposure'", "[1, 165000]"});
  expect_config_error("", {"source.options.exposure=200000"}, {"'source.options.exposure'", "[1, 165000]"});
  expect_config_error("", {"source.options.enable_auto_exposure=maybe"}, {"'source.options.enable_auto_exposure'"});
  expect_config_error("", {"source.settle_frames=-1"}, {"'source.settle_frames'", "[0, 1000]"});
  // An option the SDK has but hrcsense does not set is an unknown key, as any other.
  expect_config_error("", {"source.options.gain=16"}, {"unknown key 'source.options.gain'"});
}

TEST(CameraConfig, OptionsGivenAreInTheCanonicalConfiguration) {
  const Config plain = load_config("", {});
  EXPECT_EQ(plain.canonical_yaml.find("options"), std::string::npos);  // none given, none written
  const Config preset = load_config("", {"source.options.visual_preset=hand"});
  EXPECT_NE(preset.canonical_yaml.find("visual_preset: hand"), std::string::npos) << preset.canonical_yaml;
  EXPECT_NE(config_hash(plain), config_hash(preset));
}

}  // namespace
}  // namespace hrcsense
