// SPDX-License-Identifier: Apache-2.0
// hrcsense config internals — typed reading of dotted keys from the merged YAML tree.
#pragma once

#include "hrcsense/config/config.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace hrcsense::config_detail {

/// Throws ConfigError "<where>: key '<key>': <what>".
[[noreturn]] void fail(const std::string& where, const std::string& key, const std::string& what);

/// The node at dotted `key` below `root`, or an undefined node when any part is missing.
/// Never modifies `root` (yaml-cpp's non-const operator[] would insert).
YAML::Node find_path(const YAML::Node& root, const std::string& key);

/// Sets dotted `key` below `root` to `value`, creating maps on the way; a non-map value on
/// the way is replaced by a map. Returns false if `key` has an empty segment.
bool set_path(YAML::Node& root, const std::string& key, const YAML::Node& value);

/// Shortest decimal text that reads back as the same float (so 0.1F prints as 0.1).
std::string float_text(float value);
/// Same for double.
std::string double_text(double value);

/// "" for a number written plainly; for one with a leading zero ("017", "-00", "08e1") the
/// message why it is refused: YAML 1.1 reads 017 as octal (15), YAML 1.2 as decimal (17), and
/// yaml-cpp itself does both (15 for an integer key, 17 for a real one). Plain 0, 0.5 and 00.5
/// (the same in both) pass.
std::string leading_zero_problem(const std::string& scalar);

/// True when `value` is finite and within a float's range, so that the cast to float is defined
/// and gives a finite number (a double beyond FLT_MAX would become inf).
bool fits_float(double value);

/// Positions in the base frame (camera, robot points and capsules) lie within a kilometre of
/// the origin: a cell is metres across, and squared distances (1e6 m²) stay far from a float's
/// range.
inline constexpr float kMaxCoordinateM = 1000.0F;

/// Lower bound a number must respect.
enum class Bound { any, non_negative, positive };

/// Reads typed keys from the merged configuration tree. Each read records the key as known
/// (for the unknown-key check) and writes the value in effect, given or default, into the
/// effective tree (for canonical_yaml). A missing key leaves the default untouched.
class KeyReader {
 public:
  /// `where` names the file in error messages.
  KeyReader(YAML::Node root, std::string where);

  void text(const std::string& key, std::string& value);
  /// A string that must be one of `allowed`.
  void choice(const std::string& key, std::string& value, const std::vector<std::string>& allowed);
  /// A closed choice: the name of one of `values` (as `name` spells it), turned into that value
  /// here, once; the effective configuration gets the name back.
  template <class Choice, size_t N>
  void choice(const std::string& key, Choice& value, const Choice (&values)[N], const char* (*name)(Choice)) {
    std::string text = name(value);
    std::vector<std::string> allowed;
    for (const Choice option : values) allowed.emplace_back(name(option));
    choice(key, text, allowed);
    for (const Choice option : values) {
      if (text == name(option)) value = option;
    }
  }
  void flag(const std::string& key, bool& value);
  void integer(const std::string& key, int64_t& value, int64_t min, int64_t max);
  void integer(const std::string& key, int& value, int min, int max);
  void integer(const std::string& key, uint64_t& value);
  /// A finite number respecting `bound` and at most `max`.
  void number(const std::string& key, double& value, Bound bound,
              double max = std::numeric_limits<double>::max());
  /// The same, checked as the float it becomes (1e39 would become inf, 1e-46 a zero that
  /// slipped past "> 0"); `max` defaults to a float's largest.
  void number(const std::string& key, float& value, Bound bound, float max = std::numeric_limits<float>::max());
  /// A finite number in [min, max]; `unit` follows the range in the message (" s").
  void number_in(const std::string& key, double& value, double min, double max, const std::string& unit);
  /// A list of exactly three numbers [x, y, z], each a float with |x| <= max_abs.
  void vec3(const std::string& key, Eigen::Vector3f& value, float max_abs = std::numeric_limits<float>::max());
  /// A list of [x, y, z] lists, each number a float with |x| <= max_abs.
  void vec3_list(const std::string& key, std::vector<Eigen::Vector3f>& value,
                 float max_abs = std::numeric_limits<float>::max());
  /// A list of finite numbers; `size` > 0 demands exactly that many (an empty list is always
  /// allowed).
  void number_list(const std::string& key, std::vector<double>& value, size_t size);
  /// A structured value parsed by the caller: records the key and returns its node
  /// (undefined when absent). The caller records the effective value with `set_effective`.
  YAML::Node raw(const std::string& key);
  void set_effective(const std::string& key, const YAML::Node& value);

  /// Throws ConfigError naming the file and `key`.
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  /// Throws ConfigError naming the file and both keys of a check between two keys (either may
  /// be the one the user got wrong): "<where>: keys 'a' and 'b': <what>".
  [[noreturn]] void fail_pair(const std::string& key_a, const std::string& key_b, const std::string& what) const;

  const std::set<std::string>& known() const { return known_; }
  const YAML::Node& effective() const { return effective_; }
  const std::string& where() const { return where_; }

 private:
  YAML::Node lookup(const std::string& key);
  double scalar_number(const std::string& key, const YAML::Node& node) const;
  float scalar_float(const std::string& key, const YAML::Node& node, float max_abs) const;

  YAML::Node root_;
  YAML::Node effective_;
  std::string where_;
  std::set<std::string> known_;
};

/// Reads the simulator's D435 effect keys (`sim.left_band`, `sim.edge_dropout`, ...; see
/// docs/SIMULATOR.md) into `sim`.
void read_sim_effects(KeyReader& r, SimParams& sim);

/// Reads the live camera's keys (`source.serial`, `source.width`, `source.height`, `source.fps`,
/// `source.color.*`, `source.options.*`, `source.settle_frames`) into `source`.
void read_camera_source(KeyReader& r, SourceConfig& source);

/// Reads `filters.preset`, `filters.order` and `filters.<block>.<option>` (docs/CONFIG.md) into
/// `config.filters_preset` and `config.pipeline.filters`; a value outside the SDK's range is an
/// error naming the key and the range.
void read_filters(KeyReader& r, Config& config);

/// Reads the robot's stopping data (`safety.stopping_table`, `safety.stopping_limits`,
/// `safety.stopping_data_confirmed`) into config.pipeline.safety.ssm (src/config/safety_config.cpp).
void read_stopping_data(KeyReader& r, Config& config);

/// In `safety.mode: ssm`, after every key is read: the bounds that keep each watchdog on
/// (docs/CONFIG.md, "Limits in ssm mode"), the refusal to start a live cell without stopping
/// data unless confirmed, and config.warnings.
void check_ssm_mode(KeyReader& r, Config& config);

/// Reads `scene.objects` (a list of objects, see docs/CONFIG.md) into a Scene.
/// `key` is the list's key, used to name items in errors ("scene.objects[1].shapes[0]").
Scene read_scene_objects(const YAML::Node& objects, const std::string& where, const std::string& key);
/// The scene in the same schema, normalised (defaults spelt out, numbers in shortest form),
/// for the canonical configuration.
YAML::Node scene_objects_node(const Scene& scene);

}  // namespace hrcsense::config_detail
