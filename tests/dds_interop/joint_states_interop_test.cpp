// SPDX-License-Identifier: Apache-2.0
// `robot.state.source: ros2` fed from outside: this process publishes sensor_msgs/JointState as a
// UR driver with a tf_prefix would (names shuffled, prefixed, an extra joint, ROS wall-clock
// stamps), with types built from the spec, while `hrcsense run` reads them as a child; every
// frame carries the published joints, and once the publisher stalls the cell stops with
// robot_state_stale naming the topic.
#include "../support/child_process.hpp"
#include "../support/scenes.hpp"
#include "interop_util.hpp"

#include <signal.h>

#include <array>
#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::test {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

// cell-ur5.yaml's pose (robot.joints_rad), so that the simulated arm and the states agree.
constexpr std::array<double, 6> kCellJoints = {-0.941593, -1.5, 1.4, -1.7, -1.5708, 0.0};

// Publishes the cell's pose at 100 Hz until `stop`, as the UR driver's joint_state_broadcaster
// with tf_prefix "ur_" might: its own order, an extra joint of a gripper, velocities zero.
void publish_joint_states(const Participant& participant, const std::atomic<bool>& stop) {
  const dds_entity_t writer =
      participant.endpoint(true, sensor_msgs_msg_dds__JointState__desc, "/joint_states", true, false, 10);
  // Order: wrist_3, elbow, ur_gripper, shoulder_lift, wrist_1, shoulder_pan, wrist_2.
  const char* names[] = {"ur_wrist_3_joint", "ur_elbow_joint", "ur_gripper_joint", "ur_shoulder_lift_joint",
                         "ur_wrist_1_joint", "ur_shoulder_pan_joint", "ur_wrist_2_joint"};
  double position[] = {kCellJoints[5], kCellJoints[2], 0.7, kCellJoints[1], kCellJoints[3], kCellJoints[0],
                       kCellJoints[4]};
  double velocity[7] = {};
  const auto deadline = std::chrono::steady_clock::now() + 60s;  // bounded whatever happens
  while (!stop.load() && std::chrono::steady_clock::now() < deadline) {
    sensor_msgs_msg_dds__JointState_ msg{};
    const int64_t now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::system_clock::now().time_since_epoch())
                               .count();
    msg.header.stamp.sec = static_cast<int32_t>(now_ns / 1'000'000'000);
    msg.header.stamp.nanosec = static_cast<uint32_t>(now_ns % 1'000'000'000);
    msg.header.frame_id = const_cast<char*>("");
    msg.name._buffer = const_cast<char**>(names);
    msg.name._length = msg.name._maximum = 7;
    msg.position._buffer = position;
    msg.position._length = msg.position._maximum = 7;
    msg.velocity._buffer = velocity;
    msg.velocity._length = msg.velocity._maximum = 7;
    dds_write(writer, &msg);
    std::this_thread::sleep_for(10ms);
  }
}

TEST(Ros2JointStates, FramesCarryThePublishedJointsAndAStalledPublisherStopsTheCell) {
  if (!interop_loopback()) GTEST_SKIP() << kInteropNoLoopback;
  const uint32_t domain = interop_domain();
  Participant participant(domain);
  std::atomic<bool> stop_publishing{false};
  std::thread publisher([&] { publish_joint_states(participant, stop_publishing); });

  ChildProcess child({HRCSENSE_CLI, "run", "--config", scene_path("cell-ur5.yaml"), "--frames", "900", "--set",
                      "source.pace=true", "--set", "robot.state.source=ros2", "--set",
                      "robot.state.ros2.tf_prefix=ur_", "--set", "ros2.domain_id=" + std::to_string(domain), "--set",
                      "robot.state.ros2.speed_scaling_topic=''", "--set", "robot.state.max_age_s=0.1"});
  int with_joints = 0, stopped_stale = 0, after_stall = 0;
  std::string stale_reason;
  std::string line;
  while (child.read_line(line, 20.0)) {
    const json frame = json::parse(line);
    if (frame["type"] != "frame") continue;
    if (!stop_publishing.load()) {
      if (frame["joints_rad"].is_null()) continue;  // before the first state reached it
      const std::vector<double> q = frame["joints_rad"].get<std::vector<double>>();
      ASSERT_EQ(q.size(), 6U);
      for (size_t j = 0; j < 6; ++j) EXPECT_NEAR(q[j], kCellJoints[j], 1e-9) << "joint " << j + 1;
      // Past learning (100 frames), so that the stop is the state's and not the learner's.
      if (++with_joints == 150) stop_publishing = true;
      continue;
    }
    ++after_stall;
    if (frame["reason_code"] == "robot_state_stale") {
      ++stopped_stale;
      stale_reason = frame["verdict_reason"].get<std::string>();
      EXPECT_EQ(frame["verdict"], "stop");
    }
    if (stopped_stale >= 5 || after_stall > 300) break;
  }
  publisher.join();
  child.stop(SIGINT, 10.0);
  EXPECT_EQ(with_joints, 150) << "frames with the published joints";
  EXPECT_GE(stopped_stale, 5) << "a stalled publisher is robot_state_stale";
  EXPECT_NE(stale_reason.find("/joint_states"), std::string::npos) << "the reason names the topic: " << stale_reason;
}

}  // namespace
}  // namespace hrcsense::test
