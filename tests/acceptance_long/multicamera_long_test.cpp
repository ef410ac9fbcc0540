// SPDX-License-Identifier: Apache-2.0
// Acceptance (issue H2): config/cell-ur5-3cam.yaml run by `hrcsense cell` on loopback DDS, three
// simulated D435s and the fuser. No fused frame is laxer than the per-link truth allows (S1's
// rule, as ssm_acceptance_test.cpp: each link's safe speed scale from its true distance and true
// speed towards the person, Z_d 0) and some fused frames are `run`; beside it, what each camera
// alone decided (its own run's JSON Lines, written beside the fused output) judged against the
// same truth: its misses (laxer than the truth) and needless stops (every link clears its true S_p
// by its Z_d, and still stop). The truth of the cell is the fused line's: per link the smallest
// over the three cameras' noise-free pixels. The fused unknown volume (cubes no camera saw free)
// is smaller than any single camera's. The cell without the person fuses to run while the arm
// moves (at least a third of the instants after learning; see below). The table is printed for
// docs/MULTICAMERA.md.
#include "../dds/dds_test_util.hpp"
#include "../support/child_process.hpp"
#include "../support/scenes.hpp"

#include "hrcsense/config/config.hpp"
#include "hrcsense/ssm.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

// A namespace of its own: the family is one unity build with ssm_acceptance_test.cpp's helpers.
namespace hrcsense::multicamera_long {
namespace {

using nlohmann::json;

std::vector<json> read_lines(const std::filesystem::path& path) {
  std::vector<json> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
  return lines;
}

// Runs `hrcsense cell` on `scene` for `frames` scene frames with its outputs in `dir`; the exit code.
int run_cell(const std::string& scene, int frames, const std::filesystem::path& dir) {
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  test::ChildProcess cell({HRCSENSE_CLI, "cell", "--config", test::scene_path(scene), "--set", "sim.color=false", "--set",
                           "ros2.domain_id=" + std::to_string(test::test_domain()), "--frames", std::to_string(frames),
                           "--out", (dir / "fused.jsonl").string()});
  const int status = cell.wait(300.0);
  return status >= 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// What the cell's truth allows at one scene instant (the fused line's truth.links), judged with
// `line`'s own frame age and Z_d: the lowest safe scale over the links, and whether every link
// clears its true S_p by its Z_d.
struct TruthAllows {
  bool any = false;
  float scale = 1.0F;
  bool every_link_clear = true;
};

TruthAllows truth_allows(const SafetyParams& safety, const json& truth_line, const json& line) {
  TruthAllows out;
  if (!truth_line.contains("truth") || truth_line["truth"].is_null()) return out;
  for (const json& t : truth_line["truth"]["links"]) {
    if (t["distance_m"].is_null()) continue;
    out.any = true;
    SsmInput in;
    in.distance_m = t["distance_m"].get<float>();
    in.robot_speed_mps = t["speed_towards_mps"].is_null() ? 0.0F : t["speed_towards_mps"].get<float>();
    in.distance_uncertainty_m = 0.0F;
    in.frame_age_s = line["frame_age_s"].get<double>();
    out.scale = std::min(out.scale, ssm_speed_scale(safety.ssm, in));
    float z_d_m = 0.05F;  // the link was not measured: a typical Z_d
    for (const json& l : line["links"]) {
      if (l["link"] == t["link"] && !l["distance_uncertainty_m"].is_null()) z_d_m = l["distance_uncertainty_m"].get<float>();
    }
    const float s_p = protective_distance(safety.ssm, in, std::max(0.0F, in.robot_speed_mps)).protective_distance_m;
    out.every_link_clear = out.every_link_clear && in.distance_m >= s_p + z_d_m + safety.hysteresis_m;
  }
  return out;
}

struct Tally {
  int judged = 0, runs = 0, slows = 0, stops = 0, misses = 0, needless_stops = 0;
  std::vector<double> unknown;
};

void judge(const SafetyParams& safety, const json& truth_line, const json& line, Tally& tally) {
  if (line["type"] != "frame") return;
  const std::string verdict = line["verdict"];
  tally.runs += verdict == "run";
  tally.slows += verdict == "slow";
  tally.stops += verdict == "stop";
  if (line.contains("seen_free") && line["valid"].get<bool>()) tally.unknown.push_back(line["seen_free"]["unknown"].get<double>());
  const TruthAllows truth = truth_allows(safety, truth_line, line);
  if (!truth.any) return;
  ++tally.judged;
  const float scale = line["speed_scale"].get<float>();
  const bool lax = (verdict == "run" && truth.scale < 1.0F) || (verdict == "slow" && scale > truth.scale + 1e-6F);
  tally.misses += lax ? 1 : 0;
  tally.needless_stops += truth.every_link_clear && verdict == "stop" ? 1 : 0;
}

// The cell's processes talk over Cyclone DDS, on loopback only.
bool can_run_cells() {
#if HRCSENSE_HAVE_DDS
  return test::loopback_configured();
#else
  return false;
#endif
}
constexpr const char* kNoCells = "needs a build with Cyclone DDS and the loopback configuration (ctest sets CYCLONEDDS_URI)";

double median(std::vector<double> v) {
  if (v.empty()) return -1.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void three_camera_cell_against_the_truth() {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("hrcsense_3cam_" + std::to_string(::getpid()));
  // The first 660 of its 900 frames (22 s): the person hidden from `front` beside the shelf
  // (frames 143-340) and reaching in beside the arm (435-600).
  ASSERT_EQ(run_cell("cell-ur5-3cam.yaml", 660, dir), 0);
  const Config config = load_config(test::scene_path("cell-ur5-3cam.yaml"), {});
  const SafetyParams& safety = config.pipeline.safety;

  // The cell's truth per scene frame: the fused lines'.
  std::map<int64_t, json> truth_at;
  const std::vector<json> fused = read_lines(dir / "fused.jsonl");
  ASSERT_GE(fused.size(), 600U);
  for (const json& line : fused) {
    if (line["type"] == "frame" && line.contains("truth") && !line["truth"].is_null()) truth_at[line["frame"]] = line;
  }
  Tally fused_tally;
  for (const json& line : fused) {
    if (line["type"] != "frame") continue;
    judge(safety, line, line, fused_tally);
  }
  std::map<std::string, Tally> camera_tally;
  for (const CameraEntry& camera : config.cameras) {
    Tally& tally = camera_tally[camera.name];
    for (const json& line : read_lines(dir / ("fused." + camera.name + ".jsonl"))) {
      if (line["type"] != "frame") continue;
      const auto truth = truth_at.find(line["frame"].get<int64_t>());
      if (truth != truth_at.end()) {
        judge(safety, truth->second, line, tally);
      } else {
        judge(safety, json::object(), line, tally);
      }
    }
  }

  std::printf("| decided by | instants with a true contact | run | slow | stop | laxer than the truth (misses) | needless stops | unknown cubes (median) |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- |\n");
  const auto row = [](const std::string& name, const Tally& t) {
    std::printf("| %s | %d | %d | %d | %d | %d | %d | %.0f |\n", name.c_str(), t.judged, t.runs, t.slows, t.stops, t.misses,
                t.needless_stops, median(t.unknown));
  };
  row("fused (3 cameras)", fused_tally);
  for (const auto& [name, tally] : camera_tally) row(name + " alone", tally);

  EXPECT_GE(fused_tally.judged, 250);
  EXPECT_EQ(fused_tally.misses, 0);
  EXPECT_GT(fused_tally.runs, 0);
  for (const auto& [name, tally] : camera_tally) {
    EXPECT_LT(median(fused_tally.unknown), median(tally.unknown)) << name;
  }
  std::filesystem::remove_all(dir);
}

// One test, after the other cell's: two cells of three cameras at once would share the two cores
// eight ways.
void empty_cell_fuses_to_run() {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("hrcsense_3cam_empty_" + std::to_string(::getpid()));
  ASSERT_EQ(run_cell("cell-ur5-3cam-empty.yaml", 430, dir), 0);  // 100 learning, 10 s after
  int after_learning = 0, runs = 0, seen = 0;
  std::map<std::string, int> stops_by_reason;
  for (const json& line : read_lines(dir / "fused.jsonl")) {
    if (line["type"] != "frame" || line["frame"].get<int64_t>() < 130) continue;
    ++after_learning;
    runs += line["verdict"] == "run";
    if (line["verdict"] != "run") ++stops_by_reason[line["reason_code"].get<std::string>()];
    seen += line.contains("distance_m") && line["distance_m"].is_number();  // some camera saw foreground
  }
  std::printf("empty 3-camera cell: %d of %d fused instants after learning are run; %d with foreground;", runs,
              after_learning, seen);
  for (const auto& [reason, count] : stops_by_reason) std::printf(" %s %d", reason.c_str(), count);
  std::printf("\n");
  // Nobody is in the cell, and the self-filter takes the arm's pixels, its rim's mixes with the
  // background included (docs/ROBOT.md, "Self-filter"): no camera sees anything, and the cell
  // runs at every instant on a quiet machine (771 of 771 over the whole scene). A camera starved
  // of the cores by the other long tests may still be stale at a few instants (camera_stale and
  // the hold after it), so the run count has room; the foreground has none.
  EXPECT_GE(after_learning, 280);
  EXPECT_EQ(seen, 0);
  EXPECT_GE(runs, after_learning * 2 / 3);
  std::filesystem::remove_all(dir);
}

TEST(MultiCameraLong, TheThreeCameraCellIsNeverLaxerThanTheTruthAndTheEmptyCellRuns) {
  if (!can_run_cells()) GTEST_SKIP() << kNoCells;
  three_camera_cell_against_the_truth();
  empty_cell_fuses_to_run();
}

}  // namespace
}  // namespace hrcsense::multicamera_long
