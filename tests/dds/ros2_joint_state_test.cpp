// SPDX-License-Identifier: Apache-2.0
// robot.state.source ros2: Ros2JointStateSource against JointState and Float64 writers in this
// process on loopback: joints by name, finite differences, no state before the first sample,
// stale with the topic named when the publisher stops, malformed messages counted, domains
// apart, the speed reading's age (the plain functions: ros2_joint_state_parse_test.cpp).
// Every wait is bounded and polls for its condition; no assertion is on timing.
#include "dds/dds_entity.hpp"
#include "dds/ros2_joint_state.hpp"
#include "dds/ros2_joint_state_source.hpp"
#include "dds_test_util.hpp"
#include "joint_state_message.hpp"

#include "std_msgs.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::ros2::joint_state_test {

using namespace std::chrono_literals;
constexpr int64_t kMsNs = 1'000'000;
constexpr int64_t kSecondNs = 1'000'000'000;

// A writer of `type` on a ROS 2 topic, with ROS's default QoS (reliable, volatile, keep-last 10).
class TestWriter {
 public:
  TestWriter(uint32_t domain, const dds_topic_descriptor_t& type, const std::string& ros_topic) : scope_(domain) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic =
        scope_.own(dds_create_topic(scope_.participant(), &type, name.c_str(), nullptr, nullptr), "topic " + name);
    const QosHandle qos(EndpointQos{true, false, 10});
    writer_ = scope_.own(dds_create_writer(scope_.participant(), topic, qos.get(), nullptr), "writer " + name);
  }
  // Waits (at most 10 s) until a reader matches.
  bool matched() const {
    for (int i = 0; i < 1000; ++i) {
      dds_publication_matched_status_t status{};
      dds_get_publication_matched_status(writer_, &status);
      if (status.current_count > 0) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }
  void write(const void* sample) const { check_dds(dds_write(writer_, sample), "write"); }

 private:
  ParticipantScope scope_;
  dds_entity_t writer_ = 0;
};

// Polls `condition` every 5 ms for at most 10 s.
bool eventually(const std::function<bool()>& condition) {
  for (int i = 0; i < 2000; ++i) {
    if (condition()) return true;
    std::this_thread::sleep_for(5ms);
  }
  return condition();
}

// A topic of this test process's own, so that a parallel test process in the same domain
// cannot feed it.
std::string own_topic(const std::string& stem) { return "/js_test_" + std::to_string(::getpid()) + "/" + stem; }

Ros2JointStateParams params_for(const std::string& topic, uint32_t domain, const std::string& speed_topic = "") {
  Ros2JointStateParams params;
  params.topic = topic;
  params.speed_scaling_topic = speed_topic;
  params.domain_id = domain;
  params.history.max_age_s = 0.05;
  return params;
}

int64_t wall_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The cell's joints published in a shuffled order with zero velocities and wall-clock stamps,
// every 4 ms until stopped (at most 30 s).
class JointPublisher {
 public:
  JointPublisher(uint32_t domain, const std::string& topic, const JointAngles& q) {
    thread_ = std::thread([this, domain, topic, q] {
      const TestWriter writer(domain, sensor_msgs_msg_dds__JointState__desc, topic);
      JointStateMessage m;
      m.names = {"elbow_joint", "wrist_3_joint", "shoulder_pan_joint", "wrist_2_joint", "shoulder_lift_joint",
                 "wrist_1_joint", "tool_joint"};
      m.position = {q[2], q[5], q[0], q[4], q[1], q[3], 7.0};
      m.velocity.assign(7, 0.0);
      const auto deadline = std::chrono::steady_clock::now() + 30s;
      while (!stop_.load() && std::chrono::steady_clock::now() < deadline) {
        const int64_t now = wall_now_ns();
        m.sec = static_cast<int32_t>(now / kSecondNs);
        m.nanosec = static_cast<uint32_t>(now % kSecondNs);
        writer.write(&m.get());
        std::this_thread::sleep_for(4ms);
      }
    });
  }
  ~JointPublisher() { stop(); }
  void stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

const JointAngles kJoints{-0.941593, -1.5, 1.4, -1.7, -1.5708, 0.25};

TEST(Ros2JointStateSource, NoStateBeforeTheFirstSampleNamingTheTopic) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const SteadyClock clock;
  const std::string topic = own_topic("nobody");
  Ros2JointStateSource source(params_for(topic, test::test_domain()), clock);
  EXPECT_EQ(source.origin(), RobotStateOrigin::ros2);
  RobotState state;
  EXPECT_FALSE(source.state_at(clock.now_ns(), state));
  EXPECT_FALSE(state.valid);
  EXPECT_EQ(state.sample_time_ns, 0) << "missing, not stale";
  EXPECT_NE(source.error().find(topic), std::string::npos) << source.error();
  EXPECT_NE(source.error().find("no JointState received"), std::string::npos) << source.error();
  EXPECT_EQ(source.stats().samples.accepted, 0);
}

