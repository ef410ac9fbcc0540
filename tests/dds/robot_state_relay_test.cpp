// SPDX-License-Identifier: Apache-2.0
// The fuser's robot state relay (dds/ros2_joint_state_writer.hpp, docs/MULTICAMERA.md, "Robot
// state"): a live robot (a udp_json peer, or a fake RTDE controller, in this process on
// 127.0.0.1) → JointStateRelay → sensor_msgs/JointState and the std_msgs/Float64 speed fraction on
// loopback DDS. The samples are read back with readers of the test's own (Cyclone's generated
// types, matched by the names ROS's message specs give, not the production parser), and with the
// camera side's production reader to confirm the cameras' rule when the robot goes silent. Every
// wait is bounded.
#include "../net/rtde_rig.hpp"  // the fake RTDE controller, wait_until
#include "dds/ros2_joint_state_source.hpp"
#include "dds/ros2_joint_state_writer.hpp"
#include "dds_test_util.hpp"
#include "joint_state_peers.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/net/rtde.hpp"
#include "hrcsense/net/udp_json.hpp"
#include "hrcsense/robot_state.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::relay_test {
namespace {

using test::ReaderQos;
using test::Seen;
using test::TestFloat64Reader;
using test::TestJointStateReader;
using test::UdpRobot;
using test::wait_until;

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
  ros2::JointStateRelay relay(states, {domain, topic, "", ""});
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
  // next good sample is.
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

// The fake controller's joints: a ramp of 0.5 rad/s from controller time kRampStart_s (the
// FakeClock's start, 1000 s, plus the fake's controller offset, 1234.5 s), joint j 0.1·j above
// joint 1; over the test's 4 s of controller time every joint stays within ±2π.
constexpr double kRampStart_s = 1000.0 + 1234.5;
void ramp(double t_s, JointAngles& q, JointAngles& qd) {
  for (size_t j = 0; j < kJointCount; ++j) {
    q[j] = 0.5 * (t_s - kRampStart_s) + 0.1 * static_cast<double>(j);
    qd[j] = 0.5;
  }
}

// The speed a package k says: speed_scaling 0.5 × slider (1 + k mod 8)/8, so the state's speed
// fraction (RTDE: their product) is (1 + k mod 8)/16, exact in binary.
test::FakeModes modes_of(int64_t k) {
  test::FakeModes modes;
  modes.speed_scaling = 0.5;
  modes.target_speed_fraction = static_cast<double>(1 + k % 8) / 8.0;
  return modes;
}

// Takes from `take` until `have()` reaches `count`, at most 60 s; false then.
template <typename Take, typename Have>
bool take_until(const Take& take, const Have& have, size_t count) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    take();
    if (have() >= count) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

// 2000 data packages from a fake controller at 500 Hz on its clock, as fast as the client reads
// them in real time (a FakeClock: the whole stream in a second or two), one of them with a joint
// at 1e300 rad (package 1000, no pose of a UR): each of the 1999 the source accepts goes out once,
// in order, with its speed fraction, and the rejected one never. Deterministic: TCP loses
// nothing, the source hands every accepted sample to the relay, whose queue holds more than 2000,
// and the readers are reliable keep-all, matched before the first package (a reliable writer then
// delivers everything it writes to them).
TEST(RobotStateRelay, EveryAcceptedRtdeSampleGoesOutOnceInOrderWithItsSpeedFraction) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  constexpr int64_t kPackages = 2000;
  constexpr int64_t kRejected = 1000;
  static_assert(kPackages < static_cast<int64_t>(ros2::JointStateRelay::kQueueCapacity),
                "the relay's queue holds the whole stream, however late its thread runs");
  const uint32_t domain = test::test_domain();
  const std::string ns = "/relay_rtde_" + std::to_string(::getpid());

  std::mutex sent_mutex;
  std::vector<JointAngles> sent_q;  // what the controller sent, package by package
  test::FakeRtdeScript script;
  script.samples_per_connection = kPackages;
  script.fault = test::RtdeFault::huge_joint;  // joint 2 at 1e300 rad in package kRejected
  script.fault_at = kRejected;
  script.joints = [&](double t_s, JointAngles& q, JointAngles& qd) {
    ramp(t_s, q, qd);
    const std::lock_guard<std::mutex> lock(sent_mutex);
    sent_q.push_back(q);
  };
  script.modes = modes_of;
  FakeClock clock{1'000'000'000'000};
  test::FakeRtdeController fake(script, clock);
  RtdeParams params;
  params.host = "127.0.0.1";
  params.port = fake.port();
  params.frequency_hz = 500.0;
  params.history.q_min_rad.fill(-6.3);  // a UR's ±2π, as robot.model would set them
  params.history.q_max_rad.fill(6.3);
  RtdeRobotState robot(params, clock);
  // The fake's thread calls into `robot` until it is stopped: stopped before `robot` goes.
  struct StopFirst {
    test::FakeRtdeController& fake;
    ~StopFirst() { fake.stop(); }
  } stop_first{fake};
  std::atomic<bool> stopping{false};

