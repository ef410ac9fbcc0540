// SPDX-License-Identifier: Apache-2.0
// hrcsense config internals — the robot keys and the robot description format (docs/ROBOT.md).
#pragma once

#include "key_reader.hpp"

#include "hrcsense/robot.hpp"

#include <string>

namespace hrcsense::config_detail {

/// Reads the `robot.*` keys (model, description, points_base, padding_m, joints_rad,
/// base_frame) and builds config.pipeline.robot from them.
void read_robot(KeyReader& r, Config& config);

/// Reads a robot description from a YAML map. `where` names the file, `prefix` is put before
/// every field in errors ("" in a description file, "robot.description." inline).
RobotDescription read_robot_description(const YAML::Node& map, const std::string& where,
                                        const std::string& prefix);

/// The description in the same format, normalised (numbers in shortest form), for the
/// canonical configuration.
YAML::Node robot_description_node(const RobotDescription& description);

}  // namespace hrcsense::config_detail
