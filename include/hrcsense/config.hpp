// SPDX-License-Identifier: Apache-2.0
// hrcsense — the configuration: YAML files plus --set KEY=VALUE overrides, parsed in one
// place into the stages' parameter structs. Every key has a default (docs/CONFIG.md);
// an unknown or ill-typed key is an error that names the key and the file.
#pragma once

#include "hrcsense/pipeline.hpp"
#include "hrcsense/sim.hpp"

#include <memory>
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
  std::string filters_preset = "none";  ///< `filters.preset`: none, sdk or thesis (chain in pipeline.filters)
  std::string background_path;     ///< `background.path`: load if it exists, else save after learning
  PipelineParams pipeline;         ///< camera pose, robot, background, foreground, proximity, safety
  std::string robot_model = "points";
  std::vector<double> robot_joints_rad;  ///< `robot.joints_rad`: 6 joint angles, stored for later
  std::string robot_base_frame = "base"; ///< `robot.base_frame`: base or base_link, stored for later
  int proximity_octree_height = 8;       ///< `proximity.octree.height` (1-10), stored for later
  std::string canonical_yaml;      ///< the effective configuration, for the hash in the header
};

/// Reads `path` (may be empty: defaults only) and applies `overrides` ("key.sub=value",
/// value in YAML syntax) in order. Throws ConfigError naming file and key.
Config load_config(const std::string& path, const std::vector<std::string>& overrides);

/// The simulator described by a configuration (sim.*, scene.*, camera pose, robot).
Simulator make_simulator(const Config& config);

/// The source the configuration names (source.type); throws ConfigError for a type that is
/// unknown or not built in.
std::unique_ptr<Source> make_source(const Config& config);

/// FNV-1a 64-bit hash of the effective configuration, as 16 hex digits.
std::string config_hash(const Config& config);

}  // namespace hrcsense
