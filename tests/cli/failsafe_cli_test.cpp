// SPDX-License-Identifier: Apache-2.0
// R1 through the executable: the issue's commands, signals, a reader that leaves, flushing,
// exit codes. Each child process is bounded in time: a test that waits too long kills it.
#include "../support/scenes.hpp"
#include "../support/child_process.hpp"
#include "../support/cli_folder.hpp"
#include "../support/sanitized.hpp"
#include "hrcsense/io/io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

using hrcsense::test::scene_path;

using nlohmann::json;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

using hrcsense::test::read_text;

std::vector<json> json_lines(const std::string& text) {
  std::vector<json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(json::parse(line));
  }
  return lines;
}

// `hrcsense ARGS` as a child process, its stdout a pipe we read, its stderr a file.
class Child : public hrcsense::test::ChildProcess {
 public:
  Child(const std::vector<std::string>& args, const fs::path& err_path)
      : ChildProcess(with_cli(args), err_path.string()) {}

 private:
  static std::vector<std::string> with_cli(std::vector<std::string> args) {
    args.insert(args.begin(), HRCSENSE_CLI);
    return args;
  }
};

class FailsafeCli : public hrcsense::test::CliFolder {
 protected:
  using Outcome = hrcsense::test::CliOutcome;

  // The last lines of a run that a signal ended: a stop frame line, then the summary.
  static void expect_stop_then_summary(const std::vector<json>& lines, const std::string& end_reason) {
    ASSERT_GE(lines.size(), 3U);
    const json& summary = lines.back();
    EXPECT_EQ(summary["type"], "summary");
    EXPECT_EQ(summary["end_reason"], end_reason);
    const json& last = lines[lines.size() - 2];
    EXPECT_EQ(last["type"], "verdict");  // a stop that stands for no new source frame
    EXPECT_EQ(last["verdict"], "stop");
  }

