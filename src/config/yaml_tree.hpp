// SPDX-License-Identifier: Apache-2.0
// hrcsense config — reading nested YAML (scenes, robot descriptions) with errors that name the
// file and the field's path in it; internal to src/config/.
#pragma once

#include "key_reader.hpp"

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace hrcsense::config_detail {

/// Parses a YAML file; a missing file or a syntax error is a ConfigError naming the file (and
/// line:column). `what` names the kind of file in the message ("configuration file", ...).
YAML::Node load_yaml_file(const std::string& path, const std::string& what);

/// Field access below one node of a file: every error names the file (`where`) and the field's
/// path, `prefix` + key, e.g. scene.objects[2].shapes[0].radius_m.
struct YamlTree {
  const std::string& where;
  const std::string& prefix;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  /// A map whose keys are all among `allowed`; anything else is an "unknown key" error.
  void only_keys(const YAML::Node& map, const std::string& key, const std::vector<std::string>& allowed) const;
  /// The member `name` of a map; undefined when it is missing or null (reading never inserts).
  YAML::Node child(const YAML::Node& map, const std::string& name) const;
  /// As child(), but a missing member is an error "key.name is required".
  YAML::Node required(const YAML::Node& map, const std::string& key, const std::string& name) const;
  double number(const YAML::Node& node, const std::string& key) const;
  Eigen::Vector3d vec3(const YAML::Node& node, const std::string& key) const;
  Eigen::Vector3f vec3f(const YAML::Node& node, const std::string& key) const { return vec3(node, key).cast<float>(); }
};

}  // namespace hrcsense::config_detail
