// SPDX-License-Identifier: Apache-2.0
// The extractor's per-background tables against the float test they solve, and the whole
// extractor against itself with the image moved by a few pixels, on simulated and random
// hand-built frames: the mask must move along and the clouds stay bit for bit the same. The
// rules themselves are checked on hand-worked frames (foreground_hand_test.cpp). Also the
// fail-safe side of preparing.

#include "../support/scenes.hpp"
#include "../support/decide.hpp"
#include "src/segmentation/foreground_tables.hpp"
#include "synthetic_frames.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

/// The per-pixel float test the thresholds solve: valid raw r is a candidate iff it passes.
/// (Its rule is checked by hand in foreground_hand_test.cpp; here only the solving.)
bool float_test(int r, float mean_m, float spread_m, const detail::NearerTest& t) {
  return detail::nearer_than_background(static_cast<uint16_t>(r), mean_m, spread_m, t);
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
          for (int r = 1; r <= 65535; ++r) expected += float_test(r, mean_m, spread_m, test) ? 1 : 0;
          const int count = detail::nearer_raw_count(mean_m, spread_m, test);
          ASSERT_EQ(count, expected) << "mean " << mean_m << " spread " << spread_m << " scale " << scale
                                     << " k_model " << k_model << " min_margin " << min_margin;
          // Monotone: the passing depths are exactly 1..count.
          if (count > 0) {
            EXPECT_TRUE(float_test(count, mean_m, spread_m, test));
          }
          if (count < 65535) {
            EXPECT_FALSE(float_test(count + 1, mean_m, spread_m, test));
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

/// `frame` and `background` placed at (du, dv) in an image `pad` pixels larger than that on the
/// right and bottom, with the principal point moved along: every pixel keeps its ray (u − ppx
/// and v − ppy are exact in float for these values). Around it the depth is 0 and the
/// background unknown, and no valid depth is ever foreground there.
struct Moved {
  Frame frame;
  BackgroundModel background;
};
Moved moved(const Frame& frame, const BackgroundModel& background, int du, int dv, int pad) {
  const int w = frame.depth.width;
  const int h = frame.depth.height;
  const int W = w + du + pad;
  const int H = h + dv + pad;
  Moved out{frame, BackgroundModel{}};
  out.frame.depth.resize(W, H);
  std::fill(out.frame.depth.pixels.begin(), out.frame.depth.pixels.end(), uint16_t{0});
  out.frame.intrinsics.width = W;
  out.frame.intrinsics.height = H;
  out.frame.intrinsics.ppx += static_cast<float>(du);
  out.frame.intrinsics.ppy += static_cast<float>(dv);
  const size_t n = static_cast<size_t>(W) * static_cast<size_t>(H);
  out.background.width = W;
  out.background.height = H;
  out.background.mean_m.assign(n, 0.0F);
  out.background.spread_m.assign(n, 0.0F);
  out.background.valid_ratio.assign(n, 0.0F);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t from = static_cast<size_t>(v) * static_cast<size_t>(w) + static_cast<size_t>(u);
      const size_t to = static_cast<size_t>(v + dv) * static_cast<size_t>(W) + static_cast<size_t>(u + du);
      out.frame.depth.pixels[to] = frame.depth.pixels[from];
      out.background.mean_m[to] = background.mean_m[from];
      out.background.spread_m[to] = background.spread_m[from];
      out.background.valid_ratio[to] = background.valid_ratio[from];
    }
  }
  return out;
}