  // Sends `signal` to a paced run once its output has a frame line; returns the lines.
  std::vector<json> signal_a_paced_run(int signal, int& exit_status) {
    const fs::path out = dir_ / "out.jsonl";
    Child child({"run", "--config", scene_path("thesis-box.yaml"), "--set", "source.pace=true", "--set",
                 "sim.width=424", "--set", "sim.height=240", "--frames", "3000", "--out", out.string()},
                dir_ / "stderr.txt");
    const Clock::time_point deadline = Clock::now() + std::chrono::seconds(60);
    while (read_text(out).find("\"type\":\"frame\"") == std::string::npos && Clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ::kill(child.pid(), signal);
    exit_status = child.wait(30.0);
    return json_lines(read_text(out));
  }
};

// Item 1, the issue's command: a rotation of 1e39 degrees is inf as a float.
TEST_F(FailsafeCli, RotationThatOverflowsFloatIsAConfigError) {
  const std::string people = std::string(HRCSENSE_SHARED_DIR) + "/data/ist_piv_lab_people";
  if (!fs::exists(people)) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  const Outcome outcome = run("run --set source.type=folder --set source.path='" + people +
                              "' --set background.frames=3 --set filters.preset=none "
                              "--set 'camera.T_base_camera.rotation_rpy_deg=[1e39,0,0]'");
  EXPECT_EQ(outcome.exit_code, 2) << outcome.err;
  EXPECT_NE(outcome.err.find("camera.T_base_camera.rotation_rpy_deg"), std::string::npos) << outcome.err;
  EXPECT_TRUE(outcome.out.empty());
}

// Item 2, the issue's command: a threshold at 0.5 m leaves (almost) nothing of the cell. No
// frame may say run; frame 190, with the person 0.29 m from the robot, is a stop.
TEST_F(FailsafeCli, ThresholdThatEmptiesTheFramesNeverRuns) {
  const Outcome outcome = run("run --config '" + scene_path("walk.yaml") + "' --set filters.threshold.max=0.5" +
                              (hrcsense::test::kSanitized ? " --frames 200 --set sim.width=424 --set sim.height=240" : ""));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  int frames = 0;
  for (const json& line : json_lines(outcome.out)) {
    if (line["type"] != "frame") continue;
    ++frames;
    EXPECT_EQ(line["verdict"], "stop") << line.dump();
    if (line["frame"] == 190) {
      EXPECT_FALSE(line["valid"].get<bool>());
    }
  }
  EXPECT_GE(frames, 200);
}

// Item 3: with the issue's padding the person reaches inside the capsules; every such frame is
// a stop, and a stop distance of 0 is refused.
TEST_F(FailsafeCli, InsideTheRobotIsAlwaysStop) {
  const std::string smaller = hrcsense::test::kSanitized ? " --set sim.width=424 --set sim.height=240" : "";
  Outcome outcome = run("run --config '" + scene_path("walk.yaml") +
                        "' --set safety.stop_distance_m=0 --set safety.slow_distance_m=0 --set robot.padding_m=0.35");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_NE(outcome.err.find("safety.stop_distance_m"), std::string::npos) << outcome.err;

  outcome = run("run --config '" + scene_path("walk.yaml") +
                "' --set safety.stop_distance_m=0.001 --set safety.slow_distance_m=0.001 --set robot.padding_m=0.35" +
                smaller);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  int inside = 0;
  for (const json& line : json_lines(outcome.out)) {
    if (line["type"] != "frame" || !line["inside"].is_boolean() || !line["inside"].get<bool>()) continue;
    ++inside;
    EXPECT_EQ(line["verdict"], "stop") << line.dump();
  }
  EXPECT_GT(inside, 10);  // the issue saw 41
}

// Item 4: every line is flushed. Paced at 1 frame/s, the first frame line must reach a pipe
// while the run is still going (block-buffered, it arrived only when the run ended).
TEST_F(FailsafeCli, FrameLinesReachAPipeWhileTheRunGoesOn) {
  Child child({"run", "--config", scene_path("thesis-box.yaml"), "--set", "source.pace=true", "--set", "sim.fps=1",
               "--set", "safety.max_frame_age_s=5", "--set", "background.frames=1", "--set", "sim.width=424",
               "--set", "sim.height=240", "--frames", "3"},
              dir_ / "stderr.txt");
  std::string line;
  ASSERT_TRUE(child.read_line(line, 30.0)) << read_text(dir_ / "stderr.txt");
  EXPECT_EQ(json::parse(line)["type"], "header");
  ASSERT_TRUE(child.read_line(line, 30.0));
  EXPECT_EQ(json::parse(line)["type"], "frame");
  EXPECT_TRUE(child.running()) << "the first frame line arrived only after the run had ended";
  const int status = child.wait(30.0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

// Item 5: SIGTERM (systemd's stop) and SIGHUP end the run like SIGINT: a final stop, a summary.
TEST_F(FailsafeCli, SigtermEndsWithStopAndSummary) {
  int status = 0;
  const std::vector<json> lines = signal_a_paced_run(SIGTERM, status);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir_ / "stderr.txt");
  expect_stop_then_summary(lines, "stop requested");
}

TEST_F(FailsafeCli, SighupEndsWithStopAndSummary) {
  int status = 0;
  const std::vector<json> lines = signal_a_paced_run(SIGHUP, status);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir_ / "stderr.txt");
  expect_stop_then_summary(lines, "stop requested");
}

// S1: Ctrl-Z (SIGTSTP) ends the run like SIGINT; a suspended process would look alive to the
// consumers of its output while it decides nothing.
TEST_F(FailsafeCli, SigtstpEndsWithStopAndSummary) {
  int status = 0;
  const std::vector<json> lines = signal_a_paced_run(SIGTSTP, status);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir_ / "stderr.txt");
  expect_stop_then_summary(lines, "stop requested");
}

