// SPDX-License-Identifier: Apache-2.0
// S2's configuration: the robot's stopping data (a table, the robot's own limits), the refusal
// to start a live ssm cell without them, the warnings, source.latency_s's default per source
// type, the unknown-space policy against S_p, and the bounds ssm mode puts on the watchdogs.
#include "config_test_util.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

bool warns(const Config& config, const std::string& needle) {
  for (const std::string& warning : config.warnings) {
    if (warning.find(needle) != std::string::npos) return true;
  }
  return false;
}

constexpr const char* kTable = R"(safety:
  mode: ssm
  stopping_table:
    - {speed_mps: 0.5, distance_m: 0.10, time_s: 0.30}
    - {speed_mps: 1.0, distance_m: 0.30, time_s: 0.45}
)";

TEST(StoppingDataConfig, TableIsReadInOrderAndNamedInTheHeader) {
  const TempDir dir;
  const Config config = load_config(dir.write("table.yaml", kTable), {});
  const SsmParams& ssm = config.pipeline.safety.ssm;
  ASSERT_EQ(ssm.stopping_table.size(), 2U);
  EXPECT_FLOAT_EQ(ssm.stopping_table[1].speed_mps, 1.0F);
  EXPECT_FLOAT_EQ(ssm.stopping_table[1].distance_m, 0.30F);
  EXPECT_DOUBLE_EQ(ssm.stopping_table[1].time_s, 0.45);
  EXPECT_EQ(ssm.stopping_data, StoppingData::table);
  EXPECT_FALSE(warns(config, "stopping data"));
  // The effective configuration keeps the table, and reads back to the same.
  const Config again = load_config(dir.write("again.yaml", config.canonical_yaml), {});
  EXPECT_EQ(again.pipeline.safety.ssm.stopping_table.size(), 2U);
  EXPECT_EQ(config_hash(again), config_hash(config));
}

TEST(StoppingDataConfig, BadTablesNameTheRow) {
  const std::string base = "safety.stopping_table=";
  expect_config_error("", {base + "[{speed_mps: 1.0, distance_m: 0.3, time_s: 0.4}, {speed_mps: 0.5, distance_m: 0.4, time_s: 0.5}]"},
                      {"safety.stopping_table[1].speed_mps", "increasing"});
  expect_config_error("", {base + "[{speed_mps: 0.5, distance_m: 0.3, time_s: 0.4}, {speed_mps: 1.0, distance_m: 0.2, time_s: 0.5}]"},
                      {"safety.stopping_table[1]", "not to fall"});
  expect_config_error("", {base + "[{speed_mps: 0.5, distance_m: 0.3, time: 0.4}]"}, {"safety.stopping_table[0].time", "unknown field"});
  expect_config_error("", {base + "[{speed_mps: 0, distance_m: 0.3, time_s: 0.4}]"}, {"safety.stopping_table[0].speed_mps", "> 0"});
  expect_config_error("", {base + "[{speed_mps: 0.5, distance_m: -1, time_s: 0.4}]"}, {"safety.stopping_table[0].distance_m"});
  expect_config_error("", {base + "{speed_mps: 0.5}"}, {"safety.stopping_table", "list"});
  expect_config_error("", {base + "[{speed_mps: 0.5, distance_m: 0.3, time_s: 0.4}]", "safety.stopping_limits={distance_m: 0.4, time_s: 0.5}"},
                      {"'safety.stopping_table'", "'safety.stopping_limits'"});
}

TEST(StoppingDataConfig, LimitsAreTheRobotsOwn) {
  const Config config = load_config("", {"safety.mode=ssm", "safety.stopping_limits={distance_m: 0.4, time_s: 0.6}"});
  EXPECT_EQ(config.pipeline.safety.ssm.stopping_data, StoppingData::limits);
  EXPECT_FLOAT_EQ(config.pipeline.safety.ssm.stopping_limit_distance_m, 0.4F);
  EXPECT_DOUBLE_EQ(config.pipeline.safety.ssm.stopping_limit_time_s, 0.6);
  expect_config_error("", {"safety.stopping_limits={distance_m: 0.4}"}, {"safety.stopping_limits.time_s"});
  expect_config_error("", {"safety.stopping_limits={distance_m: 0, time_s: 0.5}"}, {"safety.stopping_limits.distance_m"});
}