  const std::string joint_topic = ns + "/joint_states", speed_topic = ns + "/robot_speed_scaling";
  ros2::JointStateRelay relay(robot, {domain, joint_topic, "", speed_topic});
  TestJointStateReader joints(domain, joint_topic, ReaderQos::reliable_keep_all);
  TestFloat64Reader speeds(domain, speed_topic);
  ASSERT_TRUE(joints.ok() && speeds.ok());
  // Volatile writers send only to readers they know: discovery both ways before the stream.
  ASSERT_TRUE(wait_until([&] {
    return relay.readers_matched() > 0 && relay.speed_readers_matched() > 0 && joints.matched() && speeds.matched();
  }, 20.0)) << "the readers and the relay's writers did not discover each other";

  // Each package is sent once the client has read the one before: a stream as fast as it reads.
  fake.start([&](int64_t sent) { wait_until([&] { return stopping || robot.status().data_packages >= sent; }); });
  ASSERT_TRUE(wait_until([&] { return robot.status().data_packages >= kPackages; }, 60.0))
      << robot.status().data_packages << " of " << kPackages << " packages read; " << robot.error();
  stopping = true;
  const RobotStateStats stats = robot.stats();
  EXPECT_EQ(stats.samples.accepted, kPackages - 1);
  EXPECT_EQ(stats.samples.rejected_limits, 1);

  // The oracle: what the controller sent, without the rejected package; its speed fraction
  // worked by hand from the script's modes.
  std::vector<std::vector<double>> expected_q;
  std::vector<double> expected_speed;
  {
    const std::lock_guard<std::mutex> lock(sent_mutex);
    ASSERT_EQ(sent_q.size(), static_cast<size_t>(kPackages));
    for (int64_t k = 0; k < kPackages; ++k) {
      if (k == kRejected) continue;
      const JointAngles& q = sent_q[static_cast<size_t>(k)];
      expected_q.emplace_back(q.begin(), q.end());
      expected_speed.push_back(static_cast<double>(1 + k % 8) / 16.0);
    }
  }
  std::vector<Seen> seen;
  std::vector<double> speed_seen;
  EXPECT_TRUE(take_until([&] { joints.take(seen); }, [&] { return seen.size(); }, expected_q.size()))
      << seen.size() << " JointStates of " << expected_q.size();
  EXPECT_TRUE(take_until([&] { speeds.take(speed_seen); }, [&] { return speed_seen.size(); }, expected_speed.size()))
      << speed_seen.size() << " speed fractions of " << expected_speed.size();
  // Once more after the relay has written everything: a sample written twice would show now.
  ASSERT_TRUE(wait_until([&] { return relay.counters().published >= kPackages - 1; }, 30.0));
  joints.take(seen);
  speeds.take(speed_seen);

  ASSERT_EQ(seen.size(), expected_q.size());
  size_t mismatches = 0;
  for (size_t i = 0; i < seen.size(); ++i) {
    if (seen[i].position != expected_q[i]) ++mismatches;
    EXPECT_NE(seen[i].position[1], 1e300) << "the rejected sample was republished";
    if (i > 0) {
      EXPECT_GT(seen[i].stamp_ns, seen[i - 1].stamp_ns) << i;
    }
  }
  EXPECT_EQ(mismatches, 0U) << "JointStates out of order, changed or missing";
  EXPECT_EQ(speed_seen, expected_speed);
  const ros2::JointStateRelayCounters counters = relay.counters();
  EXPECT_EQ(counters.published, kPackages - 1);
  EXPECT_EQ(counters.speed_published, kPackages - 1);
  EXPECT_EQ(counters.refused, 0);
  EXPECT_EQ(counters.dropped, 0);
}