// S1: the whole process frozen (SIGSTOP, as a VM pause or a debugger would) for 0.5 s while
// it runs paced at 30 frames/s, then thawed. Whatever was measured before the freeze is
// decided after it, at its real age: no line may say run or slow for a frame older than the
// no-frame limit (2 periods, 66.7 ms). Several freezes, so that some fall between a
// measurement and its write.
TEST_F(FailsafeCli, FrozenProcessWritesNothingOldAsRunOrSlow) {
  const fs::path out = dir_ / "out.jsonl";
  Child child({"run", "--config", scene_path("thesis-box.yaml"), "--set", "source.pace=true", "--set",
               "sim.width=424", "--set", "sim.height=240", "--set", "background.frames=10", "--frames", "3000",
               "--out", out.string()},
              dir_ / "stderr.txt");
  const Clock::time_point deadline = Clock::now() + std::chrono::seconds(60);
  while (read_text(out).find("\"verdict\":\"run\"") == std::string::npos && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_NE(read_text(out).find("\"verdict\":\"run\""), std::string::npos) << "the run never said run";
  for (int freeze = 0; freeze < 4; ++freeze) {
    std::this_thread::sleep_for(std::chrono::milliseconds(97 + 31 * freeze));  // a different phase each time
    ::kill(child.pid(), SIGSTOP);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    ::kill(child.pid(), SIGCONT);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(child.pid(), SIGINT);
  const int status = child.wait(30.0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir_ / "stderr.txt");
  const std::vector<json> lines = json_lines(read_text(out));
  int moving = 0;
  for (const json& line : lines) {
    if (line["type"] != "frame" || line["verdict"] == "stop") continue;
    ++moving;
    EXPECT_LE(line["frame_age_s"].get<double>(), 2.0 / 30.0) << line.dump();
  }
  EXPECT_GT(moving, 0);
}

TEST_F(FailsafeCli, SigintEndsWithStopAndSummary) {
  int status = 0;
  const std::vector<json> lines = signal_a_paced_run(SIGINT, status);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir_ / "stderr.txt");
  expect_stop_then_summary(lines, "stop requested");
}

// Item 5: a reader that goes away (SIGPIPE) makes the write fail; the run ends by itself with
// one error line and exit 1 instead of dying of the signal.
TEST_F(FailsafeCli, ClosedPipeEndsTheRunWithAnError) {
  Child child({"run", "--config", scene_path("thesis-box.yaml"), "--set", "source.pace=true", "--set",
               "sim.width=424", "--set", "sim.height=240", "--frames", "3000"},
              dir_ / "stderr.txt");
  std::string line;
  ASSERT_TRUE(child.read_line(line, 30.0));
  child.close_output();
  const int status = child.wait(30.0);
  ASSERT_NE(status, -1) << "the run did not end after its reader left";
  EXPECT_FALSE(WIFSIGNALED(status)) << "killed by signal " << WTERMSIG(status);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string err = read_text(dir_ / "stderr.txt");
  EXPECT_NE(err.find("hrcsense: error: stdout: write failed"), std::string::npos) << err;
}

// Item 6: a processing error is one error line and exit 1. Three 5000x5000 frames under a
// 400 MB address-space limit run out of memory while they are filtered (the source can still
// read them; not under the sanitizers, whose shadow memory needs terabytes of address space).
TEST_F(FailsafeCli, OutOfMemoryWhileProcessingExits1) {
  if (hrcsense::test::kSanitized) GTEST_SKIP() << "ulimit -v cannot be combined with AddressSanitizer";
  const fs::path folder = dir_ / "huge";
  fs::create_directories(folder / "depth");
  std::ofstream(folder / "intrinsics.json")
      << R"({"width": 5000, "height": 5000, "fx": 3000, "fy": 3000, "ppx": 2499.5, "ppy": 2499.5,)"
      << R"( "model": "None", "coeffs": [0, 0, 0, 0, 0]})";
  hrcsense::DepthImage depth;
  depth.resize(5000, 5000);
  std::fill(depth.pixels.begin(), depth.pixels.end(), uint16_t{2000});
  for (int i = 0; i < 3; ++i) hrcsense::write_depth_png((folder / "depth" / (std::to_string(i) + ".png")).string(), depth);
  const Outcome outcome = run("run --set source.type=folder --set source.path=huge", "ulimit -v 400000;");
  EXPECT_EQ(outcome.exit_code, 1) << outcome.err;
  EXPECT_NE(outcome.err.find("hrcsense: error: processing error at frame "), std::string::npos) << outcome.err;
  EXPECT_NE(outcome.err.find("std::bad_alloc"), std::string::npos) << outcome.err;
  // The output still ends with a stop and a summary naming the error.
  const std::vector<json> lines = json_lines(outcome.out);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back()["type"], "summary");
  EXPECT_TRUE(lines.back()["error"].is_string());
}

// Item 8: --frames is bounded; beyond 10^10 it is a usage error naming the flag.
TEST_F(FailsafeCli, FramesBeyondTheCapIsAUsageError) {
  const Outcome outcome = run("run --frames 1000000000000");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_NE(outcome.err.find("--frames"), std::string::npos) << outcome.err;
  EXPECT_TRUE(outcome.out.empty());
}

// Also: a background file from another view (the camera turned by 20 degrees) is refused
// after the first frames with one error line, exit 1.
TEST_F(FailsafeCli, BackgroundFromAnotherViewIsRefused) {
  const std::string base = "run --config '" + scene_path("thesis-box.yaml") +
                           "' --set sim.width=424 --set sim.height=240 --set background.frames=10 "
                           "--set background.path=bg.bin ";
  Outcome outcome = run(base + "--frames 12");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  outcome = run(base + "--frames 12 --set 'camera.T_base_camera.rotation_rpy_deg=[0,20,0]'");
  EXPECT_EQ(outcome.exit_code, 1) << outcome.err;
  // The 5th frame completes the check and names itself.
  EXPECT_NE(outcome.err.find("processing error at frame 4: background.path 'bg.bin': does not match the scene"),
            std::string::npos)
      << outcome.err;
  const std::vector<json> lines = json_lines(outcome.out);
  ASSERT_FALSE(lines.empty());
  for (const json& line : lines) {
    if (line["type"] == "frame") {
      EXPECT_EQ(line["verdict"], "stop") << line.dump();
    }
  }
}

}  // namespace
