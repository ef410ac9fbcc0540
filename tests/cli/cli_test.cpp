// SPDX-License-Identifier: Apache-2.0
// Tests of the `hrcsense` executable: exit codes, one-line errors, JSON Lines from `run`, `info`.
#include "../support/cli_folder.hpp"
#include "../support/run_cli.hpp"
#include "../support/sanitized.hpp"
#include "hrcsense/camera.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

using hrcsense::test::kSanitized;

using Outcome = hrcsense::test::CliOutcome;
using hrcsense::test::read_text;

// The lines of a `run` output without what depends on the machine or the build (timings, wall
// time, frame rate, commit), so that two runs compare line by line.
std::vector<json> results_without_timings(const fs::path& jsonl) {
  std::vector<json> lines;
  std::istringstream in(read_text(jsonl));
  for (std::string line; std::getline(in, line);) {
    json result = json::parse(line);
    // Wall-clock figures, and the session (random per process start), differ from run to run.
    for (const char* key : {"commit", "latency_us", "timings_us", "wall_s", "fps", "latency_p50_us",
                            "latency_p99_us", "frame_age_s", "session"}) {
      result.erase(key);
    }
    lines.push_back(std::move(result));
  }
  return lines;
}

// Runs the CLI in its own temporary folder, capturing stdout and stderr.
class Cli : public hrcsense::test::CliFolder {
 protected:
  // Thesis-box, shortened; smaller frames under the sanitizers, which are slow.
  static std::string thesis_box(const std::string& extra) {
    std::string args = std::string("--config '") + HRCSENSE_SOURCE_DIR + "/config/thesis-box.yaml' ";
    if (kSanitized) args += "--set sim.width=424 --set sim.height=240 ";
    return args + extra;  // last, so that the test's own overrides win
  }

  static void expect_one_error_line(const Outcome& outcome, const std::vector<std::string>& needles) {
    const std::vector<std::string> lines = outcome.err_lines();
    ASSERT_EQ(lines.size(), 1U) << outcome.err;
    EXPECT_EQ(lines[0].rfind("hrcsense: error: ", 0), 0U) << lines[0];
    for (const std::string& needle : needles) {
      EXPECT_NE(lines[0].find(needle), std::string::npos) << "'" << needle << "' not in: " << lines[0];
    }
  }
};

TEST_F(Cli, UnknownConfigKeyIsAUsageError) {
  write("walk.yaml", "safety:\n  stop_distanse_m: 0.3\n");
  const Outcome outcome = run("run --config walk.yaml");
  EXPECT_EQ(outcome.exit_code, 2);
  expect_one_error_line(outcome, {"walk.yaml", "unknown key 'safety.stop_distanse_m'"});
  EXPECT_TRUE(outcome.out.empty());
}

TEST_F(Cli, MissingConfigFileIsAUsageError) {
  const Outcome outcome = run("run --config nowhere.yaml");
  EXPECT_EQ(outcome.exit_code, 2);
  expect_one_error_line(outcome, {"nowhere.yaml"});
}

TEST_F(Cli, BadCommandLineIsAUsageError) {
  Outcome outcome = run("run --frames -3");
  EXPECT_EQ(outcome.exit_code, 2);
  expect_one_error_line(outcome, {"--frames"});
  outcome = run("frobnicate");
  EXPECT_EQ(outcome.exit_code, 2);
  expect_one_error_line(outcome, {"frobnicate"});
  outcome = run("run --set sim.fps");
  EXPECT_EQ(outcome.exit_code, 2);
  expect_one_error_line(outcome, {"sim.fps", "KEY=VALUE"});
}

TEST_F(Cli, DamagedBackgroundFileIsARuntimeError) {
  write("bg.bin", "this is not a background model, just text of some length\n");
  const Outcome outcome = run("run --set sim.frames=3 --set background.path=bg.bin");
  EXPECT_EQ(outcome.exit_code, 1);
  expect_one_error_line(outcome, {"bg.bin"});
}

