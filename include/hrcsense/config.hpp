// SPDX-License-Identifier: Apache-2.0
// hrcsense — the configuration: YAML files plus --set KEY=VALUE overrides, parsed in one
// place into the stages' parameter structs. Every key has a default (docs/CONFIG.md);
// an unknown or ill-typed key is an error that names the key and the file.
#pragma once

#include "hrcsense/pipeline.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/sim.hpp"

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense {

/// A configuration problem; what() names the file and the key.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SourceConfig {
  std::string type = "sim";        ///< sim (default), folder, bag, realsense
  std::string path;                ///< file or folder for recorded sources
  bool pace = false;               ///< play at the recorded / nominal rate
  bool loop = false;               ///< start over at the end
  uint64_t seed = 1;               ///< simulator noise seed
  float stereo_baseline_mm = 0.0F; ///< for sources that do not carry one
};

struct Config {
  std::string file;                ///< where it was read from ("" for defaults only)
  SourceConfig source;
  SimParams sim;                   ///< `sim.*`: the simulated camera
  Scene scene;                     ///< `scene.objects`: the simulated scene
  /// `filters.preset`: none, sdk (default: the RealSense Viewer's) or thesis; the chain itself
  /// is in pipeline.filters.
  std::string filters_preset = "sdk";
  std::string background_path;     ///< `background.path`: load if it exists, else save after learning
  PipelineParams pipeline;         ///< camera pose, robot, background, foreground, proximity, safety
  std::string robot_model = "points";    ///< `robot.model`: points, ur5, ur5e, ur10e or custom
  std::vector<double> robot_joints_rad;  ///< `robot.joints_rad`: 6 joint angles (rad), joint 1 first
  std::string robot_base_frame = "base"; ///< `robot.base_frame`: base or base_link
  BaseFrame robot_frame = BaseFrame::base;  ///< the same as an enum: the frame of T_base_camera and the robot
  double robot_padding_m = 0.0;          ///< `robot.padding_m` in effect (an arm's own padding by default)
  /// The arm (built in or from `robot.description`); empty for robot.model points. With
  /// robot_joints_rad, robot_frame and robot_padding_m it gives pipeline.robot
  /// (robot_capsules) and the arm to render (robot_render_capsules).
  std::optional<RobotDescription> robot_arm;
  int proximity_octree_height = 4;       ///< `proximity.octree.height` (1-10), for the octree backend
  std::string canonical_yaml;      ///< the effective configuration, for the hash in the header
};

/// Reads `path` (may be empty: defaults only) and applies `overrides` ("key.sub=value",
/// value in YAML syntax) in order. Throws ConfigError naming file and key.
Config load_config(const std::string& path, const std::vector<std::string>& overrides);

/// Reads a robot description file (docs/ROBOT.md); throws ConfigError naming the file and the
/// field, e.g. "arm.yaml: key 'links.forearm[1].radius_m': expected a number >= 0".
RobotDescription load_robot_description(const std::string& path);

/// The configured arm as a static simulator object named "robot": its rendering capsules
/// (robot_render_capsules: the visual body, no padding) in the robot.base_frame frame, so the
/// arm is part of the learnt background. Empty for robot.model points.
std::optional<SceneObject> robot_scene_object(const Config& config);

/// The simulator described by a configuration (sim.*, scene.*, camera pose, robot).
Simulator make_simulator(const Config& config);

/// The source the configuration names (source.type); throws ConfigError for a type that is
/// unknown or not built in.
std::unique_ptr<Source> make_source(const Config& config);

/// FNV-1a 64-bit hash of the effective configuration, as 16 hex digits.
std::string config_hash(const Config& config);

}  // namespace hrcsense
