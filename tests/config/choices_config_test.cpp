// SPDX-License-Identifier: Apache-2.0
// The closed choices (source.type, robot.state.source, robot.model, robot.base_frame,
// proximity.backend, link.udp.format, link.rtde.write, record.on_error): each name in
// docs/CONFIG.md becomes its enum value once, in load_config, and the effective configuration
// spells the same name again, so that it reloads as the same choice with the same hash.
#include "config_test_util.hpp"

#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

// One name of a key: the overrides that make it valid (some choices need another key), and
// what the loaded Config must then hold, written out by hand from docs/CONFIG.md.
struct NamedChoice {
  std::vector<std::string> sets;
  std::function<bool(const Config&)> holds;
};

const std::string kJoints = "robot.joints_rad=[0, -1.57, 1.57, 0, 1.57, 0]";
const std::string kHost = "robot.state.host=192.0.2.10";

std::vector<NamedChoice> named_choices() {
  return {
      {{"source.type=sim"}, [](const Config& c) { return c.source.type == SourceType::sim; }},
      {{"source.type=folder"}, [](const Config& c) { return c.source.type == SourceType::folder; }},
      {{"source.type=bag"}, [](const Config& c) { return c.source.type == SourceType::bag; }},
      {{"source.type=realsense"}, [](const Config& c) { return c.source.type == SourceType::realsense; }},
      {{"source.type=ros2"}, [](const Config& c) { return c.source.type == SourceType::ros2; }},
      {{"robot.state.source=fixed"}, [](const Config& c) { return c.robot_state.source == RobotStateOrigin::fixed; }},
      {{"robot.state.source=rtde", kHost}, [](const Config& c) { return c.robot_state.source == RobotStateOrigin::rtde; }},
      {{"robot.state.source=udp_json"},
       [](const Config& c) { return c.robot_state.source == RobotStateOrigin::udp_json; }},
      {{"robot.state.source=recorded"},
       [](const Config& c) { return c.robot_state.source == RobotStateOrigin::recorded; }},
      {{"robot.state.source=ros2"}, [](const Config& c) { return c.robot_state.source == RobotStateOrigin::ros2; }},
      {{"robot.state.ros2.speed_scaling_unit=fraction"},
       [](const Config& c) { return c.robot_state.ros2.speed_scaling_unit == SpeedScalingUnit::fraction; }},
      {{"robot.model=points"}, [](const Config& c) { return c.robot_model == RobotModelType::points && !c.pipeline.robot.arm; }},
      {{"robot.model=ur5", kJoints},
       [](const Config& c) { return c.robot_model == RobotModelType::ur5 && c.pipeline.robot.arm->name == "ur5"; }},
      {{"robot.model=ur5e", kJoints},
       [](const Config& c) { return c.robot_model == RobotModelType::ur5e && c.pipeline.robot.arm->name == "ur5e"; }},
      {{"robot.model=ur10e", kJoints},
       [](const Config& c) { return c.robot_model == RobotModelType::ur10e && c.pipeline.robot.arm->name == "ur10e"; }},
      {{"robot.model=custom", kJoints, "robot.description=" + std::string(HRCSENSE_SOURCE_DIR) + "/config/robots/ur10e.yaml"},
       [](const Config& c) { return c.robot_model == RobotModelType::custom && c.pipeline.robot.arm->name == "ur10e"; }},
      {{"robot.base_frame=base"}, [](const Config& c) { return c.pipeline.robot.base_frame == BaseFrame::base; }},
      {{"robot.base_frame=base_link"}, [](const Config& c) { return c.pipeline.robot.base_frame == BaseFrame::base_link; }},
      {{"proximity.backend=brute"}, [](const Config& c) { return c.pipeline.backend == ProximityBackend::brute; }},
      {{"proximity.backend=kdtree"}, [](const Config& c) { return c.pipeline.backend == ProximityBackend::kdtree; }},
      {{"proximity.backend=octree"}, [](const Config& c) { return c.pipeline.backend == ProximityBackend::octree; }},
      {{"proximity.backend=auto"}, [](const Config& c) { return c.pipeline.backend == ProximityBackend::automatic; }},
      {{"link.udp.format=binary"}, [](const Config& c) { return c.link.udp_format == UdpFormat::binary; }},
      {{"link.udp.format=json"}, [](const Config& c) { return c.link.udp_format == UdpFormat::json; }},
      {{"link.rtde.write=off"}, [](const Config& c) { return c.link.rtde_write == RtdeWrite::off; }},
      {{"link.rtde.write=speed_slider", kHost},
       [](const Config& c) { return c.link.rtde_write == RtdeWrite::speed_slider; }},
      {{"link.rtde.write=register", kHost},
       [](const Config& c) { return c.link.rtde_write == RtdeWrite::input_register; }},
      {{"record.on_error=continue"}, [](const Config& c) { return c.record.on_error == RecordOnError::continue_run; }},
      {{"record.on_error=stop"}, [](const Config& c) { return c.record.on_error == RecordOnError::stop_run; }},
  };
}

TEST(ConfigChoices, EachNameBecomesItsValueAndReloadsAsTheSame) {
  TempDir dir;
  for (const NamedChoice& choice : named_choices()) {
    const std::string& given = choice.sets.front();
    const Config config = load_config("", choice.sets);
    EXPECT_TRUE(choice.holds(config)) << given;
    // The effective configuration names the choice as given: reloaded, it is the same choice.
    const Config reloaded = load_config(dir.write("effective.yaml", config.canonical_yaml), {});
    EXPECT_TRUE(choice.holds(reloaded)) << given;
    EXPECT_EQ(config_hash(reloaded), config_hash(config)) << given;
  }
}

TEST(ConfigChoices, NamesPrintAsTheConfigurationSpellsThem) {
  EXPECT_STREQ(source_type_name(SourceType::ros2), "ros2");
  EXPECT_STREQ(udp_format_name(UdpFormat::json), "json");
  EXPECT_STREQ(rtde_write_name(RtdeWrite::input_register), "register");
  EXPECT_STREQ(rtde_write_name(RtdeWrite::speed_slider), "speed_slider");
  EXPECT_STREQ(record_on_error_name(RecordOnError::continue_run), "continue");
  EXPECT_STREQ(robot_model_name(RobotModelType::ur10e), "ur10e");
  EXPECT_STREQ(robot_model_name(RobotModelType::custom), "custom");
  EXPECT_EQ(builtin_arm_of(RobotModelType::ur5e), BuiltinArm::ur5e);
  EXPECT_FALSE(builtin_arm_of(RobotModelType::points).has_value());
}

TEST(ConfigChoices, AnotherSpellingIsRefusedWithTheList) {
  // Names are exact: no case folding, no "register" for the slider.
  expect_config_error("", {"source.type=Bag"}, {"'source.type'", "expected one of sim, folder, bag, realsense, ros2", "'Bag'"});
  expect_config_error("", {"proximity.backend=Brute"}, {"'proximity.backend'", "brute, kdtree, octree, depth_space, auto"});
  expect_config_error("", {"link.udp.format=JSON"}, {"'link.udp.format'", "expected one of binary, json"});
  expect_config_error("", {"record.on_error=retry"}, {"'record.on_error'", "expected one of continue, stop"});
  expect_config_error("", {"robot.state.source=ros"},
                      {"'robot.state.source'", "expected one of fixed, sim, rtde, udp_json, recorded, ros2"});
  expect_config_error("", {"robot.state.ros2.speed_scaling_unit=percentage"},
                      {"'robot.state.ros2.speed_scaling_unit'", "expected one of percent, fraction"});
}

}  // namespace
}  // namespace hrcsense