TEST_F(Cli, RunWritesHeaderFramesAndSummaryWithTheBindingNames) {
  const Outcome outcome =
      run("run " + thesis_box("--frames 130 --set background.frames=20 --out results/run.jsonl"));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_TRUE(outcome.out.empty());  // results went to --out, in a folder the run created

  std::vector<json> lines;
  std::istringstream in(read_text(dir_ / "results" / "run.jsonl"));
  for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
  // Header, one line per source frame, then stop results that stand for no new source frame
  // (the end of the run, a watchdog), then the summary.
  ASSERT_GE(lines.size(), 1U + 130U + 1U + 1U);
  for (size_t i = 1; i <= 130; ++i) {
    EXPECT_EQ(lines[i]["type"], "frame");
    EXPECT_EQ(lines[i]["frame"], i - 1);
  }
  for (size_t i = 131; i + 1 < lines.size(); ++i) {
    EXPECT_EQ(lines[i]["type"], "verdict");
    EXPECT_EQ(lines[i]["verdict"], "stop");
    EXPECT_FALSE(lines[i]["valid"].get<bool>());
  }
  // The run ended at --frames: the last verdict line and the summary say so by code.
  EXPECT_EQ(lines[lines.size() - 2]["reason_code"], "frame_limit_reached");
  EXPECT_EQ(lines.back()["end_reason_code"], "frame_limit_reached");

  const json& header = lines.front();
  EXPECT_EQ(header["type"], "header");
  for (const char* key : {"version", "commit", "config_hash", "source", "intrinsics"}) {
    EXPECT_TRUE(header.contains(key)) << key;
  }
  for (const char* key : {"width", "height", "fx", "fy", "ppx", "ppy", "model", "coeffs"}) {
    EXPECT_TRUE(header["intrinsics"].contains(key)) << key;
  }
  EXPECT_EQ(header["config_hash"].get<std::string>().size(), 16U);
  EXPECT_EQ(header["source"]["type"], "sim");

  const char* frame_keys[] = {"frame", "timestamp_ns", "timestamp_s", "valid", "verdict", "verdict_reason",
                              "reason_code", "distance_m", "closest_camera", "closest_base", "closest_robot_base", "robot_link",
                              "backend", "foreground_points", "invalid_pixels", "timings_us", "truth"};
  bool saw_box = false;
  for (size_t i = 1; i <= 130; ++i) {
    const json& frame = lines[i];
    ASSERT_EQ(frame["type"], "frame");
    for (const char* key : frame_keys) ASSERT_TRUE(frame.contains(key)) << key << " in line " << i;
    EXPECT_EQ(frame["frame"], static_cast<int64_t>(i - 1));  // every frame, in order
    const std::string verdict = frame["verdict"];
    EXPECT_TRUE(verdict == "run" || verdict == "slow" || verdict == "stop") << verdict;
    if (i - 1 < 20) {
      EXPECT_FALSE(frame["valid"].get<bool>());  // learning the background
      EXPECT_EQ(verdict, "stop");
    }
    if (i - 1 >= 105 && !frame["distance_m"].is_null()) {
      // The box's nearest vertex (0.5, 0, 1) is 1.2247 m from the robot point (config/thesis-box.yaml).
      EXPECT_NEAR(frame["distance_m"].get<double>(), 1.2247, 0.02) << i;
      saw_box = true;
    }
  }
  EXPECT_TRUE(saw_box);

  const json& summary = lines.back();
  EXPECT_EQ(summary["type"], "summary");
  for (const char* key : {"frames_in", "frames_processed", "frames_dropped", "frames_valid", "verdict_run",
                          "verdict_slow", "verdict_stop", "wall_s", "fps", "latency_p50_us", "latency_p99_us",
                          "min_distance_m", "end_reason"}) {
    EXPECT_TRUE(summary.contains(key)) << key;
  }
  EXPECT_EQ(summary["frames_in"], 130);
  EXPECT_EQ(summary["frames_processed"], 130);
  EXPECT_EQ(summary["frames_dropped"], 0);  // unpaced: every frame is processed
  EXPECT_EQ(summary["frames_dropped_camera"], 0);  // a simulator loses no frame on the way
}