// robot.state.source ros2 in the fuser: a driver's JointState and speed scaling (here written by a
// JointStateWriter standing in for the driver, 0.75 as a fraction) → Ros2JointStateSource →
// the relay. Each sample the source accepted goes out once, in order, with the driver's speed
// reading. The source's own reader is best-effort as the cameras' (it may lose a sample of a
// burst): the count compared is the source's accepted count, not what the driver sent.
TEST(RobotStateRelay, ADriversJointStatesAndSpeedScalingAreRelayed) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint32_t domain = test::test_domain();
  const std::string driver_ns = "/relay_driver_" + std::to_string(::getpid());
  const std::string ns = "/relay_ros2_" + std::to_string(::getpid());
  ros2::JointStateWriter driver({domain, driver_ns + "/joint_states", "", driver_ns + "/speed_scaling"});
  SteadyClock clock;
  ros2::Ros2JointStateParams params;
  params.topic = driver_ns + "/joint_states";
  params.speed_scaling_topic = driver_ns + "/speed_scaling";
  params.speed_scaling_unit = SpeedScalingUnit::fraction;
  params.domain_id = domain;
  params.history.max_age_s = 0.5;
  ros2::Ros2JointStateSource source(params, clock);
  ros2::JointStateRelay relay(source, {domain, ns + "/joint_states", "", ns + "/robot_speed_scaling"});
  TestJointStateReader joints(domain, ns + "/joint_states", ReaderQos::reliable_keep_all);
  TestFloat64Reader speeds(domain, ns + "/robot_speed_scaling");
  ASSERT_TRUE(wait_until([&] {
    return driver.readers_matched() > 0 && driver.speed_readers_matched() > 0 && relay.readers_matched() > 0 &&
           relay.speed_readers_matched() > 0 && joints.matched() && speeds.matched();
  }, 20.0));

  // The speed reading first; then samples until one comes back with it (the reading is the
  // source's once it has arrived), then a burst of 200, 1 ms apart, the reading repeated.
  ASSERT_EQ(driver.write_speed_fraction(0.75), ros2::WriteOutcome::written);
  JointAngles q{0.1, -1.2, 1.3, -0.4, 0.5, 0.6};
  const JointAngles qd{0.5, 0.0, 0.0, 0.0, 0.0, 0.0};
  std::vector<double> speed_seen;
  for (int attempt = 0; attempt < 200 && speed_seen.empty(); ++attempt) {
    q[0] += 0.0005;
    driver.write(wall_ns(), q, qd);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    speeds.take(speed_seen);
  }
  ASSERT_FALSE(speed_seen.empty()) << "no speed fraction came back; " << source.error();
  for (int k = 0; k < 200; ++k) {
    // The reading again now and then: it holds for max_age_s (0.5 s) after its arrival.
    if (k % 10 == 0) driver.write_speed_fraction(0.75);
    q[0] += 0.0005;
    driver.write(wall_ns(), q, qd);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  // Everything the source accepted, written; then read back.
  ASSERT_TRUE(wait_until([&] {
    return source.stats().samples.accepted >= 200 && relay.counters().published == source.stats().samples.accepted;
  }, 20.0)) << relay.counters().published << " of " << source.stats().samples.accepted;
  const int64_t accepted = source.stats().samples.accepted;
  std::vector<Seen> seen;
  EXPECT_TRUE(take_until([&] { joints.take(seen); }, [&] { return seen.size(); }, static_cast<size_t>(accepted)));
  EXPECT_EQ(seen.size(), static_cast<size_t>(accepted));
  for (size_t i = 1; i < seen.size(); ++i) {
    EXPECT_GT(seen[i].position[0], seen[i - 1].position[0]) << "out of order or twice at " << i;
  }
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back().position[0], q[0]) << "the last sample is the driver's last";
  // Each sample after the reading arrived carries it: the speed fractions are 0.75, one per sample.
  const int64_t speed_published = relay.counters().speed_published;
  EXPECT_GE(speed_published, 200);
  EXPECT_TRUE(take_until([&] { speeds.take(speed_seen); }, [&] { return speed_seen.size(); },
                         static_cast<size_t>(speed_published)));
  EXPECT_EQ(speed_seen, std::vector<double>(static_cast<size_t>(speed_published), 0.75));
}

// A source that hands over no samples (a fixed arm) has nothing to relay: a clear error, not a
// silent topic.
TEST(RobotStateRelay, AFixedArmIsNotRelayed) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  FixedRobotState fixed(JointAngles{});
  EXPECT_THROW(ros2::JointStateRelay(fixed, {test::test_domain(), "/relay_fixed/joint_states", "", ""}),
               std::invalid_argument);
}

}  // namespace
}  // namespace hrcsense::relay_test
