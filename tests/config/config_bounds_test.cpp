// SPDX-License-Identifier: Apache-2.0
// Tests of the numeric bounds: every number is checked as the float (or double) it is used as,
// so 1e39 is not a finite config value that becomes inf inside the pipeline; the safety keys
// and durations have bounds that keep verdicts and clocks meaningful.
#include "../support/scenes.hpp"
#include "config_test_util.hpp"
#include "../support/run_cli.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

TEST(ConfigBounds, NumbersBeyondAFloatAreErrorsNamingTheKey) {
  // Each was a finite double, cast to an infinite float: every frame then said run.
  for (const std::string set : {"camera.T_base_camera.rotation_rpy_deg=[1e39, 0, 0]",
                                "camera.T_base_camera.translation_m=[0, -1e39, 0]",
                                "robot.points_base=[[0, 0, 1], [1e39, 0, 0]]",
                                "sim.color_translation_m=[0, 0, 1e39]",
                                "foreground.workspace_base.max=[1e39, 1, 1]",
                                "foreground.min_object_mm=1e39",
                                "safety.slow_distance_m=1e39",
                                "background.moving_min_spread_m=1e39",
                                "sim.edge_jump_px=1e39",
                                "filters.spatial.alpha=1e39"}) {
    const std::string key = set.substr(0, set.find('='));
    expect_config_error("", {set}, {"key '" + key + "'"});
  }
  // The limit is a float's: 3.4e38 still fits, 3.5e38 does not (a double would take both).
  const Config big = load_config("", {"foreground.workspace_base.max=[3.4e38, 1, 1]"});
  EXPECT_EQ(big.pipeline.foreground.workspace_base.max.x(), 3.4e38F);
  expect_config_error("", {"foreground.workspace_base.max=[3.5e38, 1, 1]"}, {"'foreground.workspace_base.max'", "float"});
  // "> 0" is checked on the float: 1e-46 is positive as a double but the float 0.
  expect_config_error("", {"foreground.k_sigma=1e-46"}, {"'foreground.k_sigma'", "> 0"});
  const Config tiny = load_config("", {"foreground.k_sigma=1e-30"});
  EXPECT_EQ(tiny.pipeline.foreground.k_sigma, 1e-30F);
}

TEST(ConfigBounds, TheIssuesCommandIsNowAUsageErrorNamingTheKey) {
  const std::string people = std::string(HRCSENSE_SHARED_DIR) + "/data/ist_piv_lab_people";
  const std::string source = std::filesystem::exists(people)
                                 ? "--set source.type=folder --set source.path=" + people + " --set background.frames=3 "
                                 : std::string("--set sim.frames=5 --set background.frames=3 ");
  const test::CliResult r = test::cli("run " + source + "--set filters.preset=none "
                                      "--set 'camera.T_base_camera.rotation_rpy_deg=[1e39,0,0]' --out /dev/null");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("hrcsense: error: <defaults>: key 'camera.T_base_camera.rotation_rpy_deg': expected numbers "
                       "in [-360, 360], got '1e39'"),
            std::string::npos)
      << r.out;
}

TEST(ConfigBounds, PositionsStayWithinAKilometreAndAnglesWithinATurn) {
  const Config c = load_config("", {"camera.T_base_camera.translation_m=[1000, -1000, 0]",
                                    "camera.T_base_camera.rotation_rpy_deg=[360, -360, 90]",
                                    "robot.points_base=[[-1000, 0, 1000]]"});
  EXPECT_NEAR(c.pipeline.T_base_camera.translation().x(), 1000.0, 1e-9);
  expect_config_error("", {"camera.T_base_camera.translation_m=[1000.5, 0, 0]"},
                      {"'camera.T_base_camera.translation_m'", "[-1000, 1000]"});
  expect_config_error("", {"camera.T_base_camera.rotation_rpy_deg=[0, 361, 0]"},
                      {"'camera.T_base_camera.rotation_rpy_deg'", "[-360, 360]"});
  expect_config_error("", {"robot.points_base=[[1e30, 0, 0]]"}, {"'robot.points_base'", "[-1000, 1000]"});
  expect_config_error("", {"robot.padding_m=1e30"}, {"'robot.padding_m'", "<= 1000"});
}

