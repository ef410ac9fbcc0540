// SPDX-License-Identifier: Apache-2.0
// hrcsense config — the source and simulator a configuration describes.
#include "hrcsense/config.hpp"
#include "hrcsense/recordings.hpp"

#include <memory>
#include <utility>

namespace hrcsense {

Simulator make_simulator(const Config& config) {
  Simulator simulator;
  simulator.params = config.sim;
  simulator.params.seed = config.source.seed;
  simulator.scene = config.scene;
  simulator.T_base_camera = config.pipeline.T_base_camera;
  simulator.robot = config.pipeline.robot;
  // The arm is part of the static scene: rendered, learnt as background, never foreground.
  if (auto arm = robot_scene_object(config)) simulator.scene.objects.push_back(*arm);
  return simulator;
}

std::unique_ptr<Source> make_source(const Config& config) {
  if (config.source.type == "sim") return std::make_unique<SimSource>(make_simulator(config));
  if (config.source.type == "folder" || config.source.type == "bag") {
    if (config.source.path.empty()) {
      throw ConfigError((config.file.empty() ? std::string("configuration") : config.file) + ": source.path: required for source.type " + config.source.type);
    }
    RecordingParams params{config.source.path, config.source.loop, config.source.stereo_baseline_mm};
    if (config.source.type == "folder") return std::make_unique<FolderSource>(params);
    return std::make_unique<BagSource>(params);
  }
  // Live sources are named in the configuration schema but not built yet.
  throw ConfigError("source.type '" + config.source.type + "' is not available in this build yet");
}

}  // namespace hrcsense