// A live robot state (rtde, udp_json) or a controller link in ssm mode without stopping data is
// refused, naming the keys; confirmed, it loads with the warning; simulated and recorded cells
// load with the warning; zones mode never needs stopping data.
TEST(StoppingDataConfig, LiveSsmCellWithoutStoppingDataIsRefusedUnlessConfirmed) {
  expect_config_error("", {"safety.mode=ssm", "robot.state.source=udp_json"},
                      {"'safety.stopping_table'", "'robot.state.source'", "stopping_data_confirmed"});
  expect_config_error("", {"safety.mode=ssm", "robot.state.source=rtde", "robot.state.host=127.0.0.1"},
                      {"'safety.stopping_table'", "'robot.state.source'"});
  expect_config_error("", {"safety.mode=ssm", "link.udp.address=127.0.0.1:30020"}, {"'safety.stopping_table'", "'link'"});
  const Config confirmed =
      load_config("", {"safety.mode=ssm", "robot.state.source=udp_json", "safety.stopping_data_confirmed=true"});
  EXPECT_TRUE(confirmed.pipeline.safety.ssm.stopping_data_confirmed);
  EXPECT_FALSE(warns(confirmed, "stopping data"));
  const Config with_limits =
      load_config("", {"safety.mode=ssm", "robot.state.source=udp_json", "safety.stopping_limits={distance_m: 0.4, time_s: 0.6}"});
  EXPECT_TRUE(with_limits.warnings.empty());
  const Config simulated = load_config("", {"safety.mode=ssm"});
  EXPECT_TRUE(warns(simulated, "without the robot's stopping data"));
  EXPECT_EQ(simulated.pipeline.safety.ssm.stopping_data, StoppingData::default_time);
  const Config zones = load_config("", {"robot.state.source=udp_json", "link.udp.address=127.0.0.1:30020"});
  EXPECT_FALSE(warns(zones, "stopping data"));
}

TEST(StoppingDataConfig, FixedStateWithAnArmWarnsInSsmMode) {
  const std::string joints = "robot.joints_rad=[0, -1.57, 0, -1.57, 0, 0]";
  const Config arm = load_config("", {"safety.mode=ssm", "robot.model=ur5", joints});
  EXPECT_TRUE(warns(arm, "robot.state.source fixed with an arm"));
  EXPECT_FALSE(warns(load_config("", {"safety.mode=ssm"}), "robot.state.source fixed"));  // points
  EXPECT_FALSE(warns(load_config("", {"robot.model=ur5", joints}), "robot.state.source fixed"));  // zones
}

TEST(LatencyConfig, SourceLatencyDefaultsPerSourceTypeAndReachesTr) {
  EXPECT_EQ(load_config("", {}).source.latency_s, 0.0);  // the simulator renders at its stamp
  const Config camera = load_config("", {"source.type=realsense"});
  EXPECT_DOUBLE_EQ(camera.source.latency_s, kCameraLatencyS);
  EXPECT_DOUBLE_EQ(camera.pipeline.safety.ssm.source_latency_s, kCameraLatencyS);
  EXPECT_DOUBLE_EQ(load_config("", {"source.type=ros2"}).source.latency_s, kCameraLatencyS);
  EXPECT_DOUBLE_EQ(load_config("", {"source.type=realsense", "source.latency_s=0.05"}).pipeline.safety.ssm.source_latency_s,
                   0.05);
  expect_config_error("", {"source.latency_s=-0.01"}, {"source.latency_s"});
  EXPECT_DOUBLE_EQ(load_config("", {}).pipeline.safety.ssm.receiver_timeout_s, 0.2);
  EXPECT_DOUBLE_EQ(load_config("", {"safety.receiver_timeout_s=0.1"}).pipeline.safety.ssm.receiver_timeout_s, 0.1);
  expect_config_error("", {"safety.receiver_timeout_s=-1"}, {"safety.receiver_timeout_s"});
}

TEST(UnknownPolicyConfig, StopWithinProtectiveIsAPolicy) {
  EXPECT_EQ(load_config("", {"safety.unknown_policy=stop_within_protective"}).pipeline.safety.unknown_policy,
            SafetyParams::UnknownPolicy::stop_within_protective);
  expect_config_error("", {"safety.unknown_policy=stop_somewhere"}, {"safety.unknown_policy", "stop_within_protective"});
}

// In ssm mode no value may switch a watchdog or a term off; zones mode keeps the wider ranges.
TEST(SsmLimitsConfig, ValuesThatSwitchAWatchdogOffAreRefusedInSsmMode) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"safety.max_frame_age_s=2", "safety.max_frame_age_s"},
      {"safety.min_valid_share=0.01", "safety.min_valid_share"},
      {"safety.max_envelope_invalid_share=0.95", "safety.max_envelope_invalid_share"},
      {"safety.human_speed_mps=1.0", "safety.human_speed_mps"},
      {"safety.human_speed_near_mps=1.8", "safety.human_speed_near_mps"},
      {"robot.state.max_age_s=0.2", "robot.state.max_age_s"},
  };
  for (const auto& [set, key] : cases) {
    expect_config_error("", {"safety.mode=ssm", set}, {"'" + key + "'", "ssm"});
    EXPECT_NO_THROW((void)load_config("", {set})) << set;  // zones mode
  }
  // At the bounds: accepted.
  EXPECT_NO_THROW((void)load_config("", {"safety.mode=ssm", "safety.max_frame_age_s=1", "safety.min_valid_share=0.05",
                                         "safety.max_envelope_invalid_share=0.9", "robot.state.max_age_s=0.1"}));
}

}  // namespace
}  // namespace hrcsense
