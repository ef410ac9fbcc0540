// SPDX-License-Identifier: Apache-2.0
// The extractor's per-background tables against the float formulas they replace, and the whole
// extractor against the plain reference (reference_foreground.hpp) on simulated and hand-built
// frames: masks and clouds must be identical. Also the fail-safe side of preparing.

#include "../../src/segmentation/foreground_tables.hpp"
#include "reference_foreground.hpp"
#include "synthetic_frames.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/pipeline.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using namespace hrcsense::testing;
namespace detail = segmentation_detail;

#if defined(__SANITIZE_ADDRESS__)
constexpr int kLearnFrames = 30;  // sanitizers: the same checks on fewer frames
constexpr int kRandomFrames = 10;
#else
constexpr int kLearnFrames = 100;
constexpr int kRandomFrames = 60;
#endif

/// The old per-pixel test, written out again: valid raw r is foreground iff it passes.
bool old_test(int r, float mean_m, float spread_m, const detail::NearerTest& t) {
  const float z = static_cast<float>(r) * t.depth_scale_m;
  const float a = t.k_sigma * spread_m;
  const float b = t.k_model * z * z;
  const float ab = a > b ? a : b;
  const float margin = ab > t.min_margin_m ? ab : t.min_margin_m;
  return z < mean_m - margin;
}

// For every raw depth 1..65535, the threshold says exactly what the float test says, including
// spreads that are NaN or infinite, means beyond the raw range and odd depth units.
TEST(NearerTable, AgreesWithFloatTestAtEveryRawDepth) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<std::pair<float, float>> pixels = {{0.3F, 0.0F},  {1.0F, 0.0014F}, {2.0F, 0.003F}, {3.5F, 0.05F},
                                                 {9.9F, 0.2F},  {65.0F, 0.0F},   {70.0F, 0.01F}, {inf, 0.0F},
                                                 {2.0F, nan},   {2.0F, inf},     {0.021F, 0.0F}, {1e-4F, 0.0F}};
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> mean(0.2F, 12.0F);
  std::uniform_real_distribution<float> spread(0.0F, 0.05F);
  for (int i = 0; i < 12; ++i) pixels.emplace_back(mean(rng), spread(rng));
  // k_model for a D435 at 848x480 (fx 424 px, B 50 mm, 0.08 px) at k_sigma 4, none, and a
  // very noisy camera.
  const float d435 = 4.0F * 0.08F / (424.0F * 0.05F);
  for (const float scale : {0.001F, 0.0001F, 0.00025F}) {
    for (const float k_model : {0.0F, d435, 100.0F * d435}) {
      for (const float min_margin : {0.0F, 0.02F}) {
        const detail::NearerTest test{scale, 4.0F, k_model, min_margin};
        for (const auto& [mean_m, spread_m] : pixels) {
          int expected = 0;
          for (int r = 1; r <= 65535; ++r) expected += old_test(r, mean_m, spread_m, test) ? 1 : 0;
          const int count = detail::nearer_raw_count(mean_m, spread_m, test);
          ASSERT_EQ(count, expected) << "mean " << mean_m << " spread " << spread_m << " scale " << scale
                                     << " k_model " << k_model << " min_margin " << min_margin;
          // Monotone: the passing depths are exactly 1..count.
          if (count > 0) {
            EXPECT_TRUE(old_test(count, mean_m, spread_m, test));
          }
          if (count < 65535) {
            EXPECT_FALSE(old_test(count + 1, mean_m, spread_m, test));
          }
        }
      }
    }
  }
}

// Hand-computed: wall at 2.000 m, spread 1.4 mm, k 4, fx 200 px, B 50 mm, 0.08 px: margin =
// max(5.6 mm, 4 · 0.08 / 10 · z² = 0.032 z², 20 mm), the quadratic near 1.9 m (115 mm). The
// boundary solves z + 0.032 z² = 2: z = (sqrt(1 + 0.256) − 1) / 0.064 = 1.88616 m, so 1 mm
// units 1..1886 are foreground.
TEST(NearerTable, BoundaryOfHandComputedPixel) {
  const detail::NearerTest test{0.001F, 4.0F, 4.0F * 0.08F / (200.0F * 0.05F), 0.02F};
  EXPECT_EQ(detail::nearer_raw_count(2.0F, 0.0014F, test), 1886);
  // No baseline and spread 6.1 mm: margin max(24.4 mm, 20 mm), foreground below 1.9756 m.
  EXPECT_EQ(detail::nearer_raw_count(2.0F, 0.0061F, {0.001F, 4.0F, 0.0F, 0.02F}), 1975);
  // 0.1 mm units: below 1.9756 m is 1..19755.
  EXPECT_EQ(detail::nearer_raw_count(2.0F, 0.0061F, {0.0001F, 4.0F, 0.0F, 0.02F}), 19755);
}

