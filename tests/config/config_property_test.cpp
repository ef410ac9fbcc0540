// SPDX-License-Identifier: Apache-2.0
// A property over every numeric configuration key, found in the effective configuration of
// the defaults (list entries one by one): each hostile value (NaN, ±inf, ±1e39, 1e-39, -1, 0)
// is either refused with a one-line ConfigError naming the key, or loads into a configuration
// whose stage parameters are all finite. Which keys accept which values is printed, and checked
// against a table worked out by hand from docs/CONFIG.md for the keys that matter most.
// (tests/acceptance/hostile_values_test.cpp runs the pipeline on the accepted values.)
#include "config_test_util.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

const std::vector<std::string> kHostile = {".nan", ".inf", "-.inf", "1e39", "-1e39", "1e-39", "-1", "0"};

/// One numeric value of the configuration: its key, and how to write an override that puts a
/// value in its place (`pattern` with "@" where the value goes: "@", or "[0, @, 0]").
struct NumericKey {
  std::string key;
  std::string pattern;
  std::string name;  ///< for the table: the key, with the entry's index for lists
};

bool is_number(const YAML::Node& node) {
  double value = 0.0;
  return node.IsScalar() && YAML::convert<double>::decode(node, value);
}

/// `list` written in flow style, with entry `hole` replaced by "@".
std::string flow_with_hole(const YAML::Node& list, size_t hole) {
  std::string text = "[";
  for (size_t i = 0; i < list.size(); ++i) text += (i > 0 ? ", " : "") + (i == hole ? std::string("@") : list[i].Scalar());
  return text + "]";
}

void collect(const YAML::Node& node, const std::string& key, std::vector<NumericKey>& out) {
  if (node.IsMap()) {
    for (const auto& entry : node) collect(entry.second, key.empty() ? entry.first.Scalar() : key + "." + entry.first.Scalar(), out);
  } else if (is_number(node)) {
    out.push_back({key, "@", key});
  } else if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) {
      const std::string index = "[" + std::to_string(i) + "]";
      if (is_number(node[i])) {
        out.push_back({key, flow_with_hole(node, i), key + index});
      } else if (node[i].IsSequence()) {  // a list of [x, y, z]: one entry of one point at a time
        for (size_t j = 0; j < node[i].size(); ++j) {
          std::string text = "[";
          for (size_t k = 0; k < node.size(); ++k) {
            text += (k > 0 ? ", " : "") + (k == i ? flow_with_hole(node[i], j) : flow_with_hole(node[k], node[k].size()));
          }
          out.push_back({key, text + "]", key + index + "[" + std::to_string(j) + "]"});
        }
      }
    }
  }
}

/// Every float and double the stages take from the configuration; "" when all are finite,
/// else the first one that is not.
std::string non_finite(const Config& c) {
  const PipelineParams& p = c.pipeline;
  if (!p.T_base_camera.matrix().allFinite()) return "T_base_camera";
  for (const Capsule& capsule : fixed_robot_model(c).capsules) {
    if (!capsule.a.allFinite() || !capsule.b.allFinite() || !std::isfinite(capsule.radius_m)) return "robot capsule";
  }
  const std::map<std::string, double> values = {
      {"safety.slow", p.safety.slow_distance_m}, {"safety.stop", p.safety.stop_distance_m},
      {"safety.age", p.safety.max_frame_age_s}, {"safety.share", p.safety.min_valid_share},
      {"fg.k_sigma", p.foreground.k_sigma}, {"fg.margin", p.foreground.min_margin_m},
      {"fg.object", p.foreground.min_object_mm}, {"bg.k_sigma", p.background.moving_k_sigma},
      {"bg.spread", p.background.moving_min_spread_m}, {"bg.share", p.background.max_moving_share},
      {"bg.valid", p.background.min_valid_ratio}, {"bg.noise", p.background.max_noise_per_z2},
      {"threshold.min", p.filters.threshold.min_m}, {"threshold.max", p.filters.threshold.max_m},
      {"spatial.alpha", p.filters.spatial.alpha}, {"temporal.alpha", p.filters.temporal.alpha},
      {"sim.fps", c.sim.fps}, {"sim.noise", c.sim.disparity_noise_px}, {"sim.baseline", c.sim.baseline_mm},
      {"sim.step", c.sim.disparity_step_px}, {"sim.correlated", c.sim.correlated_noise_px},
      {"source.baseline", c.source.stereo_baseline_mm}, {"padding", p.robot.padding_m}};
  for (const auto& [name, value] : values) {
    if (!std::isfinite(value)) return name;
  }
  if (!p.foreground.workspace_base.min.allFinite() || !p.foreground.workspace_base.max.allFinite()) return "workspace";
  if (!c.sim.color_translation_m.allFinite()) return "sim.color_translation_m";
  return {};
}

