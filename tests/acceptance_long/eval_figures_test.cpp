// SPDX-License-Identifier: Apache-2.0
// `hrcsense eval`'s figures and ready-made studies, end to end on small simulated runs: a sweep
// draws its three figures (valid PNGs with lines on them, their data equal to results.csv), the
// search-backend study (Table 4.3) finds every backend's error equal to brute force's through
// the whole pipeline, and the smoothing study (Table 4.2) lists the thesis's values that the
// SDK's ranges refuse, as the configuration refuses them; a sweep killed mid-way and started
// again ends with the same deterministic columns as one never interrupted. Release builds only,
// under the ctest label `long` (the CI's short sweep; not under the sanitizers).

#include "../support/run_cli.hpp"

#include <gtest/gtest.h>
#include <png.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace {

std::string fresh_dir(const std::string& name) {
  const std::string dir = std::string(::testing::TempDir()) + "eval_figures_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A decoded PNG: its size and how many different colours it has (0 when it does not decode).
struct PngSummary {
  unsigned width = 0, height = 0;
  size_t colours = 0;
};

PngSummary summarise_png(const std::string& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&image, path.c_str()) == 0) return {};
  image.format = PNG_FORMAT_RGB;
  std::vector<png_byte> pixels(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr) == 0) return {};
  std::set<uint32_t> colours;
  for (size_t i = 0; i + 2 < pixels.size(); i += 3) {
    colours.insert(uint32_t{pixels[i]} << 16 | uint32_t{pixels[i + 1]} << 8 | pixels[i + 2]);
  }
  return {image.width, image.height, colours.size()};
}

// A figure with axes, a key and anti-aliased lines has many colours; an empty or failed one
// (one background colour, or nothing decoded) has at most a few.
void expect_real_figure(const std::string& path) {
  SCOPED_TRACE(path);
  const PngSummary png = summarise_png(path);
  EXPECT_EQ(png.width, 900U);
  EXPECT_EQ(png.height, 540U);
  EXPECT_GE(png.colours, 20U);
}

std::string scene(const std::string& file) { return std::string(HRCSENSE_SOURCE_DIR) + "/config/" + file; }

