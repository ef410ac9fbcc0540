// SPDX-License-Identifier: Apache-2.0
// Tests of load_config's errors: each names the file (or the override) and the key.
#include "common/assembly.hpp"
#include "config_test_util.hpp"

#include <gtest/gtest.h>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

TEST(ConfigErrors, UnknownKeyNamesFileAndKey) {
  TempDir dir;
  const std::string path = dir.write("walk.yaml", "safety:\n  stop_distanse_m: 0.3\n");
  try {
    (void)load_config(path, {});
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": unknown key 'safety.stop_distanse_m'");
  }
  expect_config_error(dir.write("a.yaml", "sim: {fps: 30}\nsimm: {fps: 30}\n"), {}, {"a.yaml", "'simm'"});
  expect_config_error(dir.write("b.yaml", "camera: {T_base_camera: {translation: [0, 0, 0]}}\n"), {},
                      {"b.yaml", "'camera.T_base_camera.translation'"});
  expect_config_error(dir.write("c.yaml", "scene: {objects: [{name: x, shapes: [{sphere: {centre: [0, 0, 1], radius_m: 1}}]}]}\n"),
                      {}, {"c.yaml", "scene.objects[0].shapes[0].sphere.centre"});
  expect_config_error(dir.write("d.yaml", "scene: {objects: [{name: x, colour: red, shapes: [{sphere: {center: [0, 0, 1], radius_m: 1}}]}]}\n"),
                      {}, {"d.yaml", "scene.objects[0].colour"});
  expect_config_error(dir.write("e.yaml", "sim: 5\n"), {}, {"e.yaml", "'sim'", "map"});
}

TEST(ConfigErrors, IllTypedValuesNameFileKeyAndExpectation) {
  TempDir dir;
  const auto check = [&](const std::string& yaml, const std::string& key, const std::string& expected) {
    const std::string path = dir.write("bad.yaml", yaml);
    expect_config_error(path, {}, {path, key, expected});
  };
  check("sim: {fps: fast}\n", "'sim.fps'", "number");
  check("sim: {frames: -5}\n", "'sim.frames'", "integer");
  check("sim: {frames: 2.5}\n", "'sim.frames'", "integer");
  check("sim: {noise: maybe}\n", "'sim.noise'", "true or false");
  check("sim: {width: 800, height: 600}\n", "'sim.width'", "D435");
  check("source: {type: foo}\n", "'source.type'", "sim, folder, bag, realsense");
  check("source: {seed: -1}\n", "'source.seed'", "integer");
  check("camera: {T_base_camera: {translation_m: [1, 2]}}\n", "'camera.T_base_camera.translation_m'", "3 numbers");
  check("camera: {T_base_camera: {rotation_rpy_deg: [1, x, 2]}}\n", "'camera.T_base_camera.rotation_rpy_deg'",
        "number");
  check("background: {frames: 0}\n", "'background.frames'", "integer");
  check("background: {max_moving_share: 2}\n", "'background.max_moving_share'", "[0, 1]");
  check("background: {motion_min_width_px: 4}\n", "'background.motion_min_width_px'", "odd");
  check("background: {min_valid_ratio: 1.5}\n", "'background.min_valid_ratio'", "[0, 1]");
  check("background: {fill_radius_px: -1}\n", "'background.fill_radius_px'", "integer");
  check("background: {max_noise_per_z2: 0}\n", "'background.max_noise_per_z2'", "> 0");
  check("foreground: {k_sigma: -1}\n", "'foreground.k_sigma'", "> 0");
  check("foreground: {workspace_base: {min: [0, 0, 1], max: [1, 1, 0]}}\n", "'foreground.workspace_base.min' and 'foreground.workspace_base.max'", "min <= max");
  check("robot: {points_base: [[0, 0]]}\n", "'robot.points_base'", "[x, y, z]");
  check("robot: {points_base: []}\n", "'robot.points_base'", "at least one point");
  check("robot: {padding_m: -0.1}\n", "'robot.padding_m'", ">= 0");
  check("robot: {joints_rad: [0, 1, 2]}\n", "'robot.joints_rad'", "6 numbers");
  check("robot: {base_frame: tool0}\n", "'robot.base_frame'", "base, base_link");
  check("proximity: {octree: {height: 11}}\n", "'proximity.octree.height'", "[1, 10]");
  check("safety: {slow_distance_m: 0.5, stop_distance_m: 0.8}\n", "'safety.stop_distance_m'", "slow_distance_m");
  check("safety: {max_frame_age_s: 0}\n", "'safety.max_frame_age_s'", "[0.001, 60] s");
  check("scene: {objects: [{name: x, shapes: [{sphere: {center: [0, 0, 1], radius_m: -1}}]}]}\n",
        "scene.objects[0].shapes[0].sphere.radius_m", "> 0");
  check("scene: {objects: [{name: x, shapes: [{cone: {}}]}]}\n", "scene.objects[0].shapes[0]", "unknown shape");
  check("scene: {objects: [{name: x}]}\n", "scene.objects[0].shapes", "required");
  check("scene: {objects: [{name: x, first_frame: 9, last_frame: 3, shapes: [{sphere: {center: [0, 0, 1], radius_m: 1}}]}]}\n",
        "scene.objects[0].last_frame", "first_frame");
}

