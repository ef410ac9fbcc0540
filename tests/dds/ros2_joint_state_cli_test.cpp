// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` with robot.state.source ros2, fed by a JointState writer thread in this
// process over loopback: the frames are measured against the published joints (as a fixed run
// at the same joints is) and stop once the publisher falls silent; `--record` keeps the joint
// states, so the bag replays with them; with no publisher every frame stops for want of a
// state, naming the topic. Every wait is bounded.
#include "../net/cli_cell.hpp"
#include "dds/dds_entity.hpp"
#include "dds_test_util.hpp"

#include "sensor_msgs.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::ros2::joint_state_cli_test {

using namespace std::chrono_literals;

std::string ros2_state_args(const std::string& topic) {
  return "--set robot.state.source=ros2 --set ros2.domain_id=" + std::to_string(test::test_domain()) +
         " --set robot.state.ros2.topic=" + topic + " --set robot.state.ros2.speed_scaling_topic=" + topic + "_speed";
}

// Publishes the cell's joints (UR names, the driver's order reversed, velocities zero,
// wall-clock stamps) at 250 Hz while `keep_on()` (at most 20 s).
void publish_while(const std::string& topic, const std::function<bool()>& keep_on) {
  ParticipantScope scope(test::test_domain());
  const std::string name = dds_topic_name(topic);
  const dds_entity_t dds_topic = scope.own(
      dds_create_topic(scope.participant(), &sensor_msgs_msg_dds__JointState__desc, name.c_str(), nullptr, nullptr),
      "topic");
  const QosHandle qos(EndpointQos{true, false, 10});  // ROS's default QoS, as joint_state_broadcaster
  const dds_entity_t writer =
      scope.own(dds_create_writer(scope.participant(), dds_topic, qos.get(), nullptr), "writer");
  std::vector<std::string> names = {"wrist_3_joint", "wrist_2_joint",       "wrist_1_joint",
                                    "elbow_joint",   "shoulder_lift_joint", "shoulder_pan_joint"};
  std::vector<char*> name_pointers;
  for (std::string& n : names) name_pointers.push_back(n.data());
  std::vector<double> position, velocity(6, 0.0);
  for (size_t j = 0; j < 6; ++j) position.push_back(test::kCliJoints[5 - j]);
  sensor_msgs_msg_dds__JointState_ msg{};
  msg.header.frame_id = const_cast<char*>("");
  msg.name._buffer = name_pointers.data();
  msg.name._length = msg.name._maximum = 6;
  msg.position._buffer = position.data();
  msg.position._length = msg.position._maximum = 6;
  msg.velocity._buffer = velocity.data();
  msg.velocity._length = msg.velocity._maximum = 6;
  for (int k = 0; k < 5000 && keep_on(); ++k) {
    const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::system_clock::now().time_since_epoch()).count();
    msg.header.stamp.sec = static_cast<int32_t>(now / 1'000'000'000);
    msg.header.stamp.nanosec = static_cast<uint32_t>(now % 1'000'000'000);
    dds_write(writer, &msg);
    std::this_thread::sleep_for(4ms);
  }
}

// Frames of a bag replayed with robot.state.source recorded that carry joints; each must be
// the cell's joints.
int replayed_frames_with_the_cell_joints(const std::string& config, const std::string& bag) {
  const test::ToolRun replay = test::run_tool(
      config, "--set source.type=bag --set source.path=" + bag + " --set robot.state.source=recorded", "ros2_replay");
  int with_joints = 0;
  for (const auto& [index, frame] : replay.frames) {
    if (frame.at("joints_rad").is_null()) continue;
    ++with_joints;
    for (size_t j = 0; j < 6; ++j) {
      EXPECT_NEAR(frame.at("joints_rad").at(j).get<double>(), test::kCliJoints[j], 1e-9) << index;
    }
  }
  return with_joints;
}

TEST(Ros2JointStateCli, RunFollowsThePublishedJointsStopsWhenSilentAndRecordsThem) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string config = test::write_cli_cell("ros2_joints");
  const test::ToolRun fixed = test::run_tool(config, "--set source.pace=false", "ros2_joints_fixed");
  const std::string topic = "/cli_js_" + std::to_string(::getpid()) + "/joint_states";
  const std::string bag = test::temp_path("ros2_joints", ".bag");
  std::remove(bag.c_str());
  const std::string out = test::cli_out_path("ros2_joints");
  std::thread publisher(
      [&] { publish_while(topic, [&] { return test::frames_written(out) < test::kSilentAfterFrames; }); });
  const test::ToolRun live = test::run_tool(config, ros2_state_args(topic) + " --record " + bag, "ros2_joints");
  publisher.join();

  EXPECT_EQ(live.header.at("robot_state"), "ros2");
  const nlohmann::json& robot = live.summary.at("robot_state");
  EXPECT_GE(robot.at("accepted").get<int64_t>(), test::kSilentAfterFrames);  // 250 Hz against 30 fps
  EXPECT_EQ(robot.at("malformed"), 0);
  test::expect_follows_then_stops(live, fixed);
  // The frames that stopped say why, naming the topic.
  int named = 0;
  for (const auto& [index, frame] : live.frames) {
    if (frame.at("reason_code") == "robot_state_stale" &&
        frame.at("verdict_reason").get<std::string>().find(topic) != std::string::npos) {
      ++named;
    }
  }
  EXPECT_GE(named, 1);

  // The recording replays with the joints the run was measured against (frames without a state
  // were recorded without joints, and replay as stops).
  EXPECT_GE(replayed_frames_with_the_cell_joints(config, bag), 10)
      << "the recording should hold the joint states of the frames that had one";
  std::remove(bag.c_str());
  std::remove(config.c_str());
}