/// The extractor's result on `frame` and on the same frame moved by (du, dv) into a larger
/// image must be the same: the rules look at a pixel, its neighbours and its ray, never at
/// where it lies in the image. So the mask moves with the image, and the points, in the same
/// order, are bit for bit the same. What this checks is the machinery that does depend on the
/// position: the scans that skip 16 pixels at a time and empty rows, the image border in the
/// flood fill, the rows deprojection visits. The rules themselves: foreground_hand_test.cpp.
void expect_moves_with_image(const Frame& frame, const BackgroundModel& background, const ForegroundParams& params,
                             const Pose& T_base_camera, const std::string& where, size_t& points) {
  ForegroundExtractor extractor;
  extractor.params = params;
  extractor.set_background(background, frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
  Foreground at_origin;
  ASSERT_TRUE(extractor.extract(frame, T_base_camera, at_origin)) << where;
  points += at_origin.points_camera.size();
  const int w = frame.depth.width;
  for (const auto& [du, dv, pad] : {std::array<int, 3>{1, 0, 0}, {3, 1, 5}, {8, 2, 1}, {15, 0, 16}, {17, 5, 3}}) {
    const std::string at = where + " moved by (" + std::to_string(du) + ", " + std::to_string(dv) + ")";
    const Moved m = moved(frame, background, du, dv, pad);
    const int W = m.frame.depth.width;
    ForegroundExtractor moved_extractor;
    moved_extractor.params = params;
    moved_extractor.set_background(m.background, m.frame.intrinsics.fx, m.frame.stereo_baseline_mm,
                                   m.frame.depth.depth_scale_m);
    Foreground fg;
    ASSERT_TRUE(moved_extractor.extract(m.frame, T_base_camera, fg)) << at;
    // Pixel index i of the original image → its index in the moved one.
    const auto moved_index = [&](size_t i) {
      const size_t u = i % static_cast<size_t>(w) + static_cast<size_t>(du);
      const size_t v = i / static_cast<size_t>(w) + static_cast<size_t>(dv);
      return v * static_cast<size_t>(W) + u;
    };
    std::vector<uint8_t> expected_mask(fg.mask.size(), 0);
    for (size_t i = 0; i < at_origin.mask.size(); ++i) expected_mask[moved_index(i)] = at_origin.mask[i];
    std::vector<uint32_t> expected_pixel;
    for (const uint32_t pixel : at_origin.points_camera.pixel) {
      expected_pixel.push_back(static_cast<uint32_t>(moved_index(pixel)));
    }
    ASSERT_EQ(fg.mask, expected_mask) << at;
    ASSERT_EQ(fg.points_camera.pixel, expected_pixel) << at;
    ASSERT_EQ(fg.points_base.pixel, expected_pixel) << at;
    ASSERT_EQ(fg.points_camera.x, at_origin.points_camera.x) << at;
    ASSERT_EQ(fg.points_camera.y, at_origin.points_camera.y) << at;
    ASSERT_EQ(fg.points_camera.z, at_origin.points_camera.z) << at;
    ASSERT_EQ(fg.points_base.x, at_origin.points_base.x) << at;
    ASSERT_EQ(fg.points_base.y, at_origin.points_base.y) << at;
    ASSERT_EQ(fg.points_base.z, at_origin.points_base.z) << at;
  }
}

/// Renders a configured scene, learns its background, and checks on `frames` that the
/// foreground moves with the image.
void moves_on_scene(const std::string& config_name, uint64_t seed, const std::vector<int64_t>& frames) {
  const std::string path = test::scene_path(config_name);
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
  size_t points = 0;
  for (const int64_t index : frames) {
    sim.render(index, frame);
    expect_moves_with_image(frame, learner.model(), config.pipeline.foreground, config.pipeline.T_base_camera,
                            config_name + " seed " + std::to_string(seed) + " frame " + std::to_string(index), points);
  }
  EXPECT_GT(points, 1000U) << config_name << ": the frames should show the object";
}

// The walk: the person far, close to the robot and leaving.
TEST(FastExtractor, MovesWithTheImageOnWalk) { moves_on_scene("walk.yaml", 2, {130, 215}); }

// The thesis box (with its shiny table's dropouts: unknown background).
TEST(FastExtractor, MovesWithTheImageOnThesisBox) { moves_on_scene("thesis-box.yaml", 4, {100, 150}); }

// Random rectangles at random depths over the small wall, touching the image border, with an
// unknown patch of background, a workspace, a rotated camera and sometimes distortion.
TEST(FastExtractor, MovesWithTheImageOnRandomHandBuiltFrames) {
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
  size_t points = 0;
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
    expect_moves_with_image(frame, background, params, T_base_camera, "random frame " + std::to_string(f), points);
  }
  EXPECT_GT(points, 200U * kRandomFrames) << "the rectangles should be foreground";
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
  // The second background lies nearer than the wall on purpose, which the camera-moved
  // watchdog would take for a moved camera: off here.
  params.checks.moved_min_valid = static_cast<size_t>(-1);
  Pipeline pipeline(params);
  Frame frame = wall_frame(2);
  fill_rect(frame, 20, 15, 10, 10, 1700);
  FrameResult result;
  pipeline.set_background(wall_background());
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  ASSERT_TRUE(result.valid) << result.verdict.reason;
  EXPECT_EQ(result.foreground_points, 100U);
  BackgroundModel nearer_wall = wall_background();
  nearer_wall.mean_m.assign(nearer_wall.mean_m.size(), 1.5F);
  pipeline.set_background(nearer_wall);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  ASSERT_TRUE(result.valid) << result.verdict.reason;
  EXPECT_EQ(result.foreground_points, 0U);
}

}  // namespace
}  // namespace hrcsense
