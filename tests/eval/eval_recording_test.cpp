// SPDX-License-Identifier: Apache-2.0
// `hrcsense eval` on a real recording without ground truth (../shared/data/ist_piv_lab_people,
// a folder source; skipped when ../shared is absent): only the stability measures, against the
// run's own median closest point. The expectation is computed here from the JSON Lines of
// `hrcsense run` on the same configuration: the component-wise median of the measured closest
// points (base frame), and how many lie more than 1 m and 0.1 m from it.

#include "../support/run_cli.hpp"
#include "hrcsense/eval/sweep.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

TEST(EvalRecording, StabilityAgainstTheRunsMedianWithoutGroundTruth) {
  const std::string data = std::string(HRCSENSE_SHARED_DIR) + "/data/ist_piv_lab_people";
  if (!std::filesystem::exists(data)) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  const std::string dir = std::string(::testing::TempDir()) + "eval_recording";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string config = dir + "/people.yaml";
  std::ofstream(config) << "source: {type: folder, path: '" << data << "'}\nbackground: {frames: 3}\n"
                        << "filters: {preset: none}\n";

  const test::CliResult run = test::cli("run --config " + config + " --out " + dir + "/run.jsonl");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::vector<std::array<double, 3>> points;
  std::ifstream jsonl(dir + "/run.jsonl");
  for (std::string line; std::getline(jsonl, line);) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j["type"] != "frame" || !j["valid"].get<bool>() || j["distance_m"].is_null()) continue;
    points.push_back({j["closest_base"][0].get<double>(), j["closest_base"][1].get<double>(),
                      j["closest_base"][2].get<double>()});
  }
  ASSERT_GT(points.size(), 20U);  // people are in most of the 105 frames after learning
  std::array<double, 3> centre{};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> axis;
    for (const auto& p : points) axis.push_back(p[k]);
    centre[k] = median(axis);
  }
  int beyond_1m = 0, beyond_01m = 0;
  for (const auto& p : points) {
    const double d = std::hypot(p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]);
    beyond_1m += d > 1.0;
    beyond_01m += d > 0.1;
  }
  ASSERT_GT(beyond_01m, 0);  // people walk about: the closest point moves

  const test::CliResult eval = test::cli("eval --config " + config + " --out " + dir + "/eval");
  ASSERT_EQ(eval.exit_code, 0) << eval.out;
  std::ifstream csv(dir + "/eval/results.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  const std::vector<std::string> names = eval::split_csv_line(header);
  const std::vector<std::string> fields = eval::split_csv_line(row);
  ASSERT_EQ(fields.size(), names.size());
  const auto field = [&](const std::string& name) {
    return fields.at(static_cast<size_t>(std::find(names.begin(), names.end(), name) - names.begin()));
  };
  EXPECT_EQ(field("truth_frames"), "0");
  EXPECT_EQ(field("measured_frames"), std::to_string(points.size()));
  EXPECT_EQ(field("misrecognised_1m"), std::to_string(beyond_1m));
  EXPECT_EQ(field("misrecognised_0.1m"), std::to_string(beyond_01m));
  EXPECT_FALSE(field("mse_run_m2").empty());
  EXPECT_FALSE(field("processing_fps").empty());
  // Nothing to compare a distance with: the ground-truth measures stay empty.
  EXPECT_EQ(field("distance_error_mean_m"), "");
  EXPECT_EQ(field("unsafe_share"), "");
  EXPECT_EQ(field("z_d_coverage"), "");
}

}  // namespace
}  // namespace hrcsense
