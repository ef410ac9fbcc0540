// SPDX-License-Identifier: Apache-2.0
// R1's property over the configuration: for every numeric key, each hostile value (NaN, ±inf,
// ±1e39, 1e-39, -1, 0) is either refused with a ConfigError naming the key, or gives a run in
// which no frame says `run` while it has foreground without a contact, fewer valid pixels after
// the filters than safety.min_valid_share, or a non-finite value in its result.
//
// The cell: the thesis box (1.22 m from the robot point, so the unharmed run says `run`,
// "clear", with foreground) entering right after 3 learning frames, at 424x240.

#include "../support/scenes.hpp"
#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/pipeline.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

namespace fs = std::filesystem;

constexpr int64_t kFramesPerValue = 7;
const char* const kHostile[] = {".nan", ".inf", "-.inf", "1e39", "-1e39", "1e-39", "-1", "0"};

// thesis-box.yaml with the box entering at frame 3 instead of 100.
std::string early_box_config() {
  std::ifstream in(test::scene_path("thesis-box.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string from = "first_frame: 100";
  const size_t at = yaml.find(from);
  if (at != std::string::npos) yaml.replace(at, from.size(), "first_frame: 3");
  const fs::path path = fs::temp_directory_path() / "hrcsense_hostile_values_thesis_box.yaml";
  std::ofstream(path) << yaml;
  return path.string();
}

const std::vector<std::string> kBase = {"sim.width=424", "sim.height=240", "background.frames=3", "sim.frames=20"};

// A key and, for list keys, the text of the list with `{}` where the hostile value goes.
struct NumericKey {
  std::string key;
  std::string pattern;  ///< e.g. "[{}, 0, 0]"; "{}" for a plain number
};

bool is_number(const YAML::Node& node) {
  double value = 0.0;
  return node.IsScalar() && YAML::convert<double>::decode(node, value);
}

std::string list_text(const YAML::Node& list, size_t hole) {
  std::string text = "[";
  for (size_t i = 0; i < list.size(); ++i) {
    if (i > 0) text += ", ";
    text += i == hole ? std::string("{}") : list[i].Scalar();
  }
  return text + "]";
}

// Every numeric key of the effective configuration (scene.objects, a structured list whose
// members have their own tests in tests/config, is left out).
void collect(const YAML::Node& node, const std::string& key, std::vector<NumericKey>& out) {
  if (key == "scene.objects") return;
  if (node.IsMap()) {
    for (const auto& entry : node) {
      collect(entry.second, key.empty() ? entry.first.Scalar() : key + "." + entry.first.Scalar(), out);
    }
  } else if (is_number(node)) {
    out.push_back({key, "{}"});
  } else if (node.IsSequence() && node.size() > 0 && is_number(node[0])) {
    for (size_t i = 0; i < node.size(); ++i) out.push_back({key, list_text(node, i)});
  } else if (node.IsSequence() && node.size() > 0 && node[0].IsSequence()) {  // [[x, y, z], ...]
    for (size_t i = 0; i < node[0].size(); ++i) out.push_back({key, "[" + list_text(node[0], i) + "]"});
  }
}

std::string with_value(const std::string& pattern, const char* value) {
  std::string text = pattern;
  text.replace(text.find("{}"), 2, value);
  return text;
}

struct Keeping : Sink {
  std::vector<FrameResult> results;
  void header(const RunHeader& /*header*/) override {}
  void frame(const FrameResult& result) override { results.push_back(result); }
  void summary(const RunSummary& /*summary*/) override {}
};

bool finite_result(const FrameResult& r) {
  const Contact& c = r.contact;
  return std::isfinite(r.verdict.speed_scale) && std::isfinite(r.verdict.protective_distance_m) &&
         (!c.valid || (std::isfinite(c.distance_m) && c.closest_base.allFinite() && c.closest_camera.allFinite() &&
                       c.closest_robot_base.allFinite()));
}

// What a run must never do; empty when it did nothing wrong.
std::string unsafe_run(const FrameResult& r, float min_valid_share) {
  if (r.verdict.state != VerdictState::run) return {};
  if (r.foreground_points > 0 && !r.contact.valid) return "run with foreground but no contact";
  if (r.valid_share < min_valid_share) return "run below min_valid_share";
  if (!finite_result(r)) return "run with a non-finite value";
  return {};
}

TEST(HostileValues, EveryNumericKeyIsRefusedOrFailsSafe) {
  const std::string path = early_box_config();
  const Config defaults = load_config(path, kBase);
  std::vector<NumericKey> keys;
  collect(YAML::Load(defaults.canonical_yaml), "", keys);
  ASSERT_GT(keys.size(), 50U);  // the schema has well over fifty numeric keys and list entries

  // The unharmed run says `run` with foreground: so a hostile value has something to break.
  {
    std::unique_ptr<Source> source = make_source(defaults);
    Pipeline pipeline(defaults.pipeline);
    FixedRobotState robot_states(defaults.robot_state.joints_rad);
    Keeping sink;
    RunOptions options;
    options.max_frames = kFramesPerValue;
    run_pipeline(*source, robot_states, pipeline, sink, options, RunHeader{});
    ASSERT_GE(sink.results.size(), 5U);
    EXPECT_EQ(sink.results[4].verdict.state, VerdictState::run) << sink.results[4].verdict.reason;
    EXPECT_GT(sink.results[4].foreground_points, 0U);
  }

  int refused = 0, ran = 0;
  for (const NumericKey& k : keys) {
    for (const char* value : kHostile) {
      const std::string assignment = k.key + "=" + with_value(k.pattern, value);
      std::vector<std::string> overrides = kBase;
      overrides.push_back(assignment);
      Config config;
      try {
        config = load_config(path, overrides);
      } catch (const ConfigError& e) {
        ++refused;
        EXPECT_NE(std::string(e.what()).find(k.key), std::string::npos) << assignment << ": " << e.what();
        continue;
      }
      ++ran;
      Keeping sink;
      try {
        std::unique_ptr<Source> source = make_source(config);
        Pipeline pipeline(config.pipeline);
        FixedRobotState robot_states(config.robot_state.joints_rad);
        RunOptions options;
        options.max_frames = kFramesPerValue;
        run_pipeline(*source, robot_states, pipeline, sink, options, RunHeader{});
      } catch (const std::exception& e) {
        ADD_FAILURE() << assignment << ": accepted by config, then failed outside it: " << e.what();
        continue;
      }
      for (const FrameResult& r : sink.results) {
        const std::string problem = unsafe_run(r, config.pipeline.safety.min_valid_share);
        EXPECT_TRUE(problem.empty()) << assignment << ": frame " << r.frame << ": " << problem;
      }
    }
  }
  RecordProperty("refused", refused);
  RecordProperty("ran", ran);
  std::printf("hostile values: %zu keys x %zu values: %d refused by config, %d ran\n", keys.size(),
              std::size(kHostile), refused, ran);
}

}  // namespace
}  // namespace hrcsense