TEST(EvalFigures, ASweepDrawsItsThreeFiguresFromItsTable) {
  const std::string dir = fresh_dir("sweep");
  const test::CliResult r = test::cli("eval --config " + scene("thesis-box-human.yaml") +
                                      " --set sim.color=false --set sim.width=424 --set sim.height=240"
                                      " --sweep filters.temporal.persistence=0,3 --frames 112 --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  for (const char* figure : {"distance_error.png", "instability.png", "processing_fps.png"}) {
    expect_real_figure(dir + "/" + figure);
  }
  // The distance-error figure's data are the table's column: x the persistence, y the error.
  std::istringstream csv(read(dir + "/results.csv"));
  std::string line;
  std::getline(csv, line);
  std::vector<double> errors;
  while (std::getline(csv, line)) {
    std::vector<std::string> fields;
    std::stringstream split(line);
    for (std::string field; std::getline(split, field, ',');) fields.push_back(field);
    errors.push_back(std::stod(fields.at(13)));  // distance_error_mean_m
  }
  ASSERT_EQ(errors.size(), 2U);
  std::istringstream dat(read(dir + "/distance_error.dat"));
  std::vector<std::pair<double, double>> points;
  while (std::getline(dat, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream values(line);
    double x = 0.0, y = 0.0;
    values >> x >> y;
    points.emplace_back(x, y);
  }
  ASSERT_EQ(points.size(), 2U);
  EXPECT_EQ(points[0].first, 0.0);
  EXPECT_EQ(points[1].first, 3.0);
  EXPECT_NEAR(points[0].second, errors[0], 1e-6);
  EXPECT_NEAR(points[1].second, errors[1], 1e-6);
  EXPECT_TRUE(std::filesystem::exists(dir + "/distance_error.gp"));
}

TEST(EvalFigures, EverySearchBackendHasBruteForcesErrorThroughThePipeline) {
  const std::string dir = fresh_dir("table43");
  const test::CliResult r = test::cli("eval --study table-4.3 --frames 130 --set sim.width=424 --set sim.height=240"
                                      " --config-dir " + std::string(HRCSENSE_SOURCE_DIR) + "/config --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const std::string report = read(dir + "/THESIS-REPLICATION.md");
  ASSERT_NE(report.find("## Table 4.3"), std::string::npos) << report;
  // One line per search: brute force, the kd-tree and the octree at heights 1-7, with the
  // thesis's rate beside ours, and each one's error equal to brute force's.
  for (const char* search : {"| brute | 10.88 |", "| kdtree | 0.08 |", "| octree h=1 | 11.49 |", "| octree h=7 | 3.84 |"}) {
    EXPECT_NE(report.find(search), std::string::npos) << search;
  }
  size_t same = 0;
  for (size_t at = report.find("| yes |"); at != std::string::npos; at = report.find("| yes |", at + 1)) ++same;
  EXPECT_EQ(same, 9U) << report;
  EXPECT_EQ(report.find("**no**"), std::string::npos);
  expect_real_figure(dir + "/table-4.3/backend_rate.png");
  EXPECT_NE(report.find("(table-4.3/backend_rate.png)"), std::string::npos);
}

TEST(EvalFigures, TheSmoothingStudyListsTheValuesTheSdkRefuses) {
  const std::string dir = fresh_dir("table42");
  const test::CliResult r = test::cli("eval --study table-4.2 --frames 101 --set sim.width=424 --set sim.height=240"
                                      " --config-dir " + std::string(HRCSENSE_SOURCE_DIR) + "/config --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const std::string report = read(dir + "/THESIS-REPLICATION.md");
  // The thesis's α 0, 0.1, 0.2 (below 0.25) and δ 60-100 (above 50): 3 + 5 refused lines, each
  // with the configuration's message naming the key; α 0.3-1 and δ 1-50 ran (8 + 6, and the run
  // without the spatial filter).
  size_t refused = 0;
  for (size_t at = report.find("refused by the SDK's range"); at != std::string::npos;
       at = report.find("refused by the SDK's range", at + 1)) {
    ++refused;
  }
  EXPECT_EQ(refused, 8U) << report;
  EXPECT_NE(report.find("filters.spatial.alpha"), std::string::npos);
  EXPECT_NE(report.find("filters.spatial.delta"), std::string::npos);
  std::istringstream csv(read(dir + "/table-4.2/results.csv"));
  std::string line;
  size_t rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 1U + 8U + 6U + 1U);
}

// The lines of a results.csv, the timing columns (latency, rate, `timing`) cut off.
std::vector<std::string> deterministic_lines(const std::string& csv_path) {
  std::istringstream in(read(csv_path));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    size_t cut = line.size();
    for (int k = 0; k < 4; ++k) cut = line.rfind(',', cut - 1);
    lines.push_back(line.substr(0, cut));
  }
  std::sort(lines.begin() + 1, lines.end());  // rows in row order (their first field)
  return lines;
}

size_t line_count(const std::string& path) {
  const std::string text = read(path);
  return static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
}

// A real interruption: the sweep is killed (SIGKILL, no chance to tidy up) once its first row
// is written, then the same command runs again and finishes the rest.
TEST(EvalFigures, AKilledSweepResumedEqualsAnUninterruptedOne) {
  const std::string arguments = "eval --config " + scene("thesis-box.yaml") +
                                " --set filters.preset=thesis --set sim.width=424 --set sim.height=240"
                                " --sweep filters.temporal.persistence=0:3"
                                " --frames 160 --out ";
  const std::string whole = fresh_dir("whole");
  ASSERT_EQ(test::cli(arguments + whole).exit_code, 0);

  const std::string killed = fresh_dir("killed");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::execl("/bin/sh", "sh", "-c", (std::string("exec ") + HRCSENSE_CLI + " " + arguments + killed + " 2>/dev/null").c_str(),
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Bounded: at most 60 s for the first row to appear.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (line_count(killed + "/results.csv") < 2 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  const size_t rows_before = line_count(killed + "/results.csv") - 1;
  ASSERT_GE(rows_before, 1U);
  ASSERT_LT(rows_before, 4U) << "the sweep finished before it was killed";

  const test::CliResult resumed = test::cli(arguments + killed);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.out;
  EXPECT_NE(resumed.out.find("resuming"), std::string::npos) << resumed.out;
  EXPECT_EQ(deterministic_lines(killed + "/results.csv"), deterministic_lines(whole + "/results.csv"));
}

TEST(EvalFigures, AnUnknownStudyIsNamed) {
  const test::CliResult r = test::cli("eval --study table-9 --out " + fresh_dir("unknown"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find("--study 'table-9' is no study"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace hrcsense