TEST(ConfigBounds, ArmCapsulesFarFromTheBaseAreRefused) {
  // Each DH offset is a fine number, but six of 600 m chain to a flange 3.6 km up.
  TempDir dir;
  std::string arm = "name: tower\ndh:\n";
  for (int j = 0; j < 6; ++j) arm += "  - {d_m: 600, a_m: 0, alpha_deg: 0}\n";
  arm += "links:\n  wrist_3: [{a_m: [0, 0, 0], b_m: [0, 0, 0.1], radius_m: 0.05}]\n";
  const std::string path = dir.write("tower.yaml", arm);
  expect_config_error("", {"robot.model=custom", "robot.description=" + path, "robot.joints_rad=[0, 0, 0, 0, 0, 0]"},
                      {"<defaults>: key 'robot': capsule 0 (link 6) is not within 1000 m"});
  // A description number beyond a float is refused where it is written.
  std::string huge_arm = "name: huge\ndh:\n  - {d_m: 1e39, a_m: 0, alpha_deg: 0}\n";
  for (int j = 1; j < 6; ++j) huge_arm += "  - {d_m: 0, a_m: 0, alpha_deg: 0}\n";
  huge_arm += "links:\n  base: [{a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: 0.1}]\n";
  const std::string huge = dir.write("huge.yaml", huge_arm);
  expect_config_error("", {"robot.model=custom", "robot.description=" + huge, "robot.joints_rad=[0, 0, 0, 0, 0, 0]"},
                      {huge + ": key 'dh[0].d_m'", "float"});
  expect_config_error("", {"scene.objects=[{shapes: [{sphere: {center: [0, 0, 2], radius_m: 1e39}}]}]"},
                      {"'scene.objects[0].shapes[0].sphere.radius_m'", "float"});
}

TEST(ConfigBounds, AStopDistanceOfZeroIsAnError) {
  // A point touching the robot is at distance 0, which is not below a stop distance of 0.
  expect_config_error("", {"safety.stop_distance_m=0", "safety.slow_distance_m=0"}, {"'safety.stop_distance_m'", "> 0"});
  expect_config_error("", {"safety.stop_distance_m=0"}, {"'safety.stop_distance_m'", "> 0"});
  expect_config_error("", {"safety.stop_distance_m=0.5", "safety.slow_distance_m=0.4"},
                      {"keys 'safety.stop_distance_m' and 'safety.slow_distance_m': expected stop_distance_m <= slow_distance_m, got 0.5 > 0.4"});
  const Config equal = load_config("", {"safety.stop_distance_m=0.4", "safety.slow_distance_m=0.4"});
  EXPECT_EQ(equal.pipeline.safety.stop_distance_m, 0.4F);
}

TEST(ConfigBounds, MinValidShareDefaultsToAFifthAndMustBeAShareAboveZero) {
  EXPECT_EQ(load_config("", {}).pipeline.safety.min_valid_share, 0.2F);
  EXPECT_EQ(load_config("", {"safety.min_valid_share=0.5"}).pipeline.safety.min_valid_share, 0.5F);
  EXPECT_EQ(load_config("", {"safety.min_valid_share=1"}).pipeline.safety.min_valid_share, 1.0F);
  for (const char* bad : {"0", "-0.1", "1.01", ".nan", "a fifth"}) {
    expect_config_error("", {std::string("safety.min_valid_share=") + bad},
                        {"key 'safety.min_valid_share'", bad[0] == '0' || bad[0] == '1' || bad[0] == '-' ? "> 0 and <= 1" : "number"});
  }
  EXPECT_NE(load_config("", {}).canonical_yaml.find("min_valid_share: 0.2\n"), std::string::npos);
}

