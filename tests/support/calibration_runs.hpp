// SPDX-License-Identifier: Apache-2.0
// Test support: `hrcsense calibrate` runs on a simulated cell whose told camera pose is off the
// true one, and the pose it prints read back through load_config (so that the printed --set
// lines are what is judged).
#pragma once

#include "run_cli.hpp"
#include "scenes.hpp"

#include "hrcsense/config/config.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace hrcsense::test {

/// "[a, b, c]" with enough digits for a pose.
inline std::string calib_vec3(const Eigen::Vector3d& v) {
  char text[128];
  std::snprintf(text, sizeof text, "[%.9f, %.9f, %.9f]", v.x(), v.y(), v.z());
  return text;
}

/// roll, pitch, yaw (deg) with R = Rz(yaw)·Ry(pitch)·Rx(roll), CONFIG.md's convention.
inline Eigen::Vector3d calib_rpy_deg(const Eigen::Matrix3d& R) {
  const double k = 180.0 / 3.14159265358979323846;
  return Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), std::asin(-R(2, 0)), std::atan2(R(1, 0), R(0, 0))) * k;
}

/// --set lines that put camera.T_base_camera at `told` and the simulated camera truly at `truth`.
inline std::string calib_pose_sets(const Pose& truth, const Pose& told) {
  return "--set sim.camera_T_base_camera.translation_m='" + calib_vec3(truth.translation()) +
         "' --set sim.camera_T_base_camera.rotation_rpy_deg='" + calib_vec3(calib_rpy_deg(truth.rotation())) +
         "' --set camera.T_base_camera.translation_m='" + calib_vec3(told.translation()) +
         "' --set camera.T_base_camera.rotation_rpy_deg='" + calib_vec3(calib_rpy_deg(told.rotation())) + "'";
}

/// `truth` moved by a random translation of length in [min_m, max_m] and turned about a random
/// axis through the camera by an angle in [min_deg, max_deg]; the same for the same seed.
inline Pose calib_random_error(const Pose& truth, unsigned seed, double min_m, double max_m, double min_deg,
                               double max_deg) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d direction = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const double length_m = min_m + (max_m - min_m) * unit(rng);
  const double angle_rad = (min_deg + (max_deg - min_deg) * unit(rng)) * 3.14159265358979323846 / 180.0;
  Pose told = truth;
  told.linear() = Eigen::AngleAxisd(angle_rad, axis).toRotationMatrix() * truth.linear();
  told.translation() += direction * length_m;
  return told;
}

/// The value inside the quotes after `key=` in `text` ("" when absent).
inline std::string calib_set_value(const std::string& text, const std::string& key) {
  const std::string tag = key + "='";
  const size_t at = text.find(tag);
  if (at == std::string::npos) return "";
  const size_t begin = at + tag.size();
  return text.substr(begin, text.find('\'', begin) - begin);
}

/// The pose a calibrate run printed, read as its --set lines would be applied: nullopt when it
/// printed none.
inline std::optional<Pose> calib_printed_pose(const std::string& output) {
  const std::string t = calib_set_value(output, "camera.T_base_camera.translation_m");
  const std::string rpy = calib_set_value(output, "camera.T_base_camera.rotation_rpy_deg");
  if (t.empty() || rpy.empty()) return std::nullopt;
  const Config config = load_config("", {"camera.T_base_camera.translation_m=" + t,
                                         "camera.T_base_camera.rotation_rpy_deg=" + rpy});
  return config.pipeline.T_base_camera;
}

/// The shipped cell's configured camera pose (the truth the runs render from).
inline Pose calib_scene_pose(const std::string& scene) { return load_config(scene_path(scene), {}).pipeline.T_base_camera; }

}  // namespace hrcsense::test
