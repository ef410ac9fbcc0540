// SPDX-License-Identifier: Apache-2.0
// Acceptance of the detection capability (issue 30, Part 2, item 3): S_p's C is taken for
// d = safety.detection_mm (40 mm), so a test piece of that diameter must be detected wherever
// the configuration claims d. A 40 mm sphere appears on the camera's axis after the background
// is learnt, 0.28 m (surface to point) from a `robot.model: points` robot, in `ssm` mode: at
// that distance S_p at rest is over 1 m, so a detected sphere is a stop and an undetected one
// (removed as speckle, or lost to the filters) a `run` (no foreground). No valid frame may say
// `run`, each decided alone (test::process_and_decide: a fresh monitor, no hold to bridge a
// missed frame). The scene is built with --set style overrides on the defaults (the simulated
// D435 at 848x480, the full sensor model), so that `hrcsense run --set ...` reproduces it.
// Release builds only, under the ctest label `long`; docs/SAFETY.md ("C and the detection
// capability") quotes the numbers this prints.

#include "../support/decide.hpp"
#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/filters.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr int kLearnFrames = 100;   // background.frames, the default
constexpr int kSphereFrames = 60;   // 2 s at 30 frames/s with the sphere in view
constexpr double kGapM = 0.28;      // from the sphere's surface to the robot point
constexpr double kPi = 3.14159265358979323846;

/// The overrides of the scene: a room (floor 1.2 m below the camera, back wall at 3.6 m, inside
/// the sdk chain's 4 m threshold) seen by a level camera at the base origin; a sphere of
/// diameter `diameter_mm` centred on the camera's axis at `range_m`, a moving object from the
/// first frame after learning; the robot point beside it at the same depth, kGapM from its
/// surface. Everything else is the default configuration (safety.detection_mm 40,
/// foreground.min_object_mm), in `ssm` mode.
std::vector<std::string> scene(const std::string& preset, double range_m, double diameter_mm, int seed) {
  const double radius_m = diameter_mm / 2000.0;
  const std::string z = std::to_string(range_m);
  return {"source.type=sim",
          "source.seed=" + std::to_string(seed),
          "sim.frames=" + std::to_string(kLearnFrames + kSphereFrames),
          "filters.preset=" + preset,
          "background.frames=" + std::to_string(kLearnFrames),
          "safety.mode=ssm",
          "robot.model=points",
          "robot.points_base=[[" + std::to_string(radius_m + kGapM) + ", 0, " + z + "]]",
          "scene.objects=[{name: floor, static: true, shapes: [{plane: {point: [0, 1.2, 0], normal: [0, -1, 0]}}]}, "
          "{name: back wall, static: true, shapes: [{plane: {point: [0, 0, 3.6], normal: [0, 0, -1]}}]}, "
          "{name: test piece, static: false, first_frame: " + std::to_string(kLearnFrames) +
              ", shapes: [{sphere: {center: [0, 0, " + z + "], radius_m: " + std::to_string(radius_m) + "}}]}]"};
}

/// What one distance and preset gave, over the seeds.
struct Tally {
  int frames = 0;      ///< valid frames with the sphere in view
  int run = 0, slow = 0, stop = 0;
  int detected = 0;    ///< with a measured contact
  std::vector<double> size_mm;  ///< per detected frame: the foreground's disc diameter at its mean depth
  float truth_min_m = 1e9F, truth_max_m = 0.0F;  ///< the simulator's true distance, over the frames
};

/// The foreground's size by the speckle rule's definition, recomputed here from its points:
/// 2 · sqrt(n / π) · mean z / fx (fx of the filtered image), mm.
double disc_diameter_mm(const PointCloud& points, float fx_px) {
  if (points.size() == 0) return 0.0;
  double z_sum = 0.0;
  for (const float z : points.z) z_sum += z;
  const double n = static_cast<double>(points.size());
  return 2.0 * std::sqrt(n / kPi) * (z_sum / n) * 1000.0 / fx_px;
}

