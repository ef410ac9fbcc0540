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
  }
  return "unknown";
}

RobotState fixed_robot_state(const JointAngles& q_rad) {
  RobotState state;
  state.q_rad = q_rad;
  state.valid = true;
  state.origin = RobotStateOrigin::fixed;
  return state;
}

}  // namespace hrcsense
