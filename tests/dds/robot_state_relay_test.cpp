// SPDX-License-Identifier: Apache-2.0
// The fuser's robot state relay (dds/ros2_joint_state_writer.hpp, docs/MULTICAMERA.md, "Robot
// state"): a live udp_json robot (a peer in this process, on 127.0.0.1) → JointStateRelay →
// sensor_msgs/JointState on loopback DDS. The samples are read back with a reader of the test's
// own (Cyclone's generated type, matched by the names ROS's message spec gives, not the
// production parser), and with the camera side's production reader to confirm the cameras'
// rule when the robot goes silent. Every wait is bounded.
#include "dds/ros2_joint_state_source.hpp"
#include "dds/ros2_joint_state_writer.hpp"
#include "dds_test_util.hpp"
#include "joint_state_peers.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/net/udp_json.hpp"
#include "hrcsense/robot_state.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::relay_test {
namespace {

using test::TestJointStateReader;
using test::Seen;
using test::UdpRobot;

int64_t wall_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Takes from `reader` until a sample with position[0] == q0 arrived, at most 3 s; false then.
bool wait_for_position(TestJointStateReader& reader, std::vector<Seen>& seen, double q0) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (std::chrono::steady_clock::now() < deadline) {
    reader.take(seen);
    for (const Seen& s : seen) {
      if (!s.position.empty() && s.position[0] == q0) return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

TEST(RobotStateRelay, EachAcceptedUdpJsonSampleGoesOutAsAJointStateAndARejectedOneNever) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint32_t domain = test::test_domain();
  const std::string topic = "/relay_test_" + std::to_string(::getpid()) + "/joint_states";
  SteadyClock clock;
  UdpJsonParams params;
  params.listen = "127.0.0.1:0";
  params.history.max_age_s = 0.5;
  params.history.q_min_rad.fill(-6.3);  // a UR's ±2π, as robot.model would set them
  params.history.q_max_rad.fill(6.3);
  UdpJsonRobotState states(params, clock);
  ros2::JointStateRelay relay(states, clock, {domain, topic, ""});
  TestJointStateReader reader(domain, topic);
  ASSERT_TRUE(reader.ok());
  // The camera side's production reader on the same topic, best-effort as the cameras'.
  ros2::Ros2JointStateParams camera_params;
  camera_params.topic = topic;
  camera_params.speed_scaling_topic.clear();
  camera_params.domain_id = domain;
  camera_params.history.max_age_s = 0.5;
  ros2::Ros2JointStateSource camera(camera_params, clock);
  RobotState before;
  EXPECT_FALSE(camera.state_at(clock.now_ns(), before));
  EXPECT_EQ(before.sample_time_ns, 0) << "no sample yet: a camera's frame is no_robot_state";

  UdpRobot robot(states.bound_port());
  const std::array<double, 6> qd = {0.5, -0.25, 0.125, 0.0, 1.0, -1.0};
  std::vector<Seen> seen;
  int64_t t_ns = 1'000'000'000;
  const int64_t sent_wall_ns = wall_ns();
  // The first sample may go before discovery matched the readers: it is sent again until one
  // reaches the test's reader (a reliable writer's later samples then reach it all).
  const std::array<double, 6> first = {0.1, -1.2, 1.3, -0.4, 0.5, 0.6};
  for (int attempt = 0; attempt < 150 && seen.empty(); ++attempt) {
    t_ns += 20'000'000;
    robot.send(t_ns, first, qd);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    reader.take(seen);
  }
  ASSERT_FALSE(seen.empty()) << "no JointState reached the reader in 150 tries";

  // A joint at 100 rad is no UR pose: the source rejects it, and it is never republished; the
  // next good sample is (each waited for, so that none is replaced by a newer one in a look).
  t_ns += 10'000'000;
  robot.send(t_ns, {0.2, -1.2, 1.3, 100.0, 0.5, 0.6}, qd);
  const std::array<double, 6> second = {0.105, -1.2025, 1.30125, -0.4, 0.51, 0.59};
  t_ns += 10'000'000;
  robot.send(t_ns, second, qd);
  ASSERT_TRUE(wait_for_position(reader, seen, 0.105)) << "the second good sample never arrived";

  const std::vector<std::string> ur_names = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                             "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};
  for (const Seen& s : seen) {
    EXPECT_EQ(s.names, ur_names);
    ASSERT_EQ(s.position.size(), 6U);
    EXPECT_NE(s.position[3], 100.0) << "a rejected sample was republished";
    EXPECT_EQ(s.velocity, std::vector<double>(qd.begin(), qd.end()));
    // Stamped on the shared clock: within the seconds this test ran of the wall clock.
    EXPECT_GT(s.stamp_ns, sent_wall_ns - 1'000'000'000);
    EXPECT_LT(s.stamp_ns, wall_ns() + 1'000'000'000);
  }
  EXPECT_EQ(seen.front().position, std::vector<double>(first.begin(), first.end()));
  EXPECT_EQ(seen.back().position, std::vector<double>(second.begin(), second.end()));
  EXPECT_EQ(states.stats().samples.rejected_limits, 1);
  EXPECT_EQ(relay.counters().refused, 0);

  // The camera side read them too; once the robot is silent for longer than max_age_s its state
  // is stale, as any live source's: the camera's frames stop.
  RobotState state;
  bool got = false;
  for (int i = 0; i < 1000 && !got; ++i) {
    // Now, the state is extrapolated past the newest sample; at that sample's time it is the sample.
    RobotState newest;
    camera.state_at(clock.now_ns(), newest);
    got = newest.sample_time_ns != 0 && camera.state_at(newest.sample_time_ns, state) && state.q_rad[0] == 0.105;
    if (!got) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_TRUE(got) << camera.error();
  EXPECT_EQ(state.q_rad[2], 1.30125);
  EXPECT_EQ(state.qd_rad_s[4], 1.0);
  RobotState later;
  EXPECT_FALSE(camera.state_at(clock.now_ns() + 1'000'000'000, later));  // 1 s later, max age 0.5 s
  EXPECT_NE(later.sample_time_ns, 0) << "stale, not missing: robot_state_stale";
}

}  // namespace
}  // namespace hrcsense::relay_test
