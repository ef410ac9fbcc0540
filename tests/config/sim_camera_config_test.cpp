// SPDX-License-Identifier: Apache-2.0
// `sim.camera_T_base_camera`, `sim.camera_knock_frame` and `sim.camera_knock_T_base_camera`
// (docs/CONFIG.md, docs/SIMULATOR.md "A camera pose hrcsense is not told"): read in
// camera.T_base_camera's form, bad forms name the key, and absent keys leave the configuration,
// its canonical text and so its hash as they were.
#include "config_test_util.hpp"

#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::expect_config_error;

TEST(SimCameraConfig, AbsentKeysChangeNothing) {
  const Config config = load_config("", {});
  EXPECT_FALSE(config.sim_camera_T_base_camera.has_value());
  EXPECT_EQ(config.sim_camera_knock.frame, -1);
  EXPECT_EQ(config.canonical_yaml.find("camera_T_base_camera"), std::string::npos);
  EXPECT_EQ(config.canonical_yaml.find("camera_knock"), std::string::npos);
  // Every shipped configuration: none names the keys, so its canonical text (and hash) holds
  // only the keys it held before they existed.
  const std::filesystem::path folder = std::filesystem::path(HRCSENSE_SOURCE_DIR) / "config";
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().filename().string());
    const Config shipped = load_config(entry.path().string(), {});
    EXPECT_FALSE(shipped.sim_camera_T_base_camera.has_value());
    EXPECT_EQ(shipped.sim_camera_knock.frame, -1);
    EXPECT_EQ(shipped.canonical_yaml.find("camera_T_base_camera"), std::string::npos);
    EXPECT_EQ(shipped.canonical_yaml.find("camera_knock"), std::string::npos);
    ++scenes;
  }
  EXPECT_GT(scenes, 0);
}

TEST(SimCameraConfig, ReadsTheTruePoseInCameraTBaseCamerasForm) {
  const Config config = load_config(
      "", {"camera.T_base_camera={translation_m: [0, 0, 1.5], rotation_rpy_deg: [0, 0, 0]}",
           "sim.camera_T_base_camera={translation_m: [0.05, 0, 1.5], rotation_rpy_deg: [0, 0, 90]}"});
  ASSERT_TRUE(config.sim_camera_T_base_camera.has_value());
  const Pose& truth = *config.sim_camera_T_base_camera;
  EXPECT_TRUE(truth.translation().isApprox(Eigen::Vector3d(0.05, 0.0, 1.5), 1e-6));
  // Yaw 90°: the camera's x axis points along base y (column 0 of R is (0, 1, 0)).
  EXPECT_NEAR((truth.linear().col(0) - Eigen::Vector3d(0.0, 1.0, 0.0)).norm(), 0.0, 1e-6);
  // The told pose is untouched.
  EXPECT_TRUE(config.pipeline.T_base_camera.translation().isApprox(Eigen::Vector3d(0.0, 0.0, 1.5)));
  EXPECT_TRUE(config.pipeline.T_base_camera.linear().isApprox(Eigen::Matrix3d::Identity()));
  EXPECT_NE(config.canonical_yaml.find("camera_T_base_camera"), std::string::npos);
  EXPECT_NE(config_hash(config), config_hash(load_config("", {"camera.T_base_camera={translation_m: [0, 0, 1.5], "
                                                             "rotation_rpy_deg: [0, 0, 0]}"})));
}

TEST(SimCameraConfig, ReadsTheKnock) {
  const Config config = load_config("", {"sim.camera_knock_frame=120",
                                         "sim.camera_knock_T_base_camera={translation_m: [0.1, -0.2, 1.4], "
                                         "rotation_rpy_deg: [10, 0, 0]}"});
  EXPECT_FALSE(config.sim_camera_T_base_camera.has_value());
  EXPECT_EQ(config.sim_camera_knock.frame, 120);
  const Pose& knocked = config.sim_camera_knock.T_base_camera;
  EXPECT_TRUE(knocked.translation().isApprox(Eigen::Vector3d(0.1, -0.2, 1.4), 1e-6));
  // Roll 10° about x: the camera's y axis is (0, cos 10°, sin 10°) in the base frame.
  const double roll = 10.0 * kPi / 180.0;
  EXPECT_NEAR((knocked.linear().col(1) - Eigen::Vector3d(0.0, std::cos(roll), std::sin(roll))).norm(), 0.0, 1e-6);
  // Frame 0 is a knock too (from the first frame on); an explicit -1 is none.
  EXPECT_EQ(load_config("", {"sim.camera_knock_frame=0", "sim.camera_knock_T_base_camera={translation_m: [0, 0, 0], "
                             "rotation_rpy_deg: [0, 0, 0]}"})
                .sim_camera_knock.frame,
            0);
  EXPECT_EQ(load_config("", {"sim.camera_knock_frame=-1"}).sim_camera_knock.frame, -1);
}

TEST(SimCameraConfig, BadFormsNameTheKey) {
  const std::string pose = "{translation_m: [0, 0, 1], rotation_rpy_deg: [0, 0, 0]}";
  expect_config_error("", {"sim.camera_T_base_camera={translation_m: [0, 0], rotation_rpy_deg: [0, 0, 0]}"},
                      {"sim.camera_T_base_camera.translation_m", "3 numbers"});
  expect_config_error("", {"sim.camera_T_base_camera={translation_m: [0, 0, 1], rotation_rpy_deg: [0, x, 0]}"},
                      {"sim.camera_T_base_camera.rotation_rpy_deg"});
  expect_config_error("", {"sim.camera_T_base_camera={translation_m: [0, 0, 1]}"},
                      {"sim.camera_T_base_camera", "both translation_m and rotation_rpy_deg"});
  expect_config_error("", {"sim.camera_T_base_camera={rotation_rpy_deg: [0, 0, 0]}"},
                      {"sim.camera_T_base_camera", "both"});
  expect_config_error("", {"sim.camera_T_base_camera=5"}, {"sim.camera_T_base_camera", "map"});
  expect_config_error("", {"sim.camera_T_base_camera={translation_m: [0, 0, 1], rotation_rpy_deg: [0, 0, 0], "
                           "scale: 2}"},
                      {"sim.camera_T_base_camera.scale", "unknown key"});
  expect_config_error("", {"sim.camera_T_base_camera={translation_m: [0, 0, 2000], rotation_rpy_deg: [0, 0, 0]}"},
                      {"sim.camera_T_base_camera.translation_m"});
  expect_config_error("", {"sim.camera_knock_frame=-2", "sim.camera_knock_T_base_camera=" + pose},
                      {"sim.camera_knock_frame"});
  expect_config_error("", {"sim.camera_knock_frame=1.5", "sim.camera_knock_T_base_camera=" + pose},
                      {"sim.camera_knock_frame"});
  expect_config_error("", {"sim.camera_knock_frame=10"},
                      {"sim.camera_knock_frame", "sim.camera_knock_T_base_camera"});
  expect_config_error("", {"sim.camera_knock_T_base_camera=" + pose},
                      {"sim.camera_knock_frame", "sim.camera_knock_T_base_camera"});
  expect_config_error("", {"sim.camera_knock_frame=3", "sim.camera_knock_T_base_camera={translation_m: [0, 0, 1]}"},
                      {"sim.camera_knock_T_base_camera", "both"});
}

}  // namespace
}  // namespace hrcsense
