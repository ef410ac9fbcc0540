// SPDX-License-Identifier: Apache-2.0
// hrcsense config — reading YAML strictly, and nested YAML with errors that name the file and
// the field.
#include "yaml_tree.hpp"

#include "hrcsense/io/io.hpp"

#include <yaml-cpp/eventhandler.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

namespace hrcsense::config_detail {
namespace {

std::string joined(const std::string& key, const std::string& name) { return key.empty() ? name : key + "." + name; }

bool standard_tag(const std::string& tag) {
  // "?": a plain scalar or a collection without a tag; "!": a quoted scalar or the bare "!".
  if (tag.empty() || tag == "?" || tag == "!") return true;
  const std::string core = "tag:yaml.org,2002:";
  if (tag.compare(0, core.size(), core) != 0) return false;
  const std::string name = tag.substr(core.size());
  return name == "str" || name == "int" || name == "float" || name == "bool" || name == "null" || name == "map" ||
         name == "seq";
}

std::string shown_tag(const std::string& tag) {
  const std::string core = "tag:yaml.org,2002:";
  return tag.compare(0, core.size(), core) == 0 ? "!!" + tag.substr(core.size()) : tag;
}

// Follows yaml-cpp's parse events (linear in the text, whatever its aliases) and keeps, per open
// map or list, where the reader is; errors name the key path ("scene.objects[1].name").
class StrictChecker : public YAML::EventHandler {
 public:
  StrictChecker(const std::string& where, const std::string& prefix, bool positions)
      : where_(where), prefix_(prefix), positions_(positions) {}

  void OnDocumentStart(const YAML::Mark& mark) override {
    if (++documents_ > 1) fail(mark, "a second YAML document (after '---' or '...'); a file holds one configuration");
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { node(mark, "", nullptr, "nothing"); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { node(mark, "", nullptr, "an alias"); }
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t /*anchor*/,
                const std::string& value) override {
    node(mark, tag, &value, "");
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t /*anchor*/,
                       YAML::EmitterStyle::value /*style*/) override {
    open(mark, tag, false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t /*anchor*/,
                  YAML::EmitterStyle::value /*style*/) override {
    open(mark, tag, true);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Level {
    bool is_map = false;
    bool expect_key = true;                 ///< maps: the next node is a key
    std::string key;                        ///< maps: the key whose value is being read
    size_t index = 0;                       ///< lists: the item being read
    std::map<std::string, size_t> lines;    ///< maps: every key so far, with its line
  };

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& what) const {
    std::string at = where_;
    if (positions_ && !mark.is_null()) at += ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
    throw ConfigError(at + ": " + what);
  }

  std::string path() const {
    std::string out = prefix_;
    for (const Level& level : levels_) {
      if (level.is_map) {
        if (!level.key.empty()) out = joined(out, level.key);
      } else {
        out += "[" + std::to_string(level.index) + "]";
      }
    }
    return out;
  }

  bool at_key() const { return !levels_.empty() && levels_.back().is_map && levels_.back().expect_key; }

  void check_tag(const YAML::Mark& mark, const std::string& tag) const {
    if (standard_tag(tag)) return;
    const std::string key = path();
    fail(mark, "unknown tag '" + shown_tag(tag) + "'" + (key.empty() ? std::string() : " on key '" + key + "'") +
                   "; only YAML's standard tags (!!str, !!int, !!float, !!bool, !!null, !!map, !!seq) are understood");
  }

  // A scalar, null or alias: a key of the open map, or a value.
  void node(const YAML::Mark& mark, const std::string& tag, const std::string* scalar, const char* kind) {
    if (at_key()) {
      if (scalar == nullptr) fail(mark, std::string("a key that is ") + kind + " after '" + path() + "'; keys must be names");
      Level& level = levels_.back();
      level.key = *scalar;
      check_tag(mark, tag);
      const auto [it, fresh] = level.lines.emplace(*scalar, mark.line + 1);
      if (!fresh) {
        fail(mark, "duplicate key '" + path() + "' (first at line " + std::to_string(it->second) +
                       "); YAML readers silently keep only one of them");
      }
      level.expect_key = false;
      return;
    }
    check_tag(mark, tag);
    value_done();
  }

  void open(const YAML::Mark& mark, const std::string& tag, bool is_map) {
    if (at_key()) fail(mark, std::string("a key that is a ") + (is_map ? "map" : "list") + " after '" + path() + "'; keys must be names");
    check_tag(mark, tag);
    levels_.push_back(Level{is_map, true, {}, 0, {}});
  }

  void close() {
    levels_.pop_back();
    value_done();
  }

  void value_done() {
    if (levels_.empty()) return;
    Level& level = levels_.back();
    if (level.is_map) {
      level.expect_key = true;
    } else {
      ++level.index;
    }
  }

  const std::string& where_;
  const std::string& prefix_;
  bool positions_;
  int documents_ = 0;
  std::vector<Level> levels_;
};

}  // namespace

YAML::Node parse_yaml_strict(const std::string& text, const std::string& where, const std::string& key_prefix,
                             bool file_positions) {
  try {
    // Syntax first: yaml-cpp emits odd events for broken text ("[1, 2" opens a map) before it
    // notices, and the checker would report those instead of the syntax error.
    YAML::Node root = YAML::Load(text);
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    StrictChecker checker(where, key_prefix, file_positions);
    while (parser.HandleNextDocument(checker)) {
    }
    return root;
  } catch (const YAML::Exception& e) {
    if (!file_positions) throw ConfigError(where + ": the value is not valid YAML: " + e.msg);
    throw ConfigError(where + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                      ": YAML syntax error: " + e.msg);
  }
}

YAML::Node load_yaml_file(const std::string& path, const std::string& what) {
  const std::string problem = not_regular_file(path);
  if (!problem.empty()) throw ConfigError(path + ": cannot open " + what + ": " + problem);
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ConfigError(path + ": cannot open " + what);
  const std::string text{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
  return parse_yaml_strict(text, path, "", true);
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
  const std::string zero = node.IsScalar() ? leading_zero_problem(node.Scalar()) : std::string();
  if (!zero.empty()) fail(key, zero);
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !fits_float(value)) {
    fail(key, "expected a finite number within a float's range (|x| <= 3.4e38)" +
                  (node.IsScalar() ? ", got '" + node.Scalar() + "'" : std::string()));
  }
  return value;
}

Eigen::Vector3d YamlTree::vec3(const YAML::Node& node, const std::string& key) const {
  if (!node.IsSequence() || node.size() != 3) fail(key, "expected a list of 3 numbers [x, y, z]");
  return {number(node[0], key), number(node[1], key), number(node[2], key)};
}

}  // namespace hrcsense::config_detail