TEST(ConfigErrors, NotYetImplementedChoicesSaySo) {
  // The filters are built now: their keys are tested in tests/filters/filters_config_test.cpp.
  // The arm models are built now: their keys are tested in tests/config/robot_config_test.cpp.
  expect_config_error("", {"proximity.backend=depth_space"}, {"proximity.backend 'depth_space'", "not implemented yet"});
  const Config live = load_config("", {"source.type=realsense"});
  try {
    (void)make_source(live);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
#ifdef HRCSENSE_HAVE_REALSENSE
    GTEST_SKIP() << "this build has the RealSense SDK";
#endif
    EXPECT_EQ(std::string(e.what()),
              "configuration: source.type 'realsense': this hrcsense was built without the RealSense SDK "
              "(librealsense2); install Intel's librealsense2-dev and rebuild (README, 'Cameras')");
  }
  // Recorded sources need a path.
  const Config bag = load_config("", {"source.type=bag"});
  try {
    (void)make_source(bag);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "configuration: source.path: required for source.type bag");
  }
}

TEST(ConfigErrors, MalformedOrUnknownOverridesAreNamed) {
  for (const std::string bad : {"sim.fps", "=3", "sim..fps=3", "sim.fps=", ".sim=1", "sim fps=1"}) {
    expect_config_error("", {bad}, {"--set '" + bad + "'", "KEY=VALUE"});
  }
  expect_config_error("", {"sim.fps=[1, 2"}, {"--set 'sim.fps=[1, 2'", "YAML"});
  expect_config_error("", {"safety.stop_distanse_m=0.3"}, {"--set", "unknown key 'safety.stop_distanse_m'"});
  expect_config_error("", {"sim.fps.x=3"}, {"unknown key 'sim.fps.x'"});
  expect_config_error("", {"sim.fps=fast"}, {"'sim.fps'", "number"});
}

TEST(ConfigErrors, MissingFileAndSyntaxErrorNameTheFile) {
  TempDir dir;
  const std::string missing = dir.path() + "/nope.yaml";
  expect_config_error(missing, {}, {missing, "cannot open"});
  // Line 3 is indented less than the map it should belong to.
  const std::string broken = dir.write("broken.yaml", "sim:\n  fps: 30\n bad: 1\n");
  try {
    (void)load_config(broken, {});
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(broken + ":", 0), 0U) << message;
    EXPECT_NE(message.find("syntax error"), std::string::npos) << message;
    EXPECT_EQ(message.rfind(broken + ":3:", 0), 0U) << "line 3 expected: " << message;
  }
  expect_config_error(dir.write("list.yaml", "- a\n- b\n"), {}, {"list.yaml", "map"});
}

}  // namespace
}  // namespace hrcsense