std::string accepted_text(const std::set<std::string>& accepted) {
  std::string text;
  for (const std::string& value : kHostile) {
    if (accepted.count(value) != 0) text += (text.empty() ? "" : " ") + value;
  }
  return text.empty() ? "-" : text;
}

TEST(ConfigProperty, EveryNumericKeyRefusesHostileValuesByNameOrStaysFinite) {
  const Config defaults = load_config("", {});
  std::vector<NumericKey> keys;
  collect(YAML::Load(defaults.canonical_yaml), "", keys);
  ASSERT_GE(keys.size(), 70U) << "the walk over the effective configuration found too few numbers";

  std::map<std::string, std::set<std::string>> accepted;  // by NumericKey::name
  size_t refused = 0;
  for (const NumericKey& k : keys) {
    for (const std::string& value : kHostile) {
      std::string text = k.pattern;
      text.replace(text.find('@'), 1, value);
      const std::string set = k.key + "=" + text;
      try {
        const Config c = load_config("", {set});
        EXPECT_EQ(non_finite(c), "") << set;
        accepted[k.name].insert(value);
      } catch (const ConfigError& e) {
        ++refused;
        const std::string message = e.what();
        EXPECT_NE(message.find("'" + k.key + "'"), std::string::npos) << set << ": " << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << set << ": not one line: " << message;
      }
    }
  }
  std::printf("config property: %zu numeric values x %zu hostile values: %zu refused\n", keys.size(), kHostile.size(),
              refused);
  for (const NumericKey& k : keys) std::printf("  %-44s accepts %s\n", k.name.c_str(), accepted_text(accepted[k.name]).c_str());

  // By hand, from the ranges in docs/CONFIG.md and the defaults the other keys keep. NaN, ±inf
  // and ±1e39 (beyond a float) are never accepted; 1e-39 is a positive (subnormal) float.
  const std::map<std::string, std::string> expected = {
      {"safety.stop_distance_m", "1e-39"},         // > 0 and <= slow (1.0)
      {"safety.slow_distance_m", "-"},             // >= stop (0.5)
      {"safety.max_frame_age_s", "-"},             // [0.001, 60] s
      {"safety.min_valid_share", "1e-39"},         // (0, 1]
      {"sim.fps", "-"},                            // [1, 1000]
      {"sim.frames", "-"},                         // integer >= 1
      {"sim.baseline_mm", "-"},                    // [1, 1000] mm
      {"source.stereo_baseline_mm", "0"},          // 0 or [1, 1000] mm
      {"source.seed", "0"},                        // integer >= 0
      {"sim.disparity_step_px", "0"},              // 0 or [1/64, 1]
      {"sim.disparity_noise_px", "1e-39 0"},       // [0, 10]
      {"camera.T_base_camera.translation_m[0]", "1e-39 -1 0"},
      {"camera.T_base_camera.rotation_rpy_deg[2]", "1e-39 -1 0"},
      {"robot.points_base[0][1]", "1e-39 -1 0"},
      {"robot.padding_m", "1e-39 0"},
      {"foreground.k_sigma", "1e-39"},
      {"foreground.min_margin_m", "1e-39 0"},
      {"foreground.workspace_base.min[0]", "1e-39 -1 0"},  // still <= max (1e9)
      {"filters.threshold.min", "1e-39 0"},        // [0, 16] and <= max (4)
      {"filters.threshold.max", "-"},              // >= min (0.1)
      {"filters.spatial.alpha", "-"},              // [0.25, 1]
      {"filters.temporal.alpha", "1e-39 0"},       // [0, 1]
      {"background.frames", "-"},                  // integer >= 1
      {"background.fill_radius_px", "0"},          // integer [0, 1000]
      {"proximity.threads", "-"},                  // 1 or 2
  };
  for (const auto& [name, values] : expected) {
    ASSERT_TRUE(std::any_of(keys.begin(), keys.end(), [&](const NumericKey& k) { return k.name == name; }))
        << name << " was not found in the effective configuration";
    EXPECT_EQ(accepted_text(accepted[name]), values) << name;
  }
}

}  // namespace
}  // namespace hrcsense
