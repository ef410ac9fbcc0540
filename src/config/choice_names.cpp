// SPDX-License-Identifier: Apache-2.0
// hrcsense config — the names of the closed choices (config.hpp): the one place each name is
// spelt, for the reader (load_config turns a name into its enum) and for every message,
// header and effective configuration that prints it.
#include "hrcsense/config/config.hpp"

namespace hrcsense {

const char* source_type_name(SourceType type) {
  switch (type) {
    case SourceType::sim: return "sim";
    case SourceType::folder: return "folder";
    case SourceType::bag: return "bag";
    case SourceType::realsense: return "realsense";
    case SourceType::ros2: return "ros2";
  }
  return "unknown";
}

const char* udp_format_name(UdpFormat format) {
  switch (format) {
    case UdpFormat::binary: return "binary";
    case UdpFormat::json: return "json";
  }
  return "unknown";
}

const char* rtde_write_name(RtdeWrite write) {
  switch (write) {
    case RtdeWrite::off: return "off";
    case RtdeWrite::speed_slider: return "speed_slider";
    case RtdeWrite::input_register: return "register";
  }
  return "unknown";
}

const char* robot_model_name(RobotModelType model) {
  switch (model) {
    case RobotModelType::points: return "points";
    case RobotModelType::custom: return "custom";
    case RobotModelType::ur5:
    case RobotModelType::ur5e:
    case RobotModelType::ur10e: return builtin_robot(*builtin_arm_of(model)).name.c_str();
  }
  return "unknown";
}

std::optional<BuiltinArm> builtin_arm_of(RobotModelType model) {
  switch (model) {
    case RobotModelType::ur5: return BuiltinArm::ur5;
    case RobotModelType::ur5e: return BuiltinArm::ur5e;
    case RobotModelType::ur10e: return BuiltinArm::ur10e;
    case RobotModelType::points:
    case RobotModelType::custom: return std::nullopt;
  }
  return std::nullopt;
}

const char* record_on_error_name(RecordOnError on_error) {
  switch (on_error) {
    case RecordOnError::continue_run: return "continue";
    case RecordOnError::stop_run: return "stop";
  }
  return "unknown";
}

const char* speed_scaling_unit_name(SpeedScalingUnit unit) {
  return unit == SpeedScalingUnit::percent ? "percent" : "fraction";
}

}  // namespace hrcsense
