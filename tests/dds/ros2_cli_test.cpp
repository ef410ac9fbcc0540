// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` with source.type ros2 fed by `hrcsense publish`, both child processes on
// loopback: the cell stops (no_frame) while the camera is silent and carries on by itself
// when a publisher is back. Every wait is bounded; a child still running at the end is killed.
#include "../support/scenes.hpp"
#include "dds_test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

// Runs the CLI with `args`, its stderr discarded and its stdout into `stdout_path` (empty:
// inherited).
pid_t spawn(std::vector<std::string> args, const std::string& stdout_path = {}) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDERR_FILENO);
    if (!stdout_path.empty()) {
      const int out = ::open(stdout_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (out < 0) ::_exit(126);
      ::dup2(out, STDOUT_FILENO);
    }
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(HRCSENSE_CLI, argv.data());
    ::_exit(127);
  }
  return pid;
}

// The exit status, or -1 after killing a child that did not end within `timeout`.
int wait_exit(pid_t pid, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::this_thread::sleep_for(20ms);
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

std::vector<json> read_lines(const std::string& path) {
  std::vector<json> lines;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\n') line.pop_back();
    try {
      lines.push_back(json::parse(line));
    } catch (const json::exception&) {
      break;  // a line being written
    }
  }
  return lines;
}

bool has_watchdog_stop(const std::string& path) {
  for (const json& line : read_lines(path)) {
    if (line["type"] == "verdict" && line["reason_code"] == "no_frame") return true;
  }
  return false;
}

// A person walking through a simulated cell (the demo's scene).
const std::string kWalk = test::scene_path("walk.yaml");

std::vector<std::string> publisher_args(const std::string& domain, int frames) {
  return {HRCSENSE_CLI, "publish", "--config", kWalk, "--set", "sim.width=424", "--set", "sim.height=240", "--set", "sim.frames=300",
          "--set", "publish.namespace=/cli/camera", "--set", "publish.domain_id=" + domain,
          "--set", "publish.wait_for_subscribers=1", "--frames", std::to_string(frames)};
}

TEST(Ros2Cli, SilentCameraStopsTheCellAndTheRunResumesWhenItIsBack) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string domain = std::to_string(test::test_domain());
  const std::string out = std::string(::testing::TempDir()) + "ros2_cli_run.jsonl";
  std::remove(out.c_str());
  const pid_t run = spawn({HRCSENSE_CLI, "run", "--config", kWalk, "--set", "source.type=ros2", "--set", "source.ros2.namespace=/cli/camera",
                           "--set", "source.ros2.domain_id=" + domain, "--set", "source.ros2.startup_timeout_s=30",
                           "--set", "background.frames=5", "--frames", "30", "--out", out});
  ASSERT_GT(run, 0);
  const pid_t first = spawn(publisher_args(domain, 15));
  ASSERT_GT(first, 0);
  EXPECT_EQ(wait_exit(first, 30s), 0);

  // The camera is silent now: within a few watchdog periods (safety.max_frame_age_s 0.5 s) the
  // run writes stops of its own.
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (!has_watchdog_stop(out) && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(50ms);
  ASSERT_TRUE(has_watchdog_stop(out)) << "no no_frame stop while the camera was silent";

  const pid_t second = spawn(publisher_args(domain, 200));
  ASSERT_GT(second, 0);
  const int run_exit = wait_exit(run, 60s);
  ::kill(second, SIGTERM);
  wait_exit(second, 10s);
  ASSERT_EQ(run_exit, 0) << "the run did not reach its 30 frames after the publisher came back";

  const std::vector<json> lines = read_lines(out);
  ASSERT_GE(lines.size(), 3U);
  EXPECT_EQ(lines.front()["source"]["type"], "ros2");
  EXPECT_EQ(lines.front()["intrinsics"]["width"], 424);
  const json& summary = lines.back();
  ASSERT_EQ(summary["type"], "summary");
  EXPECT_EQ(summary["frames_in"], 30);
  EXPECT_TRUE(summary.contains("frames_dropped_camera"));
  // Frames on both sides of the silence, and processed ones after it (the background was
  // learnt from the first publisher's frames).
  size_t first_stop = 0, frames_after = 0, valid_after = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (first_stop == 0 && lines[i]["type"] == "verdict" && lines[i]["reason_code"] == "no_frame") first_stop = i;
    if (first_stop != 0 && lines[i]["type"] == "frame") {
      ++frames_after;
      valid_after += lines[i]["valid"].get<bool>() ? 1 : 0;
    }
  }
  ASSERT_GT(first_stop, 0U);
  EXPECT_GT(frames_after, 0U);
  EXPECT_GT(valid_after, 0U);
  for (size_t i = first_stop; i < lines.size(); ++i) {
    if (lines[i]["type"] == "verdict" && lines[i]["reason_code"] == "no_frame") {
      EXPECT_EQ(lines[i]["verdict"], "stop");
    }
  }
}