// The jump-limit table is ceil(max(5 cm, 4 σ_model(z))) in raw units for every raw depth.
TEST(JumpLimits, AreTheRoundedUpFloatLimit) {
  std::vector<int32_t> limit(65536);
  for (const float scale : {0.001F, 0.0001F}) {
    for (const float jump_per_z2 : {0.0F, 4.0F * 0.08F / (424.0F * 0.05F)}) {
      detail::build_jump_limits(scale, jump_per_z2, limit.data());
      const float jump_min_raw = 0.05F / scale;
      const float jump_per_raw2 = jump_per_z2 * scale;
      for (int r = 0; r < 65536; ++r) {
        const float far = static_cast<float>(r);
        const double expected = std::ceil(static_cast<double>(std::max(jump_min_raw, jump_per_raw2 * far * far)));
        ASSERT_EQ(limit[static_cast<size_t>(r)], static_cast<int32_t>(std::min(expected, 65536.0))) << "raw " << r;
      }
    }
  }
  // By hand at 1 mm units: 50 raw units up to where 4 · 0.0151 · z² reaches 5 cm (z ≈ 0.91 m),
  // 4 · 0.08 / 21.2 · 3² = 135.8 mm → 136 at 3 m.
  detail::build_jump_limits(0.001F, 4.0F * 0.08F / (424.0F * 0.05F), limit.data());
  EXPECT_EQ(limit[500], 50);
  EXPECT_EQ(limit[3000], 136);
}

/// Expects the extractor's result to be the reference's: same mask, bit-identical camera
/// points, base points T_base_camera · camera points (float rounding only).
void expect_same(const Foreground& fast, const ReferenceForeground& ref, const Pose& T_base_camera,
                 const std::string& where) {
  ASSERT_EQ(fast.mask, ref.mask) << where;
  ASSERT_EQ(fast.points_camera.pixel, ref.points_camera.pixel) << where;
  ASSERT_EQ(fast.points_camera.x, ref.points_camera.x) << where;
  ASSERT_EQ(fast.points_camera.y, ref.points_camera.y) << where;
  ASSERT_EQ(fast.points_camera.z, ref.points_camera.z) << where;
  ASSERT_EQ(fast.points_base.pixel, ref.points_camera.pixel) << where;
  for (size_t i = 0; i < fast.points_base.size(); ++i) {
    const Eigen::Vector3d expected = T_base_camera * ref.points_camera.point(i).cast<double>();
    ASSERT_LT((fast.points_base.point(i).cast<double>() - expected).norm(), 1e-5) << where << " point " << i;
  }
}

