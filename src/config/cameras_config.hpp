// SPDX-License-Identifier: Apache-2.0
// hrcsense config internals — a cell with several cameras (H2): the `cameras:` list, one
// entry laid over the top-level keys for `--camera NAME`, `cell.*` and `sim.epoch`.
#pragma once

#include "key_reader.hpp"

#include <yaml-cpp/yaml.h>

#include <functional>
#include <set>
#include <string>
#include <vector>

namespace hrcsense::config_detail {

/// Checks the form of `root`'s `cameras:` list, when there is one: a non-empty list of maps,
/// each with a unique `name` (a ROS name token), a `T_base_camera` with both parts, and only
/// the keys name, T_base_camera, fps, source, sim; every key below `source:` and `sim:` must be
/// a source.* or sim.* key among `known` (load_config's table). Errors name the file and the
/// entry's key ("cameras[1].fov").
void check_camera_entries(const YAML::Node& root, const std::string& where, const std::set<std::string>& known);

/// The names of `root`'s entries, in order (empty without `cameras:`). After check_camera_entries.
std::vector<std::string> camera_names(const YAML::Node& root);

/// Lays the entry named `camera` of `root`'s list over the top-level keys of `tree` (`root`
/// itself or a copy of it, or of the file before the --set overrides): T_base_camera over
/// camera.T_base_camera, fps over sim.fps (source.fps too for a realsense camera), and each key
/// of its source: and sim: maps over the source.* and sim.* key of the same path (the entry's
/// source type: its own source.type, else `root`'s). A name that is not an entry is a
/// ConfigError listing the entries; a configuration without `cameras:` too. After
/// check_camera_entries.
void lay_camera_over(YAML::Node& tree, const YAML::Node& root, const std::string& camera, const std::string& where);

/// The typed read of a whole tree (load_config's table): what one entry's values are read with.
using ReadTree = std::function<Config(const YAML::Node& tree)>;

/// Config::cameras: each entry of `root` laid over a copy of `root` and read as a whole with
/// `read_tree`, so that an entry's values are checked as the top-level keys are and its defaults
/// are the top-level ones. An error in an entry names it. After check_camera_entries.
std::vector<CameraEntry> read_camera_entries(const YAML::Node& root, const std::string& where,
                                             const ReadTree& read_tree);

/// Records `cameras` as a key (its value goes into the effective configuration as written),
/// reads `cell.workspace_base` and `cell.voxel_m` into config.cell.grid (enabled when there are
/// cameras) and `sim.epoch` into config.sim_epoch_ns. After foreground.workspace_base is read.
/// Keys absent from a configuration without cameras stay out of the effective configuration,
/// so that its hash is the one it had before these keys existed.
void read_cell(KeyReader& r, Config& c);

}  // namespace hrcsense::config_detail