// `hrcsense info` with a ros2 source describes the camera that answers (its topic, domain and
// stream), not the simulator's settings of the same file.
TEST(Ros2Cli, InfoDescribesTheCameraThatAnswers) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string domain = std::to_string(test::test_domain());
  const std::string out = std::string(::testing::TempDir()) + "ros2_cli_info_" + std::to_string(::getpid()) + ".txt";
  const pid_t publisher = spawn(publisher_args(domain, 200));
  ASSERT_GT(publisher, 0);
  const pid_t info = spawn({HRCSENSE_CLI, "info", "--config", kWalk, "--set", "source.type=ros2", "--set",
                            "source.ros2.namespace=/cli/camera", "--set", "source.ros2.domain_id=" + domain, "--set",
                            "source.ros2.startup_timeout_s=30"},
                           out);
  ASSERT_GT(info, 0);
  const int info_exit = wait_exit(info, 40s);
  ::kill(publisher, SIGTERM);
  wait_exit(publisher, 10s);
  ASSERT_EQ(info_exit, 0);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("source: ros2, ROS 2 /cli/camera/depth/image_rect_raw (domain " + domain + ")"),
            std::string::npos) << text;
  EXPECT_NE(text.find("resolution: 424x240 at 30 frames/s"), std::string::npos) << text;
  EXPECT_EQ(text.find("sim"), std::string::npos) << "the simulator's settings printed:\n" << text;
  std::remove(out.c_str());
}

// A run whose ROS 2 camera never answers still writes what every run writes (issue 31, defect
// 5): the header, a stop and a summary that names the error as a source error, exit 1.
void expect_start_failure(const std::string& out, const std::string& error_part) {
  const std::vector<json> lines = read_lines(out);
  ASSERT_GE(lines.size(), 3U) << "header, stop, summary";
  EXPECT_EQ(lines.front()["type"], "header");
  EXPECT_EQ(lines.front()["source"]["type"], "ros2");
  const json& stop = lines[lines.size() - 2];
  EXPECT_EQ(stop["verdict"], "stop") << stop.dump();
  const json& summary = lines.back();
  ASSERT_EQ(summary["type"], "summary");
  EXPECT_EQ(summary["end_reason_code"], "source_error") << summary.dump();
  EXPECT_EQ(summary["frames_in"], 0);
  ASSERT_TRUE(summary["error"].is_string()) << summary.dump();
  EXPECT_NE(summary["error"].get<std::string>().find(error_part), std::string::npos) << summary.dump();
}

std::vector<std::string> silent_camera_run(const std::string& domain, const std::string& timeout_s,
                                           const std::string& out) {
  return {HRCSENSE_CLI, "run", "--config", kWalk, "--set", "source.type=ros2", "--set",
          "source.ros2.namespace=/nobody/camera", "--set", "source.ros2.domain_id=" + domain, "--set",
          "source.ros2.startup_timeout_s=" + timeout_s, "--out", out};
}

TEST(Ros2Cli, NoCameraWithinTheStartupTimeoutIsASourceErrorWithOutput) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string out = std::string(::testing::TempDir()) + "ros2_cli_no_camera.jsonl";
  std::remove(out.c_str());
  const pid_t run = spawn(silent_camera_run(std::to_string(test::test_domain()), "0.5", out));
  ASSERT_GT(run, 0);
  EXPECT_EQ(wait_exit(run, 30s), 1);
  expect_start_failure(out, "no CameraInfo on /nobody/camera/depth/camera_info");
  std::remove(out.c_str());
}

TEST(Ros2Cli, ASignalWhileWaitingForTheCameraEndsWithOutput) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string out = std::string(::testing::TempDir()) + "ros2_cli_signal.jsonl";
  std::remove(out.c_str());
  const pid_t run = spawn(silent_camera_run(std::to_string(test::test_domain()), "60", out));
  ASSERT_GT(run, 0);
  std::this_thread::sleep_for(1500ms);  // well into the wait (the process starts in ~0.1 s)
  ::kill(run, SIGINT);
  EXPECT_EQ(wait_exit(run, 20s), 1) << "the wait should end within 0.1 s of the signal";
  expect_start_failure(out, "stopped while waiting for the first CameraInfo on /nobody/camera/depth/camera_info");
  std::remove(out.c_str());
}

}  // namespace
}  // namespace hrcsense
