// SPDX-License-Identifier: Apache-2.0
// `hrcsense fuse` as the owner of a cell's live robot state and scene clock (docs/MULTICAMERA.md):
// a child fuser with robot.state.source udp_json (the robot a peer in this test, on 127.0.0.1)
// republishes each accepted sample as sensor_msgs/JointState on <ns>/joint_states and its speed
// fraction as std_msgs/Float64 on <ns>/robot_speed_scaling, read with the test's own readers and
// with a camera's production reader made from the overrides `hrcsense cell` gives its cameras
// (checked against load_config's real keys); and it publishes sim.epoch on <ns>/cell_clock.
// Loopback only; every wait is bounded.
#include "../support/child_process.hpp"
#include "common/assembly.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/robot_state.hpp"
#include "dds/ros2_cell_clock.hpp"
#include "dds_test_util.hpp"
#include "joint_state_peers.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::fuse_robot_state_test {
namespace {

// One simulated camera and a live robot on udp_json at `port`.
std::string cell_yaml(uint16_t port) {
  return R"(
source: {type: sim, seed: 1}
sim: {width: 424, height: 240, fps: 30, noise: false, color: false}
cameras:
  - name: front
    T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-125, 0, 90]}
    fps: 30
robot:
  model: ur5
  state: {source: udp_json, listen: "127.0.0.1:)" +
         std::to_string(port) + R"(", max_age_s: 0.5}
safety: {mode: zones}
)";
}

// A UDP port free a moment ago (bound to 0 and released): the fuser binds it next.
uint16_t free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  ::close(fd);
  return ntohs(address.sin_port);
}

struct Files {
  std::filesystem::path dir;
  std::string config;
};