// Frame i depends only on the configuration, the seed and i (docs/SIMULATOR.md), so two
// processes given the same seed write the same results; another seed gives other depth.
TEST_F(Cli, SameSeedSameResultsInSeparateProcessesOtherSeedOtherDepth) {
  const auto run_with_seed = [this](int seed, const std::string& name) {
    const fs::path out = dir_ / name;
    const hrcsense::test::CliResult result = hrcsense::test::cli(
        "run " + thesis_box("--frames 110 --set background.frames=20 --set source.seed=" + std::to_string(seed) +
                            " --out '" + out.string() + "'"));
    EXPECT_EQ(result.exit_code, 0) << result.out;
    return results_without_timings(out);
  };
  const std::vector<json> first = run_with_seed(7, "first.jsonl");
  const std::vector<json> second = run_with_seed(7, "second.jsonl");
  const std::vector<json> other = run_with_seed(8, "other.jsonl");
  ASSERT_EQ(first.size(), 1U + 110U + 1U + 1U);  // header, frames, the end-of-run stop, summary
  ASSERT_EQ(second.size(), first.size());
  ASSERT_EQ(other.size(), first.size());
  for (size_t i = 0; i < first.size(); ++i) EXPECT_EQ(first[i], second[i]) << "line " << i;
  // What was compared depends on the rendered depth: invalid pixels in every frame, and by
  // frame 109 the box (it enters at 100) has a distance.
  size_t other_invalid = 0;
  for (size_t i = 1; i <= 110; ++i) {
    ASSERT_EQ(first[i]["type"], "frame");
    EXPECT_GT(first[i]["invalid_pixels"].get<int64_t>(), 0) << "line " << i;
    other_invalid += first[i]["invalid_pixels"] != other[i]["invalid_pixels"] ? 1U : 0U;
  }
  EXPECT_FALSE(first[110]["distance_m"].is_null());
  EXPECT_GT(other_invalid, 0U) << "seed 8 gives the same invalid pixels as seed 7 in every frame";
}

TEST_F(Cli, LearntBackgroundIsSavedThenLoaded) {
  Outcome outcome = run("run " + thesis_box("--frames 12 --set background.frames=10 --set background.path=bg/model.bin"));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  ASSERT_TRUE(fs::exists(dir_ / "bg" / "model.bin"));

  // The second run starts with the saved model: it checks it against the first 5 frames
  // (stops), and the 6th frame is already valid, long before 10 learning frames.
  outcome = run("run " + thesis_box("--frames 7 --set background.frames=10 --set background.path=bg/model.bin"));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  std::istringstream in(outcome.out);
  std::string line;
  std::getline(in, line);  // header
  for (int i = 0; i < 5; ++i) {
    std::getline(in, line);
    const json frame = json::parse(line);
    EXPECT_FALSE(frame["valid"].get<bool>()) << line;
    EXPECT_EQ(frame["verdict"], "stop") << line;
    EXPECT_EQ(frame["verdict_reason"].get<std::string>().rfind("checking loaded background", 0), 0U) << line;
  }
  std::getline(in, line);
  EXPECT_TRUE(json::parse(line)["valid"].get<bool>()) << line;

  // A model of another size does not fit the source.
  outcome = run("run " + thesis_box("--frames 2 --set background.path=bg/model.bin --set sim.width=640 "
                                     "--set sim.height=480"));
  EXPECT_EQ(outcome.exit_code, 1);
  expect_one_error_line(outcome, {"bg/model.bin", "640x480"});
}

TEST_F(Cli, InfoDescribesTheSimulatedSource) {
  const Outcome outcome =
      run(std::string("info --config '") + HRCSENSE_SOURCE_DIR + "/config/thesis-box.yaml'");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const hrcsense::Intrinsics in = *hrcsense::d435_depth_intrinsics(848, 480);
  char fx[64];
  std::snprintf(fx, sizeof fx, "fx=%.4f fy=%.4f ppx=%.4f ppy=%.4f", static_cast<double>(in.fx),
                static_cast<double>(in.fy), static_cast<double>(in.ppx), static_cast<double>(in.ppy));
  for (const std::string& needle : {std::string("sim"), std::string("848x480"), std::string(fx),
                                   std::string("box: moving"), std::string("wall: static"), std::string("400")}) {
    EXPECT_NE(outcome.out.find(needle), std::string::npos) << "'" << needle << "' not in:\n" << outcome.out;
  }
  const Outcome recording = run("info some/recording.bag");
  EXPECT_EQ(recording.exit_code, 2);
  expect_one_error_line(recording, {"some/recording.bag", "no such recording"});
}

}  // namespace
