// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — JointState and speed scaling as plain functions (ros2_joint_state.hpp).
#include "dds/ros2_joint_state.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace hrcsense::ros2 {
namespace {

constexpr const char* kUrJointSuffixes[kJointCount] = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                                       "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};

// Cyclone never hands over a null string; a hand-made message might.
const char* name_at(const dds_sequence_string& names, uint32_t i) {
  const char* name = names._buffer[i];
  return name != nullptr ? name : "";
}

std::string joint_label(const JointNames& names, size_t j) {
  return "'" + names[j] + "' (joint " + std::to_string(j + 1) + ")";
}

// "position: 5 values for 6 names"
std::string count_text(const char* field, uint32_t values, uint32_t names) {
  return std::string(field) + ": " + std::to_string(values) + " values for " + std::to_string(names) + " names";
}

}  // namespace

JointNames ur_joint_names(const std::string& tf_prefix) {
  JointNames names;
  for (size_t j = 0; j < kJointCount; ++j) names[j] = tf_prefix + kUrJointSuffixes[j];
  return names;
}

JointStateSample parse_joint_state(const sensor_msgs_msg_dds__JointState_& msg, const JointNames& names) {
  JointStateSample out;
  const uint32_t count = msg.name._length;
  if (count > kMaxJointStateNames) {
    out.error = "name: " + std::to_string(count) + " names, more than " + std::to_string(kMaxJointStateNames);
    return out;
  }
  if (msg.position._length != count) {
    out.error = count_text("position", msg.position._length, count);
    return out;
  }
  if (msg.velocity._length != 0 && msg.velocity._length != count) {
    out.error = count_text("velocity", msg.velocity._length, count) + " (expected none or one per name)";
    return out;
  }
  if (msg.header.stamp.nanosec >= 1'000'000'000U) {
    out.error = "header.stamp.nanosec: " + std::to_string(msg.header.stamp.nanosec) + ", not below 10^9";
    return out;
  }
  // A name twice makes "the" value of that joint ambiguous: the whole message is refused.
  for (uint32_t a = 0; a < count; ++a) {
    for (uint32_t b = a + 1; b < count; ++b) {
      if (std::strcmp(name_at(msg.name, a), name_at(msg.name, b)) == 0) {
        out.error = std::string("name: '") + name_at(msg.name, a) + "' appears twice";
        return out;
      }
    }
  }
  out.has_velocity = msg.velocity._length == count && count > 0;
  for (size_t j = 0; j < kJointCount; ++j) {
    uint32_t i = 0;
    while (i < count && names[j] != name_at(msg.name, i)) ++i;
    if (i == count) {
      out.error = "no joint " + joint_label(names, j) + " among the " + std::to_string(count) + " names";
      return out;
    }
    out.q_rad[j] = msg.position._buffer[i];
    out.qd_rad_s[j] = out.has_velocity ? msg.velocity._buffer[i] : 0.0;
    if (!out.non_finite && !std::isfinite(out.q_rad[j])) {
      out.non_finite = true;
      out.error = "position of " + joint_label(names, j) + " is not finite";
    } else if (!out.non_finite && !std::isfinite(out.qd_rad_s[j])) {
      out.non_finite = true;
      out.error = "velocity of " + joint_label(names, j) + " is not finite";
    }
  }
  out.stamp_ns = int64_t{msg.header.stamp.sec} * 1'000'000'000 + int64_t{msg.header.stamp.nanosec};
  out.ok = !out.non_finite;
  return out;
}

JointAngles finite_difference_rad_s(const JointAngles& q_before, const JointAngles& q_after, double dt_s) {
  JointAngles qd{};
  for (size_t j = 0; j < kJointCount; ++j) qd[j] = (q_after[j] - q_before[j]) / dt_s;
  return qd;
}

double speed_fraction_from(double value, SpeedScalingUnit unit) {
  const double fraction = unit == SpeedScalingUnit::percent ? value / 100.0 : value;
  // Written so that NaN fails the test.
  if (!(fraction >= -kSpeedFractionSlack && fraction <= 1.0 + kSpeedFractionSlack)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return fraction < 0.0 ? 0.0 : (fraction > 1.0 ? 1.0 : fraction);
}

}  // namespace hrcsense::ros2