// `hrcsense record` (no processing) keeps the ROS 2 joint states as it keeps RTDE's.
TEST(Ros2JointStateCli, RecordKeepsTheJointStates) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string config = test::write_cli_cell("ros2_record");
  const std::string topic = "/cli_js_" + std::to_string(::getpid()) + "/recorded";
  const std::string bag = test::temp_path("ros2_record", ".bag");
  std::remove(bag.c_str());
  std::atomic<bool> recording{true};
  std::thread publisher([&] { publish_while(topic, [&] { return recording.load(); }); });
  // Paced (2.5 s): the reader discovers the publisher within the first frames.
  const std::string command = std::string(HRCSENSE_CLI) + " record --config " + config + " " + ros2_state_args(topic) +
                              " --out " + bag + " 2>/dev/null";
  const int status = std::system(command.c_str());
  recording = false;
  publisher.join();
  ASSERT_EQ(status, 0) << command;
  EXPECT_GE(replayed_frames_with_the_cell_joints(config, bag), 30) << "of the 75 frames";
  std::remove(bag.c_str());
  std::remove(config.c_str());
}

TEST(Ros2JointStateCli, WithoutAPublisherEveryFrameStopsForWantOfAState) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string config = test::write_cli_cell("ros2_nobody");
  const std::string topic = "/cli_js_" + std::to_string(::getpid()) + "/nobody";
  const test::ToolRun live =
      test::run_tool(config, ros2_state_args(topic) + " --set source.pace=false --set sim.frames=30", "ros2_nobody");
  std::remove(config.c_str());
  ASSERT_EQ(live.frames.size(), 30U);
  int no_state = 0;
  for (const auto& [index, frame] : live.frames) {
    EXPECT_EQ(frame.at("verdict"), "stop") << index;
    EXPECT_TRUE(frame.at("joints_rad").is_null()) << index;
    if (frame.at("reason_code") == "learning_background") continue;  // the cell's first 10 frames
    ++no_state;
    EXPECT_EQ(frame.at("reason_code"), "no_robot_state") << index;
    EXPECT_NE(frame.at("verdict_reason").get<std::string>().find(topic), std::string::npos) << frame.dump();
  }
  EXPECT_EQ(no_state, 20);
  EXPECT_EQ(live.summary.at("robot_state").at("accepted"), 0);
}

}  // namespace hrcsense::ros2::joint_state_cli_test