/// Renders a configured scene, learns its background, and compares the extractor with the
/// reference on `frames`.
void compare_on_scene(const std::string& config_name, uint64_t seed, const std::vector<int64_t>& frames) {
  const std::string path = std::string(HRCSENSE_SOURCE_DIR) + "/config/" + config_name;
  const Config config = load_config(path, {"source.seed=" + std::to_string(seed)});
  const Simulator sim = make_simulator(config);
  BackgroundLearner learner;
  learner.params = config.pipeline.background;
  learner.params.frames = kLearnFrames;
  Frame frame;
  for (int64_t i = 0; i < kLearnFrames; ++i) {
    sim.render(i, frame);
    learner.add(frame);
  }
  ASSERT_TRUE(learner.ready()) << config_name << ": " << learner.message();
  ForegroundExtractor extractor;
  extractor.params = config.pipeline.foreground;
  extractor.set_background(learner.model(), frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
  Foreground fast;
  size_t points = 0;
  for (const int64_t index : frames) {
    sim.render(index, frame);
    ASSERT_TRUE(extractor.extract(frame, config.pipeline.T_base_camera, fast));
    const ReferenceForeground ref =
        reference_foreground(frame, learner.model(), config.pipeline.foreground, config.pipeline.T_base_camera);
    expect_same(fast, ref, config.pipeline.T_base_camera,
                config_name + " seed " + std::to_string(seed) + " frame " + std::to_string(index));
    points += ref.points_camera.size();
  }
  EXPECT_GT(points, 1000U) << config_name << ": the frames should show the object";
}

// The walk: the person far, close to the robot and leaving; two noise seeds.
TEST(FastExtractor, MatchesReferenceOnWalk) {
  for (const uint64_t seed : {2U, 9U}) compare_on_scene("walk.yaml", seed, {130, 186, 215, 260});
}

// The thesis box (with its shiny table's dropouts: unknown background); two noise seeds.
TEST(FastExtractor, MatchesReferenceOnThesisBox) {
  for (const uint64_t seed : {4U, 13U}) compare_on_scene("thesis-box.yaml", seed, {100, 101, 150});
}

// Random rectangles at random depths over the small wall, touching the image border, with an
// unknown patch of background, a workspace, a rotated camera and sometimes distortion.
TEST(FastExtractor, MatchesReferenceOnRandomHandBuiltFrames) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> u_pick(-4, kWidth - 2);
  std::uniform_int_distribution<int> v_pick(-4, kHeight - 2);
  std::uniform_int_distribution<int> side(1, 14);
  std::uniform_int_distribution<int> raw_pick(900, 2100);
  BackgroundModel background = wall_background();
  for (int v = 30; v < 44; ++v) {
    for (int u = 40; u < 60; ++u) background.mean_m[static_cast<size_t>(v) * kWidth + u] = 0.0F;
  }
  background.spread_m[5] = std::numeric_limits<float>::quiet_NaN();
  Pose T_base_camera = Pose::Identity();
  T_base_camera.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T_base_camera.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  for (int f = 0; f < kRandomFrames; ++f) {
    Frame frame = wall_frame(f);
    if (f % 3 == 2) {
      frame.intrinsics.model = Distortion::brown_conrady;
      frame.intrinsics.coeffs = {0.1F, -0.05F, 0.001F, 0.002F, 0.01F};
    }
    for (int k = 0; k < 8; ++k) {
      const int u0 = std::max(u_pick(rng), 0);
      const int v0 = std::max(v_pick(rng), 0);
      const int w = std::min(side(rng), kWidth - u0);
      const int h = std::min(side(rng), kHeight - v0);
      fill_rect(frame, u0, v0, w, h, static_cast<uint16_t>(k == 7 ? 0 : raw_pick(rng)));
    }
    ForegroundParams params;
    params.min_object_mm = f % 2 == 0 ? 40.0F : 15.0F;
    if (f % 4 == 1) params.workspace_base.max.z() = 1.8F;
    ForegroundExtractor extractor;
    extractor.params = params;
    extractor.set_background(background, frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
    Foreground fast;
    ASSERT_TRUE(extractor.extract(frame, T_base_camera, fast));
    expect_same(fast, reference_foreground(frame, background, params, T_base_camera), T_base_camera,
                "random frame " + std::to_string(f));
  }
}

// Unprepared, or prepared for another camera or other parameters: extract() refuses (false,
// nothing in the output) rather than report an empty, "all clear" foreground.
TEST(FastExtractor, RefusesFramesItWasNotPreparedFor) {
  Frame frame = wall_frame(1);
  fill_rect(frame, 20, 15, 10, 10, 1700);
  ForegroundExtractor extractor;
  Foreground out;
  out.mask.assign(3, 1);
  EXPECT_FALSE(extractor.extract(frame, Pose::Identity(), out));
  EXPECT_TRUE(out.mask.empty());
  EXPECT_TRUE(out.points_base.empty());

  extractor.set_background(wall_background(), kFx, kBaselineMm, 0.001F);
  ASSERT_TRUE(extractor.extract(frame, Pose::Identity(), out));
  EXPECT_EQ(out.points_base.size(), 100U);

  Frame other_scale = frame;
  other_scale.depth.depth_scale_m = 0.0001F;
  Frame other_fx = frame;
  other_fx.intrinsics.fx = 2 * kFx;
  Frame other_baseline = frame;
  other_baseline.stereo_baseline_mm = 0.0F;
  const Frame smaller = wall_frame(1, kWidth / 2, kHeight / 2);
  for (const Frame* bad : std::vector<const Frame*>{&other_scale, &other_fx, &other_baseline, &smaller}) {
    EXPECT_FALSE(extractor.prepared_for(*bad));
    EXPECT_FALSE(extractor.extract(*bad, Pose::Identity(), out));
    EXPECT_TRUE(out.points_base.empty());
  }
  extractor.params.k_sigma = 2.0F;  // the tables depend on it
  EXPECT_FALSE(extractor.extract(frame, Pose::Identity(), out));
  extractor.params.k_sigma = 4.0F;
  extractor.params.min_object_mm = 10.0F;  // read per frame: no new tables needed
  EXPECT_TRUE(extractor.extract(frame, Pose::Identity(), out));
  extractor.clear_background();
  EXPECT_FALSE(extractor.extract(frame, Pose::Identity(), out));
}

// The pipeline prepares the extractor for a background set on it, and again for a new one: a
// patch at 1.7 m is foreground before a wall at 2 m, but not before a wall at 1.5 m.
TEST(FastExtractor, PipelineUsesTheBackgroundSetLast) {
  PipelineParams params;
  Capsule robot_point;
  robot_point.a = robot_point.b = {0.0F, 0.0F, 0.5F};
  params.robot.points.capsules.push_back(robot_point);
  params.background.check_frames = 0;  // trusted at once: this test is about the extractor
  Pipeline pipeline(params);
  Frame frame = wall_frame(2);
  fill_rect(frame, 20, 15, 10, 10, 1700);
  FrameResult result;
  pipeline.set_background(wall_background());
  pipeline.process(frame, fixed_robot_state({}), result);
  ASSERT_TRUE(result.valid) << result.verdict.reason;
  EXPECT_EQ(result.foreground_points, 100U);
  BackgroundModel nearer_wall = wall_background();
  nearer_wall.mean_m.assign(nearer_wall.mean_m.size(), 1.5F);
  pipeline.set_background(nearer_wall);
  pipeline.process(frame, fixed_robot_state({}), result);
  ASSERT_TRUE(result.valid) << result.verdict.reason;
  EXPECT_EQ(result.foreground_points, 0U);
}

}  // namespace
}  // namespace hrcsense
