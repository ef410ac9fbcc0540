// SPDX-License-Identifier: Apache-2.0
// `hrcsense record` and `hrcsense run --record` as child processes: frame and duration limits,
// joint states, a full disk, SIGINT (closed and indexed) and SIGKILL (readable up to the last
// complete chunk). Every child is bounded in time. Needs no ../shared data.
#include "../support/scenes.hpp"
#include "recordings_test_util.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/recordings/recordings.hpp"
#include "src/recordings/bag_messages.hpp"
#include "src/recordings/bag_reader.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <thread>

namespace hrcsense {
namespace {

using test::scene_path;

namespace fs = std::filesystem;
using test::ScratchDir;

std::unique_ptr<Source> cell_source(int frames, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> sets = {"sim.frames=" + std::to_string(frames)};
  sets.insert(sets.end(), extra.begin(), extra.end());
  return make_source(load_config(scene_path("cell-ur5.yaml"), sets));
}

// Starts `hrcsense record` of an endless 424x240 cell-ur5 into `path` as a child process
// (stderr silenced) and returns once the file holds at least `bytes` or 60 s have passed.
pid_t start_endless_recording(const std::string& path, uintmax_t bytes) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDERR_FILENO);
    std::vector<std::string> args = {HRCSENSE_CLI, "record", "--config", scene_path("cell-ur5.yaml"), "--out", path,
                                     "--set", "sim.width=424", "--set", "sim.height=240", "--set", "sim.frames=100000"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(HRCSENSE_CLI, argv.data());
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::error_code ec;
  while (pid > 0 && std::chrono::steady_clock::now() < deadline && (!fs::exists(path) || fs::file_size(path, ec) < bytes)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return pid;
}

// ---- `hrcsense record` killed with SIGKILL mid-recording.

TEST(RecordCli, KilledWithSigkillTheFileIsReadableUpToItsLastCompleteChunk) {
  ScratchDir dir("recorder");
  const std::string path = dir / "killed.bag";
  // Kill it once it has written a few MB.
  const pid_t pid = start_endless_recording(path, 4U << 20);
  ASSERT_GE(pid, 0);
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the recording ended before it was killed (status " << status << ")";
  ASSERT_GE(fs::file_size(path), 4U << 20) << "no recording within 60 s";

  const RecordingSummary summary = summarize_recording(path);
  EXPECT_FALSE(summary.indexed) << "a killed recording has no index";
  ASSERT_EQ(summary.streams.size(), 2U);
  EXPECT_GT(summary.streams[0].frames, 5);
  std::cout << "[killed] " << fs::file_size(path) << " bytes, " << summary.streams[0].frames
            << " frames readable; " << (summary.damage.empty() ? "ends at a chunk boundary" : summary.damage) << "\n";
  // Every frame before the cut is the simulator's own.
  std::unique_ptr<Source> truth = cell_source(100000, {"sim.width=424", "sim.height=240"});
  RecordingParams params{path};
  params.with_color = true;
  BagSource bag(params);
  Frame want, got;
  int64_t frames = 0;
  Source::Status status_got = Source::Status::frame;
  while (frames <= summary.streams[0].frames && (status_got = bag.next(got)) == Source::Status::frame) {
    ASSERT_EQ(truth->next(want), Source::Status::frame);
    ASSERT_EQ(got.depth.pixels, want.depth.pixels) << "frame " << frames;
    ASSERT_TRUE(got.color.has_value());
    ASSERT_EQ(got.color->rgb, want.color->rgb) << "frame " << frames;
    ++frames;
  }
  EXPECT_EQ(frames, summary.streams[0].frames);
  // The cut chunk (if the kill fell inside one) is an error naming the file, not a crash.
  if (status_got == Source::Status::error) {
    EXPECT_NE(bag.error().find(path), std::string::npos) << bag.error();
  }
}

TEST(RecordCli, SigintClosesAndIndexesTheRecording) {
  ScratchDir dir("recorder");
  const std::string path = dir / "stopped.bag";
  const pid_t pid = start_endless_recording(path, 1U << 20);
  ASSERT_GE(pid, 0);
  ::kill(pid, SIGINT);
  int status = 0;
  for (int i = 0; i < 3000 && ::waitpid(pid, &status, WNOHANG) == 0; ++i) {  // 30 s at most
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (i == 2999) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
    }
  }
  ASSERT_TRUE(WIFEXITED(status)) << "status " << status;
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const RecordingSummary summary = summarize_recording(path);
  EXPECT_TRUE(summary.indexed);
  EXPECT_TRUE(summary.damage.empty()) << summary.damage;
  EXPECT_GT(summary.streams[0].frames, 0);
}

TEST(RecordCli, RecordsTheRequestedFramesAndDuration) {
  ScratchDir dir("recorder");
  const auto run = [&](const std::vector<std::string>& extra) {
    std::string command = std::string(HRCSENSE_CLI) + " record --config " + scene_path("cell-ur5.yaml") +
                          " --set sim.width=424 --set sim.height=240 --set sim.frames=60";
    for (const std::string& e : extra) command += " " + e;
    return std::system((command + " 2>" + (dir / "err.txt")).c_str());
  };
  ASSERT_EQ(run({"--out", dir / "n.bag", "--frames", "7"}), 0);
  EXPECT_EQ(summarize_recording(dir / "n.bag").streams[0].frames, 7);
  // The cell's fixed arm: every frame's joint state is robot.joints_rad of the configuration.
  const JointAngles joints_rad = load_config(scene_path("cell-ur5.yaml"), {}).robot_state.joints_rad;
  BagReader reader(dir / "n.bag");
  BagMessage m;
  int joint_states = 0;
  for (int guard = 0; guard < 1000 && reader.next(m); ++guard) {
    if (reader.connections().at(m.conn).topic != "/hrcsense/joint_states") continue;
    ++joint_states;
    bag::JointStateMessage joints;
    ASSERT_EQ(bag::parse_joint_state(bag::Cursor{m.data, m.size}, joints), "");
    EXPECT_EQ(joints.position_rad, joints_rad);
  }
  EXPECT_EQ(joint_states, 7);
  // 30 frames/s: 0.5 s of source time holds frames 0..14.
  ASSERT_EQ(run({"--out", dir / "d.bag", "--duration-s", "0.5"}), 0);
  EXPECT_EQ(summarize_recording(dir / "d.bag").streams[0].frames, 15);
  EXPECT_NE(run({"--out", dir / "x.bag", "--frames", "2", "--duration-s", "1"}), 0) << "one or the other";
  EXPECT_NE(run({"--out", "/dev/full", "--overwrite"}), 0);  // /dev/full exists: replacing it is asked for
  const std::vector<char> err = test::read_bytes(dir / "err.txt");
  EXPECT_NE(std::string(err.begin(), err.end()).find("/dev/full: write failed"), std::string::npos);
}

TEST(RecordCli, RunWithRecordWritesTheSourceFramesBeforeFilters) {
  ScratchDir dir("recorder");
  const std::string command = std::string(HRCSENSE_CLI) + " run --config " + scene_path("cell-ur5.yaml") +
                              " --set sim.width=424 --set sim.height=240 --set sim.frames=12 --set record.queue_frames=64" +
                              " --record " + (dir / "run.bag") + " --out " + (dir / "out.jsonl") + " 2>/dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  RecordingParams params{dir / "run.bag"};
  BagSource bag(params);
  std::unique_ptr<Source> truth = cell_source(12, {"sim.width=424", "sim.height=240"});
  Frame want, got;
  int frames = 0;
  for (int i = 0; i < 13 && bag.next(got) == Source::Status::frame; ++i) {
    ASSERT_EQ(truth->next(want), Source::Status::frame);
    EXPECT_EQ(got.depth.pixels, want.depth.pixels) << "frame " << i << ": unfiltered";
    ++frames;
  }
  EXPECT_EQ(frames, 12) << "a 64-frame queue holds the whole run";
}

}  // namespace
}  // namespace hrcsense
