// SPDX-License-Identifier: Apache-2.0
// hrcsense config — the robot's stopping data and the limits `safety.mode: ssm` puts on the
// other keys, so that no value switches a watchdog off (docs/CONFIG.md, docs/SAFETY.md).
#include "key_reader.hpp"

#include <string>

namespace hrcsense::config_detail {
namespace {

// A finite number ≥ 0 (> 0 where `positive`) from `map`'s field `name`; errors name key.name.
double stopping_number(const KeyReader& r, const YAML::Node& map, const std::string& key, const char* name,
                       bool positive) {
  const YAML::Node node = map[name];
  const std::string field = key + "." + name;
  double value = 0.0;
  if (!node.IsDefined() || !node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
    r.fail(field, "expected a number");
  }
  if (!fits_float(value) || value < 0.0 || (positive && value == 0.0) || value > 100.0) {
    r.fail(field, std::string("expected a number ") + (positive ? "> 0" : ">= 0") + " and <= 100, got " +
                      double_text(value));
  }
  return value;
}

void only_fields(const KeyReader& r, const YAML::Node& map, const std::string& key,
                 std::initializer_list<const char*> fields, const char* expected) {
  if (!map.IsMap()) r.fail(key, std::string("expected a map ") + expected);
  for (const auto& entry : map) {
    const std::string name = entry.first.as<std::string>();
    bool known = false;
    for (const char* field : fields) known = known || name == field;
    if (!known) r.fail(key + "." + name, std::string("unknown field; expected ") + expected);
  }
}

}  // namespace

void read_stopping_data(KeyReader& r, Config& config) {
  SsmParams& ssm = config.pipeline.safety.ssm;
  // safety.stopping_table: [{speed_mps, distance_m, time_s}, ...] in increasing speed.
  const std::string table_key = "safety.stopping_table";
  const YAML::Node table = r.raw(table_key);
  if (table.IsDefined() && !table.IsNull()) {
    if (!table.IsSequence()) r.fail(table_key, "expected a list of rows {speed_mps, distance_m, time_s}");
    ssm.stopping_table.clear();
    for (size_t i = 0; i < table.size(); ++i) {
      const std::string key = table_key + "[" + std::to_string(i) + "]";
      only_fields(r, table[i], key, {"speed_mps", "distance_m", "time_s"}, "{speed_mps, distance_m, time_s}");
      StoppingRow row;
      row.speed_mps = static_cast<float>(stopping_number(r, table[i], key, "speed_mps", true));
      row.distance_m = static_cast<float>(stopping_number(r, table[i], key, "distance_m", false));
      row.time_s = stopping_number(r, table[i], key, "time_s", false);
      if (!ssm.stopping_table.empty()) {
        // A faster stop that is shorter or quicker is a typo in the data, not a robot.
        const StoppingRow& before = ssm.stopping_table.back();
        if (!(row.speed_mps > before.speed_mps)) r.fail(key + ".speed_mps", "expected speeds in increasing order");
        if (row.distance_m < before.distance_m || row.time_s < before.time_s) {
          r.fail(key, "expected distance_m and time_s not to fall as the speed rises");
        }
      }
      ssm.stopping_table.push_back(row);
    }
  }
  YAML::Node rows(YAML::NodeType::Sequence);
  for (const StoppingRow& row : ssm.stopping_table) {
    YAML::Node node(YAML::NodeType::Map);
    node["speed_mps"] = float_text(row.speed_mps);
    node["distance_m"] = float_text(row.distance_m);
    node["time_s"] = double_text(row.time_s);
    rows.push_back(node);
  }
  r.set_effective(table_key, rows);

  // safety.stopping_limits: {distance_m, time_s}, the robot's own stopping limits.
  const std::string limits_key = "safety.stopping_limits";
  const YAML::Node limits = r.raw(limits_key);
  if (limits.IsDefined() && !limits.IsNull()) {
    only_fields(r, limits, limits_key, {"distance_m", "time_s"}, "{distance_m, time_s}");
    ssm.stopping_limit_distance_m = static_cast<float>(stopping_number(r, limits, limits_key, "distance_m", true));
    ssm.stopping_limit_time_s = stopping_number(r, limits, limits_key, "time_s", true);
  }
  YAML::Node limits_node;  // null: none given
  if (ssm.stopping_limit_distance_m > 0.0F) {
    limits_node["distance_m"] = float_text(ssm.stopping_limit_distance_m);
    limits_node["time_s"] = double_text(ssm.stopping_limit_time_s);
  }
  r.set_effective(limits_key, limits_node);
  if (!ssm.stopping_table.empty() && ssm.stopping_limit_distance_m > 0.0F) {
    r.fail_pair(table_key, limits_key, "give one of the two: the table already says how the robot stops");
  }
  ssm.stopping_data = !ssm.stopping_table.empty()           ? StoppingData::table
                      : ssm.stopping_limit_distance_m > 0.0F ? StoppingData::limits
                                                             : StoppingData::default_time;
  r.flag("safety.stopping_data_confirmed", ssm.stopping_data_confirmed);
}

void check_ssm_mode(KeyReader& r, Config& config) {
  const SafetyParams& safety = config.pipeline.safety;
  if (safety.mode != SafetyParams::Mode::ssm) return;
  const SsmParams& ssm = safety.ssm;
  // Values that would switch a watchdog or a term off (docs/CONFIG.md, "Limits in ssm mode").
  const auto at_most = [&r](const std::string& key, double value, double limit, const std::string& why) {
    if (value > limit) {
      r.fail(key, "at most " + double_text(limit) + " in safety.mode ssm (" + why + "), got " + double_text(value));
    }
  };
  const auto at_least = [&r](const std::string& key, double value, double limit, const std::string& why) {
    if (value < limit) {
      r.fail(key, "at least " + double_text(limit) + " in safety.mode ssm (" + why + "), got " + double_text(value));
    }
  };
  at_most("safety.max_frame_age_s", safety.max_frame_age_s, 1.0, "an older frame is no watchdog's business any more");
  at_least("safety.min_valid_share", safety.min_valid_share, 0.05, "below it a covered camera would say run");
  at_most("safety.max_envelope_invalid_share", config.pipeline.checks.max_envelope_invalid_share, 0.9,
          "above it an arm without depth would never stop");
  at_least("safety.human_speed_mps", ssm.human_speed_mps, 1.6, "ISO 13855's walking speed");
  at_least("safety.human_speed_near_mps", ssm.human_speed_near_mps, 2.0, "ISO 13855's hand-arm speed");
  at_least("safety.robot_max_speed_mps", ssm.robot_max_speed_mps, 0.1, "the arm's travel over an old state");
  at_most("robot.state.max_age_s", config.robot_state.history.max_age_s, 0.1,
          "an older joint state leaves the arm where it no longer is");

  const RobotStateOrigin state = config.robot_state.source;
  const bool live_state =
      state == RobotStateOrigin::rtde || state == RobotStateOrigin::udp_json || state == RobotStateOrigin::ros2;
  const bool controller_link = !config.link.udp_address.empty() || config.link.rtde_write != RtdeWrite::off;
  if (ssm.stopping_data == StoppingData::default_time && !ssm.stopping_data_confirmed) {
    const std::string what =
        "safety.mode ssm without the robot's stopping data: S_s comes from safety.robot_stop_time_s (" +
        double_text(ssm.robot_stop_time_s) +
        " s) in closed form, which underestimates a real arm's braking; give safety.stopping_table or "
        "safety.stopping_limits (docs/SAFETY.md, \"Stopping data\")";
    if (live_state || controller_link) {
      r.fail_pair("safety.stopping_table", live_state ? "robot.state.source" : "link",
                  what + ", or set safety.stopping_data_confirmed: true once the closed form is checked against "
                         "the robot");
    }
    config.warnings.push_back(what);
  }
  if (state == RobotStateOrigin::fixed && config.robot_model != RobotModelType::points) {
    config.warnings.push_back(
        "robot.state.source fixed with an arm (robot.model " + std::string(robot_model_name(config.robot_model)) +
        "): hrcsense takes the arm to stand at robot.joints_rad and never to move; with a moving arm S_r, S_s and "
        "the self-filter are wrong (use rtde, udp_json or sim)");
  }
}

}  // namespace hrcsense::config_detail
