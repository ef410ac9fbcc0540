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

  /// The one reader of waypoint lists (robot.trajectory's waypoints, a scene object's path):
  /// each item a map of `t_s` (seconds) and `value_key`, which `read_value(node, key, point)`
  /// reads into `point`. Times must be strictly increasing: two waypoints at one time would be
  /// a jump, which neither a person nor an arm can make, and the interpolation between them
  /// would divide by a zero interval (docs/CONFIG.md). `list` must be a sequence.
  template <class Waypoint, class ReadValue>
  std::vector<Waypoint> waypoints(const YAML::Node& list, const std::string& key, const std::string& value_key,
                                  ReadValue read_value) const {
    std::vector<Waypoint> out;
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string item = key + "[" + std::to_string(i) + "]";
      only_keys(list[i], item, {"t_s", value_key});
      Waypoint point;
      point.t_s = number(required(list[i], item, "t_s"), item + ".t_s");
      read_value(required(list[i], item, value_key), item + "." + value_key, point);
      if (!out.empty() && !(point.t_s > out.back().t_s)) {
        fail(item + ".t_s", "expected times strictly increasing (" + double_text(point.t_s) + " s after " +
                                double_text(out.back().t_s) + " s)");
      }
      out.push_back(point);
    }
    return out;
  }
};

}  // namespace hrcsense::config_detail