Files write_cell(const std::string& name, uint16_t port) {
  Files files;
  files.dir = std::filesystem::temp_directory_path() / ("hrcsense_fuse_state_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::create_directories(files.dir);
  files.config = (files.dir / "cell.yaml").string();
  std::ofstream(files.config) << cell_yaml(port);
  return files;
}

// The burst's sample k: joint 1 at 0.25 + 0.001·k rad (the others fixed), moving at 0.5 rad/s;
// its speed fraction (1 + k mod 4)/8, none (NaN) for every fifth; sample kRejected has a joint at
// 100 rad, no pose of a UR5, which the fuser's source rejects.
constexpr int kBurst = 400;
constexpr int kRejected = 200;
std::array<double, 6> burst_q(int k) { return {0.25 + 0.001 * k, -1.5, 1.25, -0.5, 0.75, 0.125}; }
double burst_speed(int k) { return k % 5 == 4 ? std::nan("") : (1 + k % 4) / 8.0; }

// Takes from both readers until `count` JointStates and `speed_count` speed fractions came, at
// most 30 s; false then.
bool take_until(test::TestJointStateReader& joints, std::vector<test::Seen>& seen, size_t count,
                test::TestFloat64Reader& speeds, std::vector<double>& speed_seen, size_t speed_count) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    joints.take(seen);
    speeds.take(speed_seen);
    if (seen.size() >= count && speed_seen.size() >= speed_count) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

TEST(FuseRobotState, TheFuserRepublishesTheLiveRobotAndPublishesTheSceneClock) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint16_t port = free_udp_port();
  const Files files = write_cell("relay", port);
  const uint32_t domain = test::test_domain();
  const std::string ns = "/fuse_state_" + std::to_string(::getpid());
  // Two and a quarter seconds from now: a quarter is exact in binary, so the epoch is known to the ns.
  const int64_t now_s = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  const int64_t epoch_ns = (now_s + 2) * 1'000'000'000 + 250'000'000;
  const std::vector<std::string> sets = {"ros2.domain_id=" + std::to_string(domain), "ros2.namespace=" + ns};
  test::ChildProcess fuser({HRCSENSE_CLI, "fuse", "--config", files.config, "--set", sets[0], "--set", sets[1],
                            "--set", "sim.epoch=" + std::to_string(now_s + 2) + ".25", "--out",
                            (files.dir / "fused.jsonl").string()},
                           (files.dir / "fuse.err").string());
  // Reliable keep-all: what the fuser writes once they are matched, they all get.
  test::TestJointStateReader reader(domain, ns + "/joint_states", test::ReaderQos::reliable_keep_all);
  test::TestFloat64Reader speeds(domain, ns + "/robot_speed_scaling");
  ASSERT_TRUE(reader.ok() && speeds.ok());
  // A camera of the cell, as `hrcsense cell` starts it: its robot state source from the overrides.
  const Config live = load_config(files.config, sets);
  std::vector<std::string> camera_sets = sets;
  for (const std::string& set : camera_robot_state_sets(live)) camera_sets.push_back(set);
  SteadyClock clock;
  const std::unique_ptr<RobotStateSource> camera =
      make_robot_state_source(load_config(files.config, camera_sets), &clock);
  ASSERT_EQ(camera->origin(), RobotStateOrigin::ros2);

  // The scene clock: sim.epoch, latched for a camera that joins now.
  EXPECT_EQ(ros2::wait_for_cell_clock(domain, ns, 10.0), epoch_ns);

  // The robot's samples, sent until one comes back through the fuser on both topics (its socket
  // and writers are up once the cell clock is, but discovery of the readers may take a moment):
  // from then on the fuser's writers know the readers.
  const test::UdpRobot robot(port);
  // The robot's clock: this host's steady clock, strictly increasing from datagram to datagram, so
  // that the fuser's sender-to-host map keeps the stamps near their arrival whatever the pace.
  int64_t t_ns = 0;
  const auto next_t_ns = [&t_ns] {
    using std::chrono::steady_clock;
    const int64_t now_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(steady_clock::now().time_since_epoch()).count();
    t_ns = std::max(t_ns + 1000, now_ns);
    return t_ns;
  };
  const std::array<double, 6> q = {0.23, -1.5, 1.25, -0.5, 0.75, 0.125};
  const std::array<double, 6> qd = {0.5, 0.0, 0.0, 0.0, 0.0, -0.5};
  std::vector<test::Seen> seen;
  std::vector<double> speed_seen;
  for (int attempt = 0; attempt < 250 && (seen.empty() || speed_seen.empty()); ++attempt) {
    robot.send(next_t_ns(), q, qd, 1.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    reader.take(seen);
    speeds.take(speed_seen);
  }
  ASSERT_FALSE(seen.empty() || speed_seen.empty())
      << "nothing on " << ns << "/joint_states or robot_speed_scaling within 5 s; see " << files.dir / "fuse.err";
  EXPECT_EQ(seen.front().names, (std::vector<std::string>{"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                                          "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"}));
  EXPECT_EQ(seen.front().position, std::vector<double>(q.begin(), q.end()));
  EXPECT_EQ(seen.front().velocity, std::vector<double>(qd.begin(), qd.end()));
  EXPECT_EQ(speed_seen.front(), 1.0);
  // Take the rest of the warm-up: one more sample each way marks its end.
  robot.send(next_t_ns(), q, qd, 1.0);
  const size_t warm_up = seen.size() + 1, speed_warm_up = speed_seen.size() + 1;
  ASSERT_TRUE(take_until(reader, seen, warm_up, speeds, speed_seen, speed_warm_up));
  seen.clear();
  speed_seen.clear();

  // The burst, as fast as the fuser takes them, never more than 16 ahead of what came back (the
  // socket's buffer then never overflows: UDP loses nothing on loopback but to a full buffer). Each accepted sample comes back once, in order; the
  // rejected one never; a speed fraction for each one that had one.
  std::vector<std::vector<double>> expected_q;
  std::vector<double> expected_speed;
  for (int k = 0; k < kBurst; ++k) {
    if (k == kRejected) continue;
    const std::array<double, 6> qk = burst_q(k);
    expected_q.emplace_back(qk.begin(), qk.end());
    if (!std::isnan(burst_speed(k))) expected_speed.push_back(burst_speed(k));
  }
  size_t sent_accepted = 0;
  for (int k = 0; k < kBurst; ++k) {
    ASSERT_TRUE(take_until(reader, seen, sent_accepted > 16 ? sent_accepted - 16 : 0, speeds, speed_seen, 0))
        << seen.size() << " of " << sent_accepted << " came back; see " << files.dir / "fuse.err";
    std::array<double, 6> qk = burst_q(k);
    if (k == kRejected) qk[3] = 100.0;
    robot.send(next_t_ns(), qk, qd, burst_speed(k));
    if (k != kRejected) ++sent_accepted;
  }
  EXPECT_TRUE(take_until(reader, seen, expected_q.size(), speeds, speed_seen, expected_speed.size()))
      << seen.size() << " JointStates of " << expected_q.size() << ", " << speed_seen.size()
      << " speed fractions of " << expected_speed.size();

  // The camera reads the speed fraction too: the robot's samples from now on say 0.625.
  const std::array<double, 6> last = burst_q(kBurst - 1);
  bool camera_speed = false;
  for (int attempt = 0; attempt < 150 && !camera_speed; ++attempt) {
    robot.send(next_t_ns(), last, {}, 0.625);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    RobotState state;
    camera_speed = camera->state_at(clock.now_ns(), state) && state.speed_fraction == 0.625;
  }
  EXPECT_TRUE(camera_speed) << "the camera's ros2 source never read the speed fraction; " << camera->error();
  // Once the robot stops reporting its speed, the fuser writes none, and the camera's reading goes
  // out of date after robot.state.max_age_s (0.5 s): its states have no speed fraction (NaN).
  bool camera_no_speed = false;
  for (int attempt = 0; attempt < 150 && !camera_no_speed; ++attempt) {
    robot.send(next_t_ns(), last, {});
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    RobotState state;
    camera_no_speed = camera->state_at(clock.now_ns(), state) && std::isnan(state.speed_fraction);
  }
  EXPECT_TRUE(camera_no_speed) << camera->error();

  const int status = fuser.stop(SIGTERM, 10.0);
  EXPECT_TRUE(status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  // Compared after the fuser ended: nothing more can come.
  reader.take(seen);
  speeds.take(speed_seen);
  ASSERT_GE(seen.size(), expected_q.size());
  size_t mismatches = 0;
  for (size_t i = 0; i < expected_q.size(); ++i) {
    if (seen[i].position != expected_q[i]) ++mismatches;
    EXPECT_NE(seen[i].position[3], 100.0) << "the rejected sample was republished";
  }
  EXPECT_EQ(mismatches, 0U) << "JointStates out of order, changed or missing";
  ASSERT_GE(speed_seen.size(), expected_speed.size());
  const auto burst_end = speed_seen.begin() + static_cast<std::ptrdiff_t>(expected_speed.size());
  EXPECT_EQ(std::vector<double>(speed_seen.begin(), burst_end), expected_speed);
  // After the burst only the camera phase's samples: 0.625 each while it said so, none after.
  for (size_t i = expected_speed.size(); i < speed_seen.size(); ++i) EXPECT_EQ(speed_seen[i], 0.625) << i;
  for (size_t i = expected_q.size(); i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].position, std::vector<double>(last.begin(), last.end())) << i;
  }
  std::filesystem::remove_all(files.dir);
}

TEST(FuseRobotState, TheCellsCamerasAreSetToReadTheRepublishedTopic) {
  const Files files = write_cell("sets", 30099);
  const Config live = load_config(files.config, {"ros2.namespace=/cell_a"});
  const std::vector<std::string> sets = camera_robot_state_sets(live);
  ASSERT_FALSE(sets.empty());
  std::vector<std::string> camera = {"ros2.namespace=/cell_a"};
  camera.insert(camera.end(), sets.begin(), sets.end());
  const Config read = load_config(files.config, camera);
  EXPECT_EQ(read.robot_state.source, RobotStateOrigin::ros2);
  EXPECT_EQ(read.robot_state.ros2.topic, "/cell_a/joint_states");
  // The fuser's republished speed fraction, not hrcsense's own commanded scale (/cell_a/speed_scaling).
  EXPECT_EQ(read.robot_state.ros2.speed_scaling_topic, "/cell_a/robot_speed_scaling");
  EXPECT_EQ(read.robot_state.ros2.speed_scaling_unit, SpeedScalingUnit::fraction);
  // A fixed (or simulated) arm is the cameras' own: nothing to override.
  EXPECT_TRUE(camera_robot_state_sets(load_config(files.config, {"robot.state.source=fixed", "robot.joints_rad=[0, -1.5, 1.5, -1.5, -1.5, 0]"})).empty());
  std::filesystem::remove_all(files.dir);
}

}  // namespace
}  // namespace hrcsense::fuse_robot_state_test
