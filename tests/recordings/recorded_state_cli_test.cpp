// SPDX-License-Identifier: Apache-2.0
// `robot.state.source: recorded` end to end (issue C2 part 3), with the built `hrcsense`: the
// moving-arm cell (config/cell-ur5-moving.yaml, its arm on the simulator's trajectory) processed
// and recorded by `hrcsense run --record`, then replayed from the bag with the recorded joint
// states: every frame gets the joints the first run measured it against, unpaced and paced, as
// its JSON output says. Also: `hrcsense record`'s bags replay the same way, the joints carry UR's
// names, a bag without joint states is a clear error, and the summary's `record` counters.
// 424x240 frames, at most 90 of them. No ../shared data.
#include "../support/scenes.hpp"
#include "recordings_test_util.hpp"

#include "hrcsense/recordings/bag_writer.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"
#include "src/recordings/bag_messages.hpp"
#include "src/recordings/bag_reader.hpp"
#include "../support/run_cli.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::scene_path;

using nlohmann::json;

constexpr int kRecordedFrames = 90;  // a full 2.7 s pick-and-place cycle and some

// The moving cell at 424x240 with a short background.
std::string moving_cell(int frames) {
  return "--config " + scene_path("cell-ur5-moving.yaml") + " --set sim.width=424 --set sim.height=240 --set sim.frames=" +
         std::to_string(frames) + " --set background.frames=20";
}

std::string replay(const std::string& bag) {
  return "--config " + scene_path("cell-ur5-moving.yaml") + " --set source.type=bag --set source.path=" + bag +
         " --set robot.state.source=recorded --set background.frames=20";
}

struct RunOutput {
  std::map<int64_t, json> frames;  ///< `frame` lines by source frame index
  json summary;
};

RunOutput read_run(const std::string& path) {
  RunOutput out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    json j = json::parse(line);
    if (j["type"] == "frame") out.frames[j["frame"].get<int64_t>()] = j;
    if (j["type"] == "summary") out.summary = j;
  }
  return out;
}

// A folder for the whole suite (ScratchDir names itself after the running test: none yet).
struct SuiteDir {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("hrcsense_recorded_state_" + std::to_string(::getpid()));
  SuiteDir() {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~SuiteDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

// The moving cell processed and recorded once for the whole suite (about a second).
class RecordedState : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new SuiteDir();
    live_run_ = new test::CliResult(test::cli("run " + moving_cell(kRecordedFrames) + " --set record.queue_frames=128 --record " +
                                              (*dir_ / "moving.bag") + " --out " + (*dir_ / "live.jsonl")));
    live_ = new RunOutput(live_run_->exit_code == 0 ? read_run(*dir_ / "live.jsonl") : RunOutput{});
  }
  static void TearDownTestSuite() {
    delete live_;
    delete live_run_;
    delete dir_;
  }
  void SetUp() override { ASSERT_EQ(live_run_->exit_code, 0) << "the recorded live run failed: " << live_run_->out; }
  static SuiteDir* dir_;
  static test::CliResult* live_run_;
  static RunOutput* live_;
};
SuiteDir* RecordedState::dir_ = nullptr;
test::CliResult* RecordedState::live_run_ = nullptr;
RunOutput* RecordedState::live_ = nullptr;

TEST_F(RecordedState, TheLiveRunRecordedEveryFrameAndSaysSoInItsSummary) {
  ASSERT_EQ(live_->frames.size(), static_cast<size_t>(kRecordedFrames));
  const json& record = live_->summary["record"];
  ASSERT_TRUE(record.is_object()) << live_->summary.dump();
  EXPECT_EQ(record["frames_recorded"], kRecordedFrames);
  EXPECT_EQ(record["frames_dropped"], 0);
  EXPECT_EQ(record["files"], json::array({*dir_ / "moving.bag"}));
  EXPECT_TRUE(record["error"].is_null());
  EXPECT_EQ(live_->summary["frames_dropped"], 0) << "the pipeline's own drops stay apart";
  // The arm moves: a replay with one fixed pose could not match every frame.
  EXPECT_NE(live_->frames.at(0)["joints_rad"], live_->frames.at(40)["joints_rad"]);
}

