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

/// Parses YAML text strictly. Beyond syntax errors, these are ConfigErrors too, because a YAML
/// reader would accept them and silently use something else than what was written: a second
/// document, a key given twice in one map at any depth (yaml-cpp keeps the first, so an override
/// appended to a file would be ignored), a key that is not a plain scalar (a list, map, alias or
/// nothing), and a tag other than YAML's standard ones (!!str, !!int, !!float, !!bool, !!null,
/// !!map, !!seq, and the untagged `!`). `where` starts every message; with `file_positions`
/// it is a file name and gets ":line:column". `key_prefix` goes before key paths in messages
/// ("" for a file, the dotted key for a --set value).
YAML::Node parse_yaml_strict(const std::string& text, const std::string& where, const std::string& key_prefix,
                             bool file_positions);

/// Reads and parses a YAML file with parse_yaml_strict. A missing file, or one that is not a
/// regular file (a directory; a FIFO, which would block the open forever), is a ConfigError
/// naming the file; `what` names the kind of file in the message ("configuration file", ...).
/// The configuration, robot description files and everything read through them share it.
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
  /// A number: finite and within a float's range (every number of these files ends up in a
  /// float somewhere, so the cast is safe), not written with an ambiguous leading zero.
  double number(const YAML::Node& node, const std::string& key) const;
  Eigen::Vector3d vec3(const YAML::Node& node, const std::string& key) const;
  /// As vec3, in float (safe: number() bounds every component to a float's range).
  Eigen::Vector3f vec3f(const YAML::Node& node, const std::string& key) const { return vec3(node, key).cast<float>(); }
};

}  // namespace hrcsense::config_detail
