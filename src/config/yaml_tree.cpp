// SPDX-License-Identifier: Apache-2.0
// hrcsense config — reading nested YAML with errors that name the file and the field.
#include "yaml_tree.hpp"

#include <cmath>
#include <fstream>

namespace hrcsense::config_detail {
namespace {

std::string joined(const std::string& key, const std::string& name) { return key.empty() ? name : key + "." + name; }

}  // namespace

YAML::Node load_yaml_file(const std::string& path, const std::string& what) {
  std::ifstream file(path);
  if (!file) throw ConfigError(path + ": cannot open " + what);
  try {
    return YAML::Load(file);
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                      ": YAML syntax error: " + e.msg);
  }
}

void YamlTree::fail(const std::string& key, const std::string& what) const {
  config_detail::fail(where, prefix + key, what);
}

void YamlTree::only_keys(const YAML::Node& map, const std::string& key,
                         const std::vector<std::string>& allowed) const {
  if (!map.IsMap()) fail(key, "expected a map");
  for (const auto& entry : map) {
    const std::string name = entry.first.Scalar();
    bool ok = false;
    for (const std::string& option : allowed) ok = ok || name == option;
    if (!ok) throw ConfigError(where + ": unknown key '" + prefix + joined(key, name) + "'");
  }
}

YAML::Node YamlTree::child(const YAML::Node& map, const std::string& name) const {
  const YAML::Node& const_map = map;  // const access never inserts
  YAML::Node node = const_map[name];
  if (!node.IsDefined() || node.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
  return node;
}

YAML::Node YamlTree::required(const YAML::Node& map, const std::string& key, const std::string& name) const {
  YAML::Node node = child(map, name);
  if (!node.IsDefined()) fail(joined(key, name), "is required");
  return node;
}

double YamlTree::number(const YAML::Node& node, const std::string& key) const {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    fail(key, "expected a number");
  }
  return value;
}

Eigen::Vector3d YamlTree::vec3(const YAML::Node& node, const std::string& key) const {
  if (!node.IsSequence() || node.size() != 3) fail(key, "expected a list of 3 numbers [x, y, z]");
  return {number(node[0], key), number(node[1], key), number(node[2], key)};
}

}  // namespace hrcsense::config_detail