TEST_F(RecordedState, AReplayMeasuresEveryFrameAgainstTheRecordedJoints) {
  const test::CliResult run = test::cli("run " + replay(*dir_ / "moving.bag") + " --out " + (*dir_ / "replay.jsonl"));
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const RunOutput replayed = read_run(*dir_ / "replay.jsonl");
  ASSERT_EQ(replayed.frames.size(), live_->frames.size());
  for (const auto& [index, live] : live_->frames) {
    const json& again = replayed.frames.at(index);
    EXPECT_EQ(again["joints_rad"], live["joints_rad"]) << "frame " << index;
    EXPECT_EQ(again["robot_state_age_ms"], 0.0) << "frame " << index;
    // The same depth against the same arm: the same result.
    EXPECT_EQ(again["distance_m"], live["distance_m"]) << "frame " << index;
    EXPECT_EQ(again["verdict"], live["verdict"]) << "frame " << index;
  }
  EXPECT_EQ(replayed.summary["robot_state"]["accepted"], kRecordedFrames);
  EXPECT_TRUE(replayed.summary["record"].is_null()) << "nothing recorded";
}

TEST_F(RecordedState, APacedReplayLooksTheStatesUpOnTheRecordingsTimeline) {
  // Paced, frames are delivered on the host clock; their joints are still the recording's.
  const test::CliResult run =
      test::cli("run " + replay(*dir_ / "moving.bag") + " --set source.pace=true --frames 30 --out " + (*dir_ / "paced.jsonl"));
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const RunOutput paced = read_run(*dir_ / "paced.jsonl");
  ASSERT_GE(paced.frames.size(), 10U) << "a paced run may drop some frames, not most";
  for (const auto& [index, frame] : paced.frames) {
    EXPECT_EQ(frame["joints_rad"], live_->frames.at(index)["joints_rad"]) << "frame " << index;
    EXPECT_NE(frame["reason_code"], "no_robot_state") << "frame " << index;
  }
}

TEST_F(RecordedState, TheJointsCarryUrNamesAndTheSimulatedVelocities) {
  BagReader reader(*dir_ / "moving.bag");
  BagMessage m;
  const Config config = load_config(scene_path("cell-ur5-moving.yaml"), {});
  int64_t states = 0;
  for (int guard = 0; guard < 100000 && reader.next(m); ++guard) {
    if (reader.connections().at(m.conn).topic != "/hrcsense/joint_states") continue;
    // The first name, straight from the bytes (header: seq, stamp, empty frame_id; count).
    uint32_t length = 0;
    std::memcpy(&length, m.data + 20, 4);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(m.data + 24), length), "shoulder_pan_joint");
    bag::JointStateMessage joints;
    ASSERT_EQ(bag::parse_joint_state(bag::Cursor{m.data, m.size}, joints), "");
    // Velocities as the trajectory has them at the frame's time (frame k at k/30 s).
    const TrajectorySample want = joints_at(*config.robot_state.trajectory, static_cast<double>(joints.stamp_ns) * 1e-9);
    EXPECT_TRUE(joints.has_velocity);
    for (size_t j = 0; j < 6; ++j) EXPECT_NEAR(joints.velocity_rad_s[j], want.qd_rad_s[j], 1e-9) << "joint " << j;
    ++states;
  }
  EXPECT_EQ(states, kRecordedFrames);
}

