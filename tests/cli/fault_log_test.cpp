// SPDX-License-Identifier: Apache-2.0
// Faults said when they start and when they clear (issue 31, defect 3; apps/common/fault_log):
// the tracker's timing worked by hand, then whole runs whose robot state sender is silent,
// whose recording disk is full and whose RTDE controller is not there.
#include "../support/cli_folder.hpp"
#include "../support/loopback.hpp"

#include "common/fault_log.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense::app {
namespace {

constexpr int64_t kMs = 1'000'000;

// With the default quiet time of 1 s: a fault is said when it starts; a new text 0.3 s later
// waits until a second after the last line (1.0 s), and only the newest text is said then; a
// poll without the fault 0.5 s after it was last seen clears nothing, one 1.0 s after does,
// giving how long it lasted (0 to 1.2 s).
TEST(FaultTrack, StartsOnceSaysChangesOnceASecondAndClearsAfterQuiet) {
  FaultTrack track;
  EXPECT_FALSE(track.update("", 0).has_value());
  std::optional<FaultEvent> e = track.update("stale (60 ms)", 100 * kMs);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->kind, FaultEvent::Kind::started);
  EXPECT_EQ(e->text, "stale (60 ms)");
  EXPECT_FALSE(track.update("stale (60 ms)", 200 * kMs).has_value());  // the same text
  EXPECT_FALSE(track.update("stale (90 ms)", 400 * kMs).has_value());  // new, but 0.3 s after the line
  EXPECT_FALSE(track.update("stale (120 ms)", 900 * kMs).has_value());
  e = track.update("stale (150 ms)", 1100 * kMs);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->kind, FaultEvent::Kind::changed);
  EXPECT_EQ(e->text, "stale (150 ms)");
  EXPECT_FALSE(track.update("stale (150 ms)", 1300 * kMs).has_value());
  EXPECT_FALSE(track.update("", 1800 * kMs).has_value());  // 0.5 s quiet: still in force
  EXPECT_TRUE(track.active());
  e = track.update("", 2300 * kMs);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->kind, FaultEvent::Kind::cleared);
  EXPECT_EQ(e->text, "stale (150 ms)");
  EXPECT_NEAR(e->lasted_s, 1.2, 1e-12);
  EXPECT_FALSE(track.active());
  // A new fault after the clear is a new start.
  e = track.update("stale again", 2400 * kMs);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->kind, FaultEvent::Kind::started);
}

// A fault that comes and goes faster than the quiet time (a rejected sample every 0.4 s) is one
// fault: one start, no clear in between.
TEST(FaultTrack, AFaultThatComesAndGoesIsOneFault) {
  FaultTrack track;
  int starts = 0, clears = 0;
  for (int64_t t = 0; t < 5000; t += 100) {
    const std::string problem = t % 400 == 0 ? "sample rejected" : "";
    if (const std::optional<FaultEvent> e = track.update(problem, t * kMs)) {
      starts += e->kind == FaultEvent::Kind::started ? 1 : 0;
      clears += e->kind == FaultEvent::Kind::cleared ? 1 : 0;
    }
  }
  EXPECT_EQ(starts, 1);
  EXPECT_EQ(clears, 0);
}

TEST(FaultLog, WhenRisingSaysTheTextOnlyWhenTheCountRose) {
  int64_t count = 0;
  auto probe = when_rising([&count] { return count; }, [&count] { return std::to_string(count) + " rejected"; });
  const FrameResult frame;
  EXPECT_EQ(probe(frame), "");
  count = 2;
  EXPECT_EQ(probe(frame), "2 rejected");
  EXPECT_EQ(probe(frame), "");
  count = 3;
  EXPECT_EQ(probe(frame), "3 rejected");
}

// The sink passes every frame on before it polls, and logs each probe's events under its name.
class Collect final : public Sink {
 public:
  void header(const RunHeader&) override {}
  void frame(const FrameResult& result) override { frames.push_back(result.frame); }
  void summary(const RunSummary&) override {}
  std::vector<int64_t> frames;
};

TEST(FaultLog, SinkPassesFramesOnAndLogsEachProbeUnderItsName) {
  Collect inner;
  int64_t now = 0;
  std::vector<std::string> lines;
  std::vector<FaultProbe> probes;
  probes.push_back({"robot state", [](const FrameResult& r) { return r.frame >= 2 && r.frame < 4 ? "no state" : ""; }});
  probes.push_back({"recording", [](const FrameResult& r) { return r.frame >= 3 ? "disk full" : ""; }});
  FaultLogSink sink(inner, std::move(probes), [&now] { return now; },
                    [&lines](const std::string& name, const FaultEvent& e) { lines.push_back(fault_line(name, e)); });
  FrameResult frame;
  for (int64_t i = 0; i < 40; ++i) {
    frame.frame = i;
    now = i * 100 * kMs;  // 10 frames/s
    sink.frame(frame);
  }
  EXPECT_EQ(inner.frames.size(), 40U);
  // Seen at frames 2 and 3 (0.2 to 0.3 s), cleared at the first poll a second later (1.3 s).
  const std::vector<std::string> expected{"fault: robot state: no state", "fault: recording: disk full",
                                          "fault cleared: robot state (lasted 0.1 s): no state"};
  EXPECT_EQ(lines, expected);
}

}  // namespace
}  // namespace hrcsense::app

