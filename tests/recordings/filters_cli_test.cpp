// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` on a folder recording with the default filter preset (sdk): the JSON Lines
// header says in which domain the filters ran (depth without a stereo baseline) and at which
// resolution, every frame line's timings_us names each block of the chain, and a background
// saved at the decimated resolution loads again.
#include "recordings_test_util.hpp"
#include "../support/run_cli.hpp"

#include "hrcsense/io/io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense {
namespace {

using test::cli;
using test::CliResult;

/// A folder recording of `frames` 64x48 frames of a wall at 1.5 m (no stereo baseline: the
/// folder layout does not carry one).
void make_folder(const test::ScratchDir& dir, int frames) {
  std::filesystem::create_directories(dir.path / "depth");
  DepthImage depth;
  depth.resize(64, 48);
  std::fill(depth.pixels.begin(), depth.pixels.end(), uint16_t{1500});
  for (int i = 0; i < frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "depth/%06d.png", i);
    write_depth_png(dir / name, depth);
  }
  test::write_text(dir / "intrinsics.json",
                   R"({"width": 64, "height": 48, "depth_K": [[60, 0, 32], [0, 60, 24], [0, 0, 1]]})");
}

/// Runs the folder and returns the header line, parsed.
nlohmann::json run_header(const test::ScratchDir& dir, const std::string& extra) {
  const std::string out = dir / "run.jsonl";
  const CliResult r = cli("run --set source.type=folder --set source.path=" + dir.path.string() +
                          " --set background.frames=2 " + extra + " --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const std::vector<char> bytes = test::read_bytes(out);
  std::istringstream lines(std::string(bytes.begin(), bytes.end()));
  std::string first;
  std::getline(lines, first);
  return nlohmann::json::parse(first, nullptr, false);
}

TEST(FiltersCli, WithoutBaselineTheHeaderSaysTheSdkChainRanOnDepth) {
  test::ScratchDir dir("filters");
  make_folder(dir, 3);
  const nlohmann::json header = run_header(dir, "");
  ASSERT_TRUE(header.contains("filters")) << header.dump();
  const nlohmann::json& filters = header["filters"];
  EXPECT_EQ(filters["preset"], "sdk");
  EXPECT_EQ(filters["domain"], "depth");
  EXPECT_NE(filters["note"].get<std::string>().find("no stereo baseline"), std::string::npos) << filters.dump();
  // Decimation x2: 32x24 (already a multiple of 4), focal length and principal point halved.
  EXPECT_EQ(filters["width"], 32);
  EXPECT_EQ(filters["height"], 24);
  EXPECT_EQ(filters["fx"], 30.0);
  EXPECT_EQ(filters["ppx"], 16.0);
  EXPECT_EQ(header["intrinsics"]["width"], 64);  // the source's own intrinsics stay as they were
}

TEST(FiltersCli, WithABaselineOrNoChainTheHeaderSaysSo) {
  test::ScratchDir dir("filters");
  make_folder(dir, 3);
  nlohmann::json header = run_header(dir, "--set source.stereo_baseline_mm=50");
  EXPECT_EQ(header["filters"]["domain"], "disparity");
  EXPECT_FALSE(header["filters"].contains("note")) << header.dump();
  header = run_header(dir, "--set filters.preset=none");
  EXPECT_EQ(header["filters"]["preset"], "none");
  EXPECT_EQ(header["filters"]["domain"], "none");
  EXPECT_EQ(header["filters"]["width"], 64);
  header = run_header(dir, "--set filters.preset=thesis");  // thesis asks for disparity too
  EXPECT_EQ(header["filters"]["domain"], "depth");
  EXPECT_EQ(header["filters"]["width"], 64);
}

/// Runs the folder and returns the `timings_us` keys of every `frame` line, in the order written.
std::vector<std::vector<std::string>> frame_timing_keys(const test::ScratchDir& dir, const std::string& extra) {
  const std::string out = dir / "timings.jsonl";
  const CliResult r = cli("run --set source.type=folder --set source.path=" + dir.path.string() +
                          " --set background.frames=2 " + extra + " --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const std::vector<char> bytes = test::read_bytes(out);
  std::istringstream lines(std::string(bytes.begin(), bytes.end()));
  std::vector<std::vector<std::string>> keys;
  for (std::string line; std::getline(lines, line);) {
    // ordered_json keeps the members in the order of the line.
    const nlohmann::ordered_json j = nlohmann::ordered_json::parse(line, nullptr, false);
    if (!j.is_object() || j.value("type", "") != "frame") continue;
    keys.emplace_back();
    for (const auto& [key, value] : j.at("timings_us").items()) {
      EXPECT_TRUE(value.is_number() && value.get<double>() >= 0.0) << key << " in " << line;
      keys.back().push_back(key);
    }
  }
  return keys;
}

/// `keys` split into the filter blocks that lead it and the stages after them.
std::pair<std::vector<std::string>, std::vector<std::string>> split_filters(const std::vector<std::string>& keys) {
  const std::set<std::string> blocks{"threshold", "decimation", "to_disparity", "spatial",
                                     "temporal",  "to_depth",   "hole_filling"};
  size_t n = 0;
  while (n < keys.size() && blocks.count(keys[n]) != 0) ++n;
  return {std::vector<std::string>(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(n)),
          std::vector<std::string>(keys.begin() + static_cast<std::ptrdiff_t>(n), keys.end())};
}

// Every frame line times each block of the chain under its name (filter_block_name), in the
// chain's order, before the pipeline's own stages: the 2 background-learning frames end with
// `background`, the others with `foreground`, `proximity`, `safety`.
TEST(FiltersCli, FrameLinesTimeEveryBlockOfTheChainUnderItsName) {
  test::ScratchDir dir("filters");
  make_folder(dir, 4);
  using Names = std::vector<std::string>;
  const Names sdk{"threshold", "decimation", "to_disparity", "spatial", "temporal", "to_depth"};
  const Names learning{"background"};
  const Names processing{"foreground", "proximity", "unknown_space", "safety"};
  const auto expect_chain = [&](const std::string& extra, const Names& blocks) {
    const std::vector<Names> frames = frame_timing_keys(dir, extra);
    ASSERT_EQ(frames.size(), 4U) << extra;
    for (size_t i = 0; i < frames.size(); ++i) {
      const auto [filters, stages] = split_filters(frames[i]);
      EXPECT_EQ(filters, blocks) << extra << ", frame " << i;
      EXPECT_EQ(stages, i < 2 ? learning : processing) << extra << ", frame " << i;
    }
  };
  expect_chain("--set filters.preset=sdk --set source.stereo_baseline_mm=50", sdk);
  // No baseline: the transforms are skipped, so they are not timed either.
  expect_chain("--set filters.preset=sdk", {"threshold", "decimation", "spatial", "temporal"});
  expect_chain("--set filters.preset=sdk --set source.stereo_baseline_mm=50 --set filters.hole_filling.enabled=true",
               {"threshold", "decimation", "to_disparity", "spatial", "temporal", "to_depth", "hole_filling"});
  expect_chain("--set filters.preset=thesis --set source.stereo_baseline_mm=50",
               {"to_disparity", "spatial", "temporal", "to_depth"});
  expect_chain("--set filters.preset=none", {});
}

// The background is learnt after the filters, at 32x24; saving and loading it must agree on
// that size (the source itself is 64x48).
TEST(FiltersCli, BackgroundSavedAtTheDecimatedResolutionLoadsAgain) {
  test::ScratchDir dir("filters");
  make_folder(dir, 3);
  const std::string background = dir / "bg.bin";
  run_header(dir, "--set background.path=" + background);
  ASSERT_TRUE(std::filesystem::exists(background));
  EXPECT_EQ(load_background(background).width, 32);
  run_header(dir, "--set background.path=" + background);  // loads: exit code 0 checked inside
  const CliResult r = cli("run --set source.type=folder --set source.path=" + dir.path.string() +
                          " --set filters.preset=none --set background.path=" + background + " --out " +
                          (dir / "none.jsonl"));
  EXPECT_NE(r.exit_code, 0) << r.out;  // unfiltered frames are 64x48: the saved model does not fit
  EXPECT_NE(r.out.find("32x24"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("64x48"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace hrcsense
