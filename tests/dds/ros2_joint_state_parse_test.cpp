// SPDX-License-Identifier: Apache-2.0
// robot.state.source ros2, the plain functions: a JointState read by name for UR's six joints
// (any order, a tf_prefix, extra joints ignored, every malformed case named), finite
// differences and the speed scaling as a fraction, against values worked out by hand.
#include "dds/ros2_joint_state.hpp"
#include "joint_state_message.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace hrcsense::ros2::joint_state_test {

TEST(Ros2JointStateParse, ShuffledNamesAreMatchedByName) {
  JointStateMessage m;
  m.names = {"wrist_3_joint", "elbow_joint",         "shoulder_pan_joint",
             "wrist_1_joint", "shoulder_lift_joint", "wrist_2_joint"};
  m.position = {0.6, 0.3, 0.1, 0.4, 0.2, 0.5};
  m.velocity = {-6.0, -3.0, -1.0, -4.0, -2.0, -5.0};
  m.sec = 12;
  m.nanosec = 345;
  const JointStateSample s = parse_joint_state(m.get(), ur_joint_names(""));
  ASSERT_TRUE(s.ok) << s.error;
  EXPECT_EQ(s.q_rad, (JointAngles{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
  EXPECT_TRUE(s.has_velocity);
  EXPECT_EQ(s.qd_rad_s, (JointAngles{-1.0, -2.0, -3.0, -4.0, -5.0, -6.0}));
  EXPECT_EQ(s.stamp_ns, 12'000'000'345);
}

TEST(Ros2JointStateParse, TfPrefixComesBeforeEachName) {
  const JointNames names = ur_joint_names("ur_");
  EXPECT_EQ(names[0], "ur_shoulder_pan_joint");
  EXPECT_EQ(names[2], "ur_elbow_joint");
  EXPECT_EQ(names[5], "ur_wrist_3_joint");
  JointStateMessage prefixed = ur_message("ur_");
  const JointStateSample s = parse_joint_state(prefixed.get(), names);
  ASSERT_TRUE(s.ok) << s.error;
  EXPECT_FALSE(s.has_velocity);
  EXPECT_EQ(s.q_rad, (JointAngles{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
  // The driver without the prefix: the first joint looked for is missing.
  JointStateMessage plain = ur_message();
  const JointStateSample missing = parse_joint_state(plain.get(), names);
  EXPECT_FALSE(missing.ok);
  EXPECT_NE(missing.error.find("'ur_shoulder_pan_joint' (joint 1)"), std::string::npos) << missing.error;
}

TEST(Ros2JointStateParse, ExtraJointsAreIgnoredWhateverTheirValues) {
  JointStateMessage m = ur_message();
  m.names.insert(m.names.begin() + 2, "gripper_finger_joint");
  m.position.insert(m.position.begin() + 2, std::nan(""));
  const JointStateSample s = parse_joint_state(m.get(), ur_joint_names(""));
  ASSERT_TRUE(s.ok) << s.error;
  EXPECT_EQ(s.q_rad, (JointAngles{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
}

TEST(Ros2JointStateParse, AMissingJointIsNamed) {
  JointStateMessage m = ur_message();
  m.names.erase(m.names.begin() + 2);  // elbow_joint
  m.position.erase(m.position.begin() + 2);
  const JointStateSample s = parse_joint_state(m.get(), ur_joint_names(""));
  EXPECT_FALSE(s.ok);
  EXPECT_FALSE(s.non_finite);
  EXPECT_EQ(s.error, "no joint 'elbow_joint' (joint 3) among the 5 names");
}

TEST(Ros2JointStateParse, ArraysOfOtherLengthsAreMalformed) {
  JointStateMessage short_position = ur_message();
  short_position.position.pop_back();
  JointStateSample s = parse_joint_state(short_position.get(), ur_joint_names(""));
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.error, "position: 5 values for 6 names");

  JointStateMessage short_velocity = ur_message();
  short_velocity.velocity = {0.0, 0.0, 0.0};
  s = parse_joint_state(short_velocity.get(), ur_joint_names(""));
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.error.find("velocity: 3 values for 6 names"), std::string::npos) << s.error;

  // effort is not read: any length is fine.
  JointStateMessage with_effort = ur_message();
  std::vector<double> effort{1.0, 2.0};
  sensor_msgs_msg_dds__JointState_ msg = with_effort.get();
  msg.effort._buffer = effort.data();
  msg.effort._length = msg.effort._maximum = 2;
  EXPECT_TRUE(parse_joint_state(msg, ur_joint_names("")).ok);
}

TEST(Ros2JointStateParse, DuplicateNamesAndBadStampsAreMalformed) {
  JointStateMessage twice = ur_message();
  twice.names.push_back("elbow_joint");
  twice.position.push_back(0.3);
  JointStateSample s = parse_joint_state(twice.get(), ur_joint_names(""));
  EXPECT_FALSE(s.ok);
  EXPECT_EQ(s.error, "name: 'elbow_joint' appears twice");

  JointStateMessage stamp = ur_message();
  stamp.nanosec = 1'000'000'000;
  s = parse_joint_state(stamp.get(), ur_joint_names(""));
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.error.find("header.stamp.nanosec"), std::string::npos) << s.error;
}

TEST(Ros2JointStateParse, NonFiniteValuesOfTheSixAreRejectedNamingTheJoint) {
  JointStateMessage m = ur_message();
  m.position[3] = std::nan("");
  JointStateSample s = parse_joint_state(m.get(), ur_joint_names(""));
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(s.non_finite);
  EXPECT_EQ(s.error, "position of 'wrist_1_joint' (joint 4) is not finite");

  JointStateMessage v = ur_message();
  v.velocity = {0.0, 0.0, 0.0, 0.0, 0.0, -INFINITY};
  s = parse_joint_state(v.get(), ur_joint_names(""));
  EXPECT_TRUE(s.non_finite);
  EXPECT_EQ(s.error, "velocity of 'wrist_3_joint' (joint 6) is not finite");
}

TEST(Ros2JointStateParse, FiniteDifferences) {
  // Joint 1 from 0.100 to 0.104 rad in 8 ms: 0.5 rad/s; joint 2 from -1.0 to -1.016: -2 rad/s.
  const JointAngles before{0.100, -1.0, 0.0, 0.0, 0.0, 3.0};
  const JointAngles after{0.104, -1.016, 0.0, 0.0, 0.0, 3.0};
  const JointAngles qd = finite_difference_rad_s(before, after, 0.008);
  EXPECT_NEAR(qd[0], 0.5, 1e-12);
  EXPECT_NEAR(qd[1], -2.0, 1e-12);
  EXPECT_EQ(qd[2], 0.0);
  EXPECT_EQ(qd[5], 0.0);
}

TEST(Ros2JointStateParse, SpeedScalingAsAFraction) {
  EXPECT_DOUBLE_EQ(speed_fraction_from(37.5, SpeedScalingUnit::percent), 0.375);
  EXPECT_EQ(speed_fraction_from(100.0, SpeedScalingUnit::percent), 1.0);
  EXPECT_EQ(speed_fraction_from(0.0, SpeedScalingUnit::percent), 0.0);
  EXPECT_EQ(speed_fraction_from(0.6, SpeedScalingUnit::fraction), 0.6);
  EXPECT_EQ(speed_fraction_from(1.0, SpeedScalingUnit::fraction), 1.0);
  // Rounding just past the ends is taken as the end; anything further is no reading.
  EXPECT_EQ(speed_fraction_from(100.00001, SpeedScalingUnit::percent), 1.0);
  EXPECT_EQ(speed_fraction_from(-1e-9, SpeedScalingUnit::fraction), 0.0);
  EXPECT_TRUE(std::isnan(speed_fraction_from(150.0, SpeedScalingUnit::percent)));
  EXPECT_TRUE(std::isnan(speed_fraction_from(-1.0, SpeedScalingUnit::percent)));
  EXPECT_TRUE(std::isnan(speed_fraction_from(37.5, SpeedScalingUnit::fraction)));  // percent read as fraction
  EXPECT_TRUE(std::isnan(speed_fraction_from(std::nan(""), SpeedScalingUnit::fraction)));
  EXPECT_TRUE(std::isnan(speed_fraction_from(INFINITY, SpeedScalingUnit::percent)));
}

}  // namespace hrcsense::ros2::joint_state_test