namespace {

// A small noise-free scene (a wall 2 m in front of the camera, a robot point before it).
std::string scene(int frames) {
  return "source: {type: sim, seed: 1, pace: false}\n"
         "sim: {width: 424, height: 240, frames: " +
         std::to_string(frames) +
         ", noise: false, color: false}\n"
         "camera:\n"
         "  T_base_camera: {translation_m: [0, 0, 0], rotation_rpy_deg: [0, 0, 0]}\n"
         "filters: {preset: none}\n"
         "background: {frames: 5}\n"
         "robot: {model: points, points_base: [[0.3, 0, 1.8]]}\n"
         "scene:\n"
         "  objects:\n"
         "    - name: wall\n"
         "      static: true\n"
         "      shapes:\n"
         "        - plane: {point: [0, 0, 2.0], normal: [0, 0, 1]}\n";
}

int count_lines(const std::string& text, const std::string& part) {
  std::istringstream in(text);
  int n = 0;
  for (std::string line; std::getline(in, line);) n += line.find(part) != std::string::npos ? 1 : 0;
  return n;
}

nlohmann::json summary_of(const std::string& jsonl) {
  std::istringstream in(jsonl);
  nlohmann::json summary;
  for (std::string line; std::getline(in, line);) {
    nlohmann::json j = nlohmann::json::parse(line);
    if (j["type"] == "summary") summary = j;
  }
  return summary;
}

using FaultLogCli = hrcsense::test::CliFolder;

// A udp_json state source nobody sends to (a sender on the wrong port looks the same): the
// fault is said once when the first frame after learning finds no state, every stopped frame
// says why, and the summary keeps it. Before issue 31 this run said nothing on stderr and the
// summary's last_problem was empty.
TEST_F(FaultLogCli, ASilentUdpJsonSenderIsSaidWhenItStartsAndOnEveryFrame) {
  uint16_t port = 0;
  {
    const hrcsense::test::LoopbackUdpSocket probe;  // free now; the tool binds it a moment later
    port = probe.port;
  }
  write("cell.yaml", scene(40));
  const std::string listen = "127.0.0.1:" + std::to_string(port);
  const hrcsense::test::CliOutcome run =
      this->run("run --config cell.yaml --set robot.state.source=udp_json --set robot.state.listen=" + listen);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(count_lines(run.err, "fault: robot state: no robot state: udp_json on " + listen +
                                     ": no robot state accepted; no datagram received"),
            1)
      << run.err;
  EXPECT_EQ(count_lines(run.out, "no datagram received"), 35 + 1) << "35 frames after learning and the summary";
  const nlohmann::json summary = summary_of(run.out);
  EXPECT_NE(summary["robot_state"]["last_problem"].get<std::string>().find("no datagram received"), std::string::npos)
      << summary.dump();
}

// run --record onto a full disk (/dev/full), record.on_error continue: the failed write is said
// while the run goes on, not only in the summary at the end.
TEST_F(FaultLogCli, AFullDiskIsSaidWhenTheWriteFails) {
  write("cell.yaml", scene(60));
  const hrcsense::test::CliOutcome run =
      this->run("run --config cell.yaml --set record.on_error=continue --record /dev/full --overwrite --out out.jsonl");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(count_lines(run.err, "fault: recording: recording ended: "), 1) << run.err;
  EXPECT_NE(run.err.find("/dev/full"), std::string::npos) << run.err;
}

// link.rtde.write with no controller at robot.state.host:port: the refused connection is said
// while the run goes on.
TEST_F(FaultLogCli, AnRtdeLinkWithoutControllerIsSaid) {
  uint16_t port = 0;
  {
    // A TCP port nobody listens on: bound (not listening) and closed again.
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in self{};
    self.sin_family = AF_INET;
    self.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof self;
    ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&self), sizeof self), 0);
    ASSERT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&self), &length), 0);
    port = ntohs(self.sin_port);
    ::close(fd);
  }
  write("cell.yaml", scene(45));  // 1.5 s paced
  const hrcsense::test::CliOutcome run = this->run(
      "run --config cell.yaml --set source.pace=true --set link.rtde.write=register --set robot.state.host=127.0.0.1 "
      "--set robot.state.port=" +
      std::to_string(port) + " --out out.jsonl");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(count_lines(run.err, "fault: link.rtde: link.rtde.write register"), 1) << run.err;
}

}  // namespace
