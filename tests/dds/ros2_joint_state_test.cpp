// SPDX-License-Identifier: Apache-2.0
// robot.state.source ros2: JointState read by name and the speed scaling as plain functions
// (values worked out by hand), then Ros2JointStateSource against a JointState writer in this
// process on loopback: joints by name, finite differences, no state before the first sample,
// stale with the topic named when the publisher stops, domains apart, the speed reading's age.
// Every wait is bounded and polls for its condition; no assertion is on timing.
#include "dds/dds_entity.hpp"
#include "dds/ros2_joint_state.hpp"
#include "dds/ros2_joint_state_source.hpp"
#include "dds_test_util.hpp"

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
JointStateMessage ur_message(const std::string& prefix = "") {
  JointStateMessage m;
  m.names = {prefix + "shoulder_pan_joint", prefix + "shoulder_lift_joint", prefix + "elbow_joint",
             prefix + "wrist_1_joint",      prefix + "wrist_2_joint",       prefix + "wrist_3_joint"};
  m.position = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  return m;
}

// ---- The plain functions

TEST(Ros2JointStateParse, ShuffledNamesAreMatchedByName) {
  JointStateMessage m;
  m.names = {"wrist_3_joint", "elbow_joint", "shoulder_pan_joint", "wrist_1_joint", "shoulder_lift_joint", "wrist_2_joint"};
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

// ---- Over DDS, in this process

// A writer of `Msg` on a ROS 2 topic, with ROS's default QoS (reliable, volatile, keep-last 10).
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