TEST_F(RecordedState, HrcsenseRecordsBagsThatReplayTheSameWay) {
  const test::CliResult record = test::cli("record " + moving_cell(kRecordedFrames) + " --frames 30 --out " + (*dir_ / "r.bag"));
  ASSERT_EQ(record.exit_code, 0) << record.out;
  const test::CliResult run = test::cli("run " + replay(*dir_ / "r.bag") + " --out " + (*dir_ / "r.jsonl"));
  ASSERT_EQ(run.exit_code, 0) << run.out;
  const RunOutput replayed = read_run(*dir_ / "r.jsonl");
  ASSERT_EQ(replayed.frames.size(), 30U);
  for (const auto& [index, frame] : replayed.frames) {
    EXPECT_EQ(frame["joints_rad"], live_->frames.at(index)["joints_rad"]) << "frame " << index;
  }
}

TEST_F(RecordedState, ACustomArmsJointsAreNumbered) {
  const std::string description = std::string(HRCSENSE_SOURCE_DIR) + "/config/robots/ur5.yaml";
  const test::CliResult record = test::cli("record " + moving_cell(2) + " --set robot.model=custom --set robot.description=" +
                                           description + " --out " + (*dir_ / "custom.bag"));
  ASSERT_EQ(record.exit_code, 0) << record.out;
  BagReader reader(*dir_ / "custom.bag");
  BagMessage m;
  int states = 0;
  for (int guard = 0; guard < 1000 && reader.next(m); ++guard) {
    if (reader.connections().at(m.conn).topic != "/hrcsense/joint_states") continue;
    uint32_t length = 0;
    std::memcpy(&length, m.data + 20, 4);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(m.data + 24), length), "joint_0");
    ++states;
  }
  EXPECT_EQ(states, 2);
}

TEST_F(RecordedState, ABagWithoutJointStatesIsAClearError) {
  const std::string bag = *dir_ / "depth_only.bag";
  {
    // A bag with a depth frame and nothing of hrcsense's (as the RealSense Viewer records).
    Frame frame;
    frame.timestamp_ns = 1'000'000'000;
    frame.depth.resize(424, 240);
    frame.intrinsics = Intrinsics{424, 240, 300.0F, 300.0F, 212.0F, 120.0F};
    BagWriter writer(bag);
    writer.add_depth(frame);
  }
  const test::CliResult run = test::cli("run " + replay(bag) + " --out " + (*dir_ / "none.jsonl"));
  EXPECT_EQ(run.exit_code, 1) << run.out;
  EXPECT_NE(run.out.find(bag + ": no robot joint states (topic /hrcsense/joint_states)"), std::string::npos) << run.out;
  // A recorded state needs a recording to come from.
  const test::CliResult sim = test::cli("run " + moving_cell(3) + " --set robot.state.source=recorded");
  EXPECT_EQ(sim.exit_code, 2) << sim.out;
  EXPECT_NE(sim.out.find("robot.state.source recorded: needs source.type bag"), std::string::npos) << sim.out;
}

TEST_F(RecordedState, AFailedRecordingShowsInTheSummaryAndTheRunGoesOn) {
  const test::CliResult run =
      test::cli("run " + moving_cell(5) + " --record /dev/full --overwrite --out " + (*dir_ / "full.jsonl"));
  EXPECT_EQ(run.exit_code, 0) << "record.on_error continue: " << run.out;
  const RunOutput out = read_run(*dir_ / "full.jsonl");
  EXPECT_EQ(out.frames.size(), 5U);
  const json& record = out.summary["record"];
  ASSERT_TRUE(record.is_object()) << out.summary.dump();
  EXPECT_NE(record["error"].get<std::string>().find("/dev/full: write failed"), std::string::npos) << record.dump();
  EXPECT_EQ(record["frames_recorded"].get<int64_t>() + record["frames_dropped"].get<int64_t>(), 5) << record.dump();
  EXPECT_GT(record["frames_dropped"].get<int64_t>(), 0) << record.dump();
  EXPECT_EQ(out.summary["frames_dropped"], 0);
}

}  // namespace
}  // namespace hrcsense