TEST(ConfigBounds, TheWatchdogWaitsBetweenAMillisecondAndAMinute) {
  EXPECT_EQ(load_config("", {"safety.max_frame_age_s=60"}).pipeline.safety.max_frame_age_s, 60.0);
  EXPECT_EQ(load_config("", {"safety.max_frame_age_s=0.001"}).pipeline.safety.max_frame_age_s, 0.001);
  // 9.2e9 s overflowed a clock conversion and flooded the output with watchdog lines.
  for (const char* bad : {"9.2e9", "60.5", "3600", "0.0009", "0", "-1", ".inf"}) {
    expect_config_error("", {std::string("safety.max_frame_age_s=") + bad},
                        {"key 'safety.max_frame_age_s'", bad == std::string(".inf") ? "number" : "[0.001, 60] s"});
  }
}

TEST(ConfigBounds, SimulatorTimingAndNoiseKeepTimestampsAndCountsInRange) {
  expect_config_error("", {"sim.fps=1e-39"}, {"'sim.fps'", "[1, 1000] frames/s"});
  expect_config_error("", {"sim.fps=0.5"}, {"'sim.fps'", "[1, 1000] frames/s"});
  expect_config_error("", {"sim.fps=1001"}, {"'sim.fps'", "[1, 1000] frames/s"});
  expect_config_error("", {"sim.frames=1000000001"}, {"'sim.frames'", "[1, 1000000000]"});
  expect_config_error("", {"sim.disparity_step_px=1e-39"}, {"'sim.disparity_step_px'", "[0.015625, 1]"});
  expect_config_error("", {"sim.disparity_noise_px=11"}, {"'sim.disparity_noise_px'", "<= 10"});
  expect_config_error("", {"sim.baseline_mm=1e-39"}, {"'sim.baseline_mm'", "[1, 1000] mm"});
  expect_config_error("", {"source.stereo_baseline_mm=1e-39"}, {"'source.stereo_baseline_mm'", "0 (unknown)"});
  const Config c = load_config("", {"sim.fps=1", "sim.frames=1000000000", "sim.disparity_step_px=0",
                                    "source.stereo_baseline_mm=0", "sim.baseline_mm=1"});
  EXPECT_EQ(c.sim.frames, 1000000000);
  EXPECT_EQ(c.sim.disparity_step_px, 0.0F);
}

TEST(ConfigBounds, SelfFilterKeysAreReadAndBounded) {
  // Defaults as docs/CONFIG.md states them, and each key reaches the pipeline's parameters.
  const Config defaults = load_config(test::scene_path("cell-ur5-moving.yaml"), {});
  EXPECT_TRUE(defaults.pipeline.self_filter.enabled);
  EXPECT_FLOAT_EQ(defaults.pipeline.self_filter.margin_m, 0.03F);
  EXPECT_EQ(defaults.pipeline.self_filter.dilate_px, 2);
  EXPECT_EQ(defaults.pipeline.self_filter.memory_frames, 3);
  const Config set = load_config(test::scene_path("cell-ur5-moving.yaml"),
                                 {"self_filter.enabled=false", "self_filter.margin_m=0.05", "self_filter.dilate_px=0",
                                  "self_filter.memory_frames=1"});
  EXPECT_FALSE(set.pipeline.self_filter.enabled);
  EXPECT_FLOAT_EQ(set.pipeline.self_filter.margin_m, 0.05F);
  EXPECT_EQ(set.pipeline.self_filter.dilate_px, 0);
  EXPECT_EQ(set.pipeline.self_filter.memory_frames, 1);
  for (const std::string bad : {"self_filter.margin_m=-0.01", "self_filter.margin_m=2", "self_filter.dilate_px=65",
                                "self_filter.memory_frames=0", "self_filter.enabled=maybe"}) {
    expect_config_error("", {bad}, {"key '" + bad.substr(0, bad.find('=')) + "'"});
  }
}

}  // namespace
}  // namespace hrcsense
