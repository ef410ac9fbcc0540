// SPDX-License-Identifier: Apache-2.0
// hrcsense — robot state names and the fixed state.
#include "hrcsense/robot_state.hpp"

namespace hrcsense {

const char* robot_state_origin_name(RobotStateOrigin origin) {
  switch (origin) {
    case RobotStateOrigin::fixed: return "fixed";
    case RobotStateOrigin::sim: return "sim";
    case RobotStateOrigin::rtde: return "rtde";
    case RobotStateOrigin::udp_json: return "udp_json";
    case RobotStateOrigin::recorded: return "recorded";
    case RobotStateOrigin::ros2: return "ros2";
  }
  return "unknown";
}

const char* robot_mode_name(int32_t robot_mode) {
  switch (robot_mode) {
    case -1: return "no_controller";
    case 0: return "disconnected";
    case 1: return "confirm_safety";
    case 2: return "booting";
    case 3: return "power_off";
    case 4: return "power_on";
    case 5: return "idle";
    case 6: return "backdrive";
    case 7: return "running";
    case 8: return "updating_firmware";
    default: return "unknown";
  }
}

const char* safety_mode_name(int32_t safety_mode) {
  switch (safety_mode) {
    case 1: return "normal";
    case 2: return "reduced";
    case 3: return "protective_stop";
    case 4: return "recovery";
    case 5: return "safeguard_stop";
    case 6: return "system_emergency_stop";
    case 7: return "robot_emergency_stop";
    case 8: return "violation";
    case 9: return "fault";
    default: return "unknown";
  }
}

bool robot_running(const RobotStatus& status) { return status.known && status.robot_mode == 7; }

bool in_protective_stop(const RobotStatus& status) {
  return status.known && (status.safety_mode == 3 || status.safety_mode == 5);
}

bool robot_mode_changed(const RobotStatus& before, const RobotStatus& after) {
  return before.known && after.known &&
         (before.robot_mode != after.robot_mode || before.safety_mode != after.safety_mode);
}

void RobotStatusCounts::add(const RobotStatus& status) {
  if (!status.known) return;
  ++frames_reported;
  frames_not_running += robot_running(status) ? 0 : 1;
  frames_protective_stop += in_protective_stop(status) ? 1 : 0;
  frames_tcp_pose_mismatch += status.tcp_pose_mismatch ? 1 : 0;
  mode_changes += robot_mode_changed(last, status) ? 1 : 0;
  last = status;
}

RobotState fixed_robot_state(const JointAngles& q_rad) {
  RobotState state;
  state.q_rad = q_rad;
  state.valid = true;
  state.origin = RobotStateOrigin::fixed;
  return state;
}

}  // namespace hrcsense
