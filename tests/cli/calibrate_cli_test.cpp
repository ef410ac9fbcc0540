// SPDX-License-Identifier: Apache-2.0
// `hrcsense calibrate` from the command line (issue H3, part 1): a small noise-free sweep of the
// moving UR5 cell from a told pose 0.1 m and 8 degrees off the simulator's true one writes the
// true pose (the file and the printed --set lines agree), an arm held still is refused with exit 1
// and nothing written, and a configuration without an arm is a usage error.

#include "../support/calibration_runs.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <string>

namespace hrcsense {
namespace {

// The moving cell without noise or colour, its first 120 frames, a sample every 8 pixels: a
// quick sweep (the person enters the view after frame 120; 4 s under the sanitizers).
std::string calib_cli_small_cell() {
  return "--config " + test::scene_path("cell-ur5-moving.yaml") +
         " --set sim.noise=false --set sim.color=false --set calibration.grid_px=8 --frames 120";
}

TEST(CalibrateCli, WritesTheTruePoseAndPrintsTheSetLinesThatApplyIt) {
  const Pose truth = test::calib_scene_pose("cell-ur5-moving.yaml");
  const Pose told = test::calib_random_error(truth, 7, 0.1, 0.1, 8.0, 8.0);
  const std::string out = std::string(::testing::TempDir()) + "calibrate_cli/pose.yaml";
  std::filesystem::remove_all(std::filesystem::path(out).parent_path());
  const test::CliResult run =
      test::cli("calibrate " + calib_cli_small_cell() + " --out " + out + " " + test::calib_pose_sets(truth, told));
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const std::optional<Pose> printed = test::calib_printed_pose(run.out);
  ASSERT_TRUE(printed) << run.out;
  EXPECT_LT(translation_between_m(*printed, truth), 0.002);
  EXPECT_LT(rotation_between_deg(*printed, truth), 0.05);

  const YAML::Node file = YAML::LoadFile(out);  // its folder was made
  const YAML::Node pose = file["camera"]["T_base_camera"];
  ASSERT_TRUE(pose["translation_m"].IsSequence());
  ASSERT_TRUE(pose["rotation_rpy_deg"].IsSequence());
  std::string t = "[";
  std::string rpy = "[";
  for (int i = 0; i < 3; ++i) {
    t += (i ? ", " : "") + pose["translation_m"][i].as<std::string>();
    rpy += (i ? ", " : "") + pose["rotation_rpy_deg"][i].as<std::string>();
  }
  const Pose from_file = load_config("", {"camera.T_base_camera.translation_m=" + t + "]",
                                          "camera.T_base_camera.rotation_rpy_deg=" + rpy + "]"})
                             .pipeline.T_base_camera;
  EXPECT_LT(translation_between_m(from_file, *printed), 1e-6);
  EXPECT_LT(rotation_between_deg(from_file, *printed), 1e-4);
  // Noise-free depth in 1 mm steps: sub-millimetre residuals; a spread was measured.
  EXPECT_GT(file["residual_rms_m"].as<double>(), 0.0);
  EXPECT_LT(file["residual_rms_m"].as<double>(), 0.002);
  EXPECT_GT(file["sigma_translation_m"].as<double>(), 0.0);
  EXPECT_LT(file["sigma_translation_m"].as<double>(), 0.002);
  EXPECT_GT(file["sigma_rotation_deg"].as<double>(), 0.0);
  EXPECT_LT(file["sigma_rotation_deg"].as<double>(), 0.05);
}

TEST(CalibrateCli, AnArmHeldStillIsRefusedWithExitOneAndNothingWritten) {
  const std::string out = std::string(::testing::TempDir()) + "calibrate_held.yaml";
  std::filesystem::remove(out);
  const test::CliResult run = test::cli(
      "calibrate " + calib_cli_small_cell() + " --out " + out +
      " --set robot.trajectory='{interpolation: linear, loop: false, waypoints: [{t_s: 0, joints_rad: [-2.741593, "
      "-1.0, 1.6, -2.1708, -1.5708, 0.0]}, {t_s: 1, joints_rad: [-2.741593, -1.0, 1.6, -2.1708, -1.5708, 0.0]}]}'");
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_NE(run.out.find("calibrate: refused"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("six degrees of freedom"), std::string::npos) << run.out;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CalibrateCli, ACellWithoutAnArmIsAUsageError) {
  const test::CliResult run = test::cli("calibrate --config " + test::scene_path("walk.yaml") + " --out " +
                                        std::string(::testing::TempDir()) + "calibrate_points.yaml");
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_NE(run.out.find("robot.model"), std::string::npos) << run.out;
  const test::CliResult no_out = test::cli("calibrate --config " + test::scene_path("cell-ur5-moving.yaml"));
  EXPECT_EQ(no_out.exit_code, 2) << no_out.out;
  EXPECT_NE(no_out.out.find("--out"), std::string::npos) << no_out.out;
}

}  // namespace
}  // namespace hrcsense