TEST(Ros2JointStateSource, JointsByNameThenStaleWithTheTopicWhenThePublisherStops) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const SteadyClock clock;
  const std::string topic = own_topic("joint_states");
  Ros2JointStateSource source(params_for(topic, test::test_domain()), clock);
  JointPublisher publisher(test::test_domain(), topic, kJoints);
  RobotState state;
  ASSERT_TRUE(eventually([&] { return source.state_at(clock.now_ns(), state); })) << source.error();
  EXPECT_EQ(state.origin, RobotStateOrigin::ros2);
  EXPECT_EQ(state.q_rad, kJoints);  // zero velocity: no extrapolation moves them
  EXPECT_TRUE(std::isnan(state.speed_fraction)) << "no speed scaling topic";
  EXPECT_GE(source.stats().connections, 1);

  publisher.stop();
  ASSERT_TRUE(eventually([&] { return !source.state_at(clock.now_ns(), state); }));
  EXPECT_GT(state.sample_time_ns, 0) << "stale, not missing";
  const std::string error = source.error();
  EXPECT_NE(error.find(topic), std::string::npos) << error;
  EXPECT_NE(error.find("old (max 50.0 ms)"), std::string::npos) << error;
  EXPECT_GE(source.stats().samples.accepted, 1);
  EXPECT_EQ(source.stats().malformed, 0);
}

TEST(Ros2JointStateSource, MalformedMessagesAreCountedNamingTopicAndJoint) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const SteadyClock clock;
  const std::string topic = own_topic("malformed");
  Ros2JointStateSource source(params_for(topic, test::test_domain()), clock);
  const TestWriter writer(test::test_domain(), sensor_msgs_msg_dds__JointState__desc, topic);
  ASSERT_TRUE(writer.matched());
  JointStateMessage m = ur_message();
  m.names[4] = "wrist_two_joint";
  writer.write(&m.get());
  ASSERT_TRUE(eventually([&] { return source.stats().malformed == 1; }));
  const std::string problem = source.stats().last_problem;
  EXPECT_NE(problem.find(topic), std::string::npos) << problem;
  EXPECT_NE(problem.find("'wrist_2_joint' (joint 5)"), std::string::npos) << problem;

  JointStateMessage nan = ur_message();
  nan.velocity = {0.0, std::nan(""), 0.0, 0.0, 0.0, 0.0};
  writer.write(&nan.get());
  ASSERT_TRUE(eventually([&] { return source.stats().samples.rejected_non_finite == 1; }));
  EXPECT_NE(source.stats().last_problem.find("velocity of 'shoulder_lift_joint' (joint 2)"), std::string::npos)
      << source.stats().last_problem;
  RobotState state;
  EXPECT_FALSE(source.state_at(clock.now_ns(), state));
  EXPECT_NE(source.error().find("'shoulder_lift_joint'"), std::string::npos) << source.error();
}

// Stamps far from the wall clock (a simulated time): the arrival time on the fake clock stands
// in for them, so the test sets each sample's host time; the velocity comes from the stamps.
TEST(Ros2JointStateSource, WithoutVelocitiesTheSecondSampleGetsFiniteDifferences) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  FakeClock clock(100 * kSecondNs);
  const std::string topic = own_topic("no_velocity");
  Ros2JointStateSource source(params_for(topic, test::test_domain()), clock);
  const TestWriter writer(test::test_domain(), sensor_msgs_msg_dds__JointState__desc, topic);
  ASSERT_TRUE(writer.matched());
  JointStateMessage m = ur_message();
  m.sec = 5;
  writer.write(&m.get());
  RobotState state;
  // The first is the reference only: no state, and no made-up zero velocity.
  ASSERT_TRUE(eventually([&] {
    source.state_at(clock.now_ns(), state);
    return source.error().find("waiting for a second JointState") != std::string::npos;
  })) << source.error();
  EXPECT_FALSE(state.valid);

  // 10 ms later by the stamps (8 ms by arrival): joint 1 +0.004 rad, joint 6 −0.002 rad.
  clock.advance(8 * kMsNs);
  m.nanosec = 10'000'000;
  m.position[0] = 0.104;
  m.position[5] = 0.598;
  writer.write(&m.get());
  ASSERT_TRUE(eventually([&] { return source.state_at(clock.now_ns(), state); })) << source.error();
  EXPECT_EQ(state.q_rad, (JointAngles{0.104, 0.2, 0.3, 0.4, 0.5, 0.598}));
  EXPECT_NEAR(state.qd_rad_s[0], 0.4, 1e-9);   // 0.004 rad / 0.010 s
  EXPECT_NEAR(state.qd_rad_s[5], -0.2, 1e-9);  // −0.002 rad / 0.010 s
  EXPECT_EQ(state.qd_rad_s[1], 0.0);

  // A jump: joint 3 by 0.2 rad in 10 ms against 0 rad/s and the 0.05 rad tolerance.
  clock.advance(8 * kMsNs);
  m.nanosec = 20'000'000;
  m.position[2] = 0.5;
  writer.write(&m.get());
  ASSERT_TRUE(eventually([&] { return source.stats().samples.rejected_jump == 1; }));
  EXPECT_NE(source.stats().last_problem.find("'elbow_joint' (joint 3) jumped"), std::string::npos)
      << source.stats().last_problem;
  EXPECT_EQ(source.stats().samples.accepted, 1);
}

