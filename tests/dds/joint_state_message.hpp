// SPDX-License-Identifier: Apache-2.0
// What the joint state tests share: a sensor_msgs/JointState built from vectors, as Cyclone
// would hand it over (names, position, velocity, stamp).
#pragma once

#include "sensor_msgs.h"

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::ros2::joint_state_test {

// A JointState pointing at the caller's vectors (which must outlive it); nothing is owned.
struct JointStateMessage {
  std::vector<std::string> names;
  std::vector<double> position, velocity;
  int32_t sec = 0;
  uint32_t nanosec = 0;
  std::vector<char*> name_pointers;
  sensor_msgs_msg_dds__JointState_ msg{};

  const sensor_msgs_msg_dds__JointState_& get() {
    name_pointers.clear();
    for (std::string& name : names) name_pointers.push_back(name.data());
    msg = sensor_msgs_msg_dds__JointState_{};
    msg.header.stamp.sec = sec;
    msg.header.stamp.nanosec = nanosec;
    msg.header.frame_id = const_cast<char*>("");
    msg.name._buffer = name_pointers.data();
    msg.name._length = msg.name._maximum = static_cast<uint32_t>(names.size());
    msg.position._buffer = position.data();
    msg.position._length = msg.position._maximum = static_cast<uint32_t>(position.size());
    msg.velocity._buffer = velocity.data();
    msg.velocity._length = msg.velocity._maximum = static_cast<uint32_t>(velocity.size());
    return msg;
  }
};

// UR's names in the driver's order with positions 0.1 ... 0.6 and no velocity.
inline JointStateMessage ur_message(const std::string& prefix = "") {
  JointStateMessage m;
  m.names = {prefix + "shoulder_pan_joint", prefix + "shoulder_lift_joint", prefix + "elbow_joint",
             prefix + "wrist_1_joint",      prefix + "wrist_2_joint",       prefix + "wrist_3_joint"};
  m.position = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  return m;
}

}  // namespace hrcsense::ros2::joint_state_test