/// Runs the scene for one seed into `t`; with `require`, a `run` frame is a failure.
void run_sphere(const std::string& preset, double range_m, double diameter_mm, int seed, bool require, Tally& t) {
  const Config config = load_config("", scene(preset, range_m, diameter_mm, seed));
  Simulator sim = make_simulator(config);
  const auto states = make_robot_state_source(config);
  Pipeline pipeline(config.pipeline);
  Frame frame;
  RobotState state;
  FrameResult result;
  for (int64_t i = 0; i < config.sim.frames; ++i) {
    sim.render(i, frame);
    frame.host_time_ns = frame.timestamp_ns;
    if (!states->state_at(frame.host_time_ns, state)) state.valid = false;
    test::process_and_decide(pipeline, frame, state, result);
    if (i < kLearnFrames || !result.valid) continue;
    ++t.frames;
    t.run += result.verdict.state == VerdictState::run ? 1 : 0;
    t.slow += result.verdict.state == VerdictState::slow ? 1 : 0;
    t.stop += result.verdict.state == VerdictState::stop ? 1 : 0;
    if (require && result.verdict.state == VerdictState::run) {
      ADD_FAILURE() << preset << ", sphere at " << range_m << " m, seed " << seed << ": frame " << i << " says run ("
                    << result.verdict.reason << "), " << result.foreground_points << " foreground points";
    }
    if (result.truth && result.truth->valid) {
      t.truth_min_m = std::min(t.truth_min_m, result.truth->distance_m);
      t.truth_max_m = std::max(t.truth_max_m, result.truth->distance_m);
    }
    if (result.contact.valid) {
      ++t.detected;
      const float fx = filtered_intrinsics(config.pipeline.filters, frame.intrinsics).fx;
      t.size_mm.push_back(disc_diameter_mm(pipeline.foreground().points_camera, fx));
    }
  }
}

void report(const std::string& preset, double range_m, Tally& t, const char* note) {
  std::sort(t.size_mm.begin(), t.size_mm.end());
  const auto at = [&](double q) {
    return t.size_mm.empty() ? 0.0 : t.size_mm[static_cast<size_t>(q * static_cast<double>(t.size_mm.size() - 1))];
  };
  std::printf("detection %s at %.2f m%s: %d valid frames with the sphere: %d run, %d slow, %d stop; %d detected, "
              "measured size min %.1f / median %.1f / max %.1f mm; true distance %.3f-%.3f m\n",
              preset.c_str(), range_m, note, t.frames, t.run, t.slow, t.stop, t.detected, at(0.0), at(0.5), at(1.0),
              static_cast<double>(t.truth_min_m), static_cast<double>(t.truth_max_m));
}

/// A filter preset and the distances (m from the camera) where detection_mm must hold: 0.5, 1
/// and 2 m, and the preset's stated detection range (docs/SAFETY.md, "C and the
/// detection capability").
struct Case {
  std::string preset;
  std::vector<double> ranges_m;
  std::vector<double> beyond_m;  ///< measured and reported, not required
};
void PrintTo(const Case& c, std::ostream* os) { *os << c.preset; }

class DetectionCapability : public ::testing::TestWithParam<Case> {};

// A sphere of safety.detection_mm (40 mm) kGapM from the robot, seeds 1-3, 60 frames each.
TEST_P(DetectionCapability, SphereOfDetectionSizeNeverGivesRun) {
  const Case& c = GetParam();
  const double detection_mm = load_config("", {}).pipeline.safety.ssm.detection_mm;
  ASSERT_EQ(detection_mm, 40.0);
  for (const bool required : {true, false}) {
    for (const double range_m : required ? c.ranges_m : c.beyond_m) {
      Tally t;
      for (const int seed : {1, 2, 3}) run_sphere(c.preset, range_m, detection_mm, seed, required, t);
      report(c.preset, range_m, t, required ? "" : " (beyond the stated range, not required)");
      // The scene is what it claims: the sphere in view in every frame after learning, kGapM
      // from the robot point (its nearest rendered pixel lies within a pixel's footprint of it).
      EXPECT_EQ(t.frames, 3 * kSphereFrames) << c.preset << " at " << range_m << " m";
      EXPECT_NEAR(t.truth_min_m, kGapM, 0.01) << c.preset << " at " << range_m << " m";
      if (required) {
        EXPECT_EQ(t.run, 0) << c.preset << " at " << range_m << " m";
        EXPECT_EQ(t.detected, t.frames) << c.preset << " at " << range_m << " m: frames without a contact";
      }
    }
  }
}

// sdk: the D435's defaults (848x480 decimated to 424x240), stated range 2.5 m; beyond it the
// spatial filter merges the sphere, 2-3 px across, into the wall behind it. none: 848x480,
// required at 3 m.
INSTANTIATE_TEST_SUITE_P(Presets, DetectionCapability,
                         ::testing::Values(Case{"sdk", {0.5, 1.0, 2.0, 2.5}, {3.0}}, Case{"none", {0.5, 1.0, 2.0, 3.0}, {}}),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.preset; });

}  // namespace
}  // namespace hrcsense