TEST(Ros2JointStateSource, TwoDomainsDoNotSeeEachOther) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const SteadyClock clock;
  const std::string topic = own_topic("domains");
  const uint32_t domain = test::test_domain();
  const uint32_t other = domain + 1;  // 2..201
  Ros2JointStateSource here(params_for(topic, domain), clock);
  Ros2JointStateSource there(params_for(topic, other), clock);
  JointPublisher publisher(domain, topic, kJoints);
  RobotState state;
  // Once the source in the publisher's domain has its joints, the other has had time to hear them.
  ASSERT_TRUE(eventually([&] { return here.stats().samples.accepted >= 20; }));
  publisher.stop();
  EXPECT_FALSE(there.state_at(clock.now_ns(), state));
  EXPECT_EQ(there.stats().samples.accepted, 0);
  EXPECT_EQ(there.stats().connections, 0);
  EXPECT_NE(there.error().find("domain " + std::to_string(other)), std::string::npos) << there.error();
}

// The speed scaling has no stamp: its arrival on the (fake) clock counts. Joint states with
// velocities, stamped far from the wall clock, arrive at the fake clock's time too.
TEST(Ros2JointStateSource, SpeedScalingIsAReadingForMaxAgeAfterItsArrival) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  FakeClock clock(100 * kSecondNs);
  const std::string topic = own_topic("speed_joints");
  const std::string speed_topic = own_topic("speed_scaling");
  Ros2JointStateSource source(params_for(topic, test::test_domain(), speed_topic), clock);
  const TestWriter joints(test::test_domain(), sensor_msgs_msg_dds__JointState__desc, topic);
  const TestWriter speed(test::test_domain(), std_msgs_msg_dds__Float64__desc, speed_topic);
  ASSERT_TRUE(joints.matched());
  ASSERT_TRUE(speed.matched());
  JointStateMessage m = ur_message();
  m.velocity.assign(6, 0.0);
  m.sec = 5;
  joints.write(&m.get());
  RobotState state;
  ASSERT_TRUE(eventually([&] { return source.state_at(clock.now_ns(), state); })) << source.error();
  EXPECT_TRUE(std::isnan(state.speed_fraction)) << "no reading yet";

  const std_msgs_msg_dds__Float64_ percent{37.5};
  speed.write(&percent);
  ASSERT_TRUE(eventually([&] {
    return source.state_at(clock.now_ns(), state) && state.speed_fraction == 0.375;
  })) << state.speed_fraction;

  // 100 ms on, a fresh joint state; the reading is 100 ms old against max_age_s 0.05: none.
  clock.advance(100 * kMsNs);
  m.nanosec = 100'000'000;
  joints.write(&m.get());
  ASSERT_TRUE(eventually([&] { return source.stats().samples.accepted == 2; }));
  ASSERT_TRUE(source.state_at(clock.now_ns(), state)) << source.error();
  EXPECT_TRUE(std::isnan(state.speed_fraction)) << state.speed_fraction;
  // ... while a state 60 ms earlier, 40 ms after the reading, still has it.
  ASSERT_TRUE(source.state_at(clock.now_ns() - 60 * kMsNs, state)) << source.error();
  EXPECT_EQ(state.speed_fraction, 0.375);

  // Out of range (150 %): rejected, counted, and no reading from then on.
  const std_msgs_msg_dds__Float64_ good{50.0};
  speed.write(&good);
  ASSERT_TRUE(eventually([&] { return source.state_at(clock.now_ns(), state) && state.speed_fraction == 0.5; }));
  const std_msgs_msg_dds__Float64_ bad{150.0};
  speed.write(&bad);
  ASSERT_TRUE(eventually([&] { return source.speed_readings_rejected() == 1; }));
  ASSERT_TRUE(source.state_at(clock.now_ns(), state));
  EXPECT_TRUE(std::isnan(state.speed_fraction));
  const RobotStateStats stats = source.stats();
  EXPECT_EQ(stats.malformed, 1);
  EXPECT_NE(stats.last_problem.find(speed_topic), std::string::npos) << stats.last_problem;
  EXPECT_NE(stats.last_problem.find("150"), std::string::npos) << stats.last_problem;
}

}  // namespace hrcsense::ros2::joint_state_test
