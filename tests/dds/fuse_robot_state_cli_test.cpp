// SPDX-License-Identifier: Apache-2.0
// `hrcsense fuse` as the owner of a cell's live robot state and scene clock (docs/MULTICAMERA.md):
// a child fuser with robot.state.source udp_json (the robot a peer in this test, on 127.0.0.1)
// republishes the robot's samples as sensor_msgs/JointState on <ns>/joint_states, read with the
// test's own reader, and publishes sim.epoch on <ns>/cell_clock; `hrcsense cell` gives its cameras
// the overrides that make them read that topic (checked against load_config's real keys).
// Loopback only; every wait is bounded.
#include "../support/child_process.hpp"
#include "common/assembly.hpp"
#include "dds/ros2_cell_clock.hpp"
#include "dds_test_util.hpp"
#include "joint_state_peers.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <csignal>
#include <chrono>
#include <filesystem>
#include <fstream>
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

TEST(FuseRobotState, TheFuserRepublishesTheLiveRobotAndPublishesTheSceneClock) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint16_t port = free_udp_port();
  const Files files = write_cell("relay", port);
  const uint32_t domain = test::test_domain();
  const std::string ns = "/fuse_state_" + std::to_string(::getpid());
  // Two and a quarter seconds from now: a quarter is exact in binary, so the epoch is known to the ns.
  const int64_t now_s = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  const int64_t epoch_ns = (now_s + 2) * 1'000'000'000 + 250'000'000;
  test::ChildProcess fuser({HRCSENSE_CLI, "fuse", "--config", files.config, "--set", "ros2.domain_id=" + std::to_string(domain),
                      "--set", "ros2.namespace=" + ns, "--set", "sim.epoch=" + std::to_string(now_s + 2) + ".25", "--out",
                      (files.dir / "fused.jsonl").string()},
                     (files.dir / "fuse.err").string());
  test::TestJointStateReader reader(domain, ns + "/joint_states");
  ASSERT_TRUE(reader.ok());

  // The scene clock: sim.epoch, latched for a camera that joins now.
  EXPECT_EQ(ros2::wait_for_cell_clock(domain, ns, 10.0), epoch_ns);

  // The robot's samples, sent until one comes back through the fuser (its socket and writer are
  // up once the cell clock is, but discovery of the reader may take a moment).
  const test::UdpRobot robot(port);
  const std::array<double, 6> q = {0.25, -1.5, 1.25, -0.5, 0.75, 0.125};
  const std::array<double, 6> qd = {0.5, 0.0, 0.0, 0.0, 0.0, -0.5};
  std::vector<test::Seen> seen;
  int64_t t_ns = 5'000'000'000;
  for (int attempt = 0; attempt < 250 && seen.empty(); ++attempt) {
    t_ns += 20'000'000;
    robot.send(t_ns, q, qd);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    reader.take(seen);
  }
  ASSERT_FALSE(seen.empty()) << "nothing on " << ns << "/joint_states within 5 s; see " << files.dir / "fuse.err";
  EXPECT_EQ(seen.front().names, (std::vector<std::string>{"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                                          "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"}));
  EXPECT_EQ(seen.front().position, std::vector<double>(q.begin(), q.end()));
  EXPECT_EQ(seen.front().velocity, std::vector<double>(qd.begin(), qd.end()));

  const int status = fuser.stop(SIGTERM, 10.0);
  EXPECT_TRUE(status >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
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
  // A fixed (or simulated) arm is the cameras' own: nothing to override.
  EXPECT_TRUE(camera_robot_state_sets(load_config(files.config, {"robot.state.source=fixed", "robot.joints_rad=[0, -1.5, 1.5, -1.5, -1.5, 0]"})).empty());
  std::filesystem::remove_all(files.dir);
}

}  // namespace
}  // namespace hrcsense::fuse_robot_state_test
