// SPDX-License-Identifier: Apache-2.0
// Acceptance of the depth filters on the simulator (issue 4): on the thesis's box scene the
// thesis preset lowers the frame-to-frame noise of static pixels and the count of invalid
// pixels, keeps the closest distance within 10 mm on average and 40 mm at worst over 300
// frames at 848x480; and the default sdk preset runs the pipeline at the decimated resolution.
// The numbers these tests print are the ones in docs/ACCURACY.md.

#include "../support/scenes.hpp"
#include "../support/decide.hpp"
#include "../support/sanitized.hpp"
#include "common/assembly.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::scene_path;

using test::kSanitized;

/// The thesis box scene with `preset`; learning shortened to `learn_frames` and the box moved to
/// appear right after it, so that no frame is rendered for nothing. No colour camera.
Config thesis_box(const std::string& preset, const std::string& seed, int learn_frames) {
  Config config = load_config(scene_path("thesis-box.yaml"),
                              {"filters.preset=" + preset, "source.seed=" + seed,
                               "background.frames=" + std::to_string(learn_frames)});
  config.sim.color = false;
  for (SceneObject& object : config.scene.objects)
    if (!object.is_static) object.first_frame = learn_frames;
  return config;
}

/// Per-pixel statistics of the filtered depth over a run of the empty scene.
struct NoiseStats {
  double mean_std_mm = 0.0;        ///< frame-to-frame standard deviation, averaged over pixels
  double mean_invalid = 0.0;       ///< invalid (0) pixels per frame
  size_t pixels = 0;               ///< pixels the standard deviation is averaged over
};

/// Renders frames [0, frames) of the empty thesis box scene, filters them with `preset` and
/// measures on frames [warmup, frames): the temporal filter's history needs a few frames.
/// Standard deviations are taken over the pixels `stable` marks (valid in every measured
/// unfiltered frame; the first call, with `stable` empty, fills it), so both presets are
/// compared on the same pixels.
NoiseStats filtered_noise(const std::string& preset, int frames, int warmup, std::vector<uint8_t>& stable) {
  Config config = thesis_box(preset, "3101", 1);
  for (SceneObject& object : config.scene.objects)
    if (!object.is_static) object.first_frame = 1'000'000;  // static pixels only
  const Simulator sim = make_simulator(config);
  FilterChain chain;
  chain.params = config.pipeline.filters;
  Frame source, filtered;
  std::vector<double> sum, sum_sq;
  std::vector<int> valid;
  size_t invalid = 0;
  for (int i = 0; i < frames; ++i) {
    sim.render(i, source);
    chain.process(source, filtered);
    if (i < warmup) continue;
    const std::vector<uint16_t>& raw = filtered.depth.pixels;
    sum.resize(raw.size());
    sum_sq.resize(raw.size());
    valid.resize(raw.size());
    for (size_t p = 0; p < raw.size(); ++p) {
      if (raw[p] == 0) {
        ++invalid;
        continue;
      }
      sum[p] += raw[p];
      sum_sq[p] += static_cast<double>(raw[p]) * raw[p];
      ++valid[p];
    }
  }
  const int measured = frames - warmup;
  if (stable.empty()) {  // the unfiltered run chooses the pixels
    stable.resize(valid.size());
    for (size_t p = 0; p < valid.size(); ++p) stable[p] = valid[p] == measured ? 1 : 0;
  }
  NoiseStats stats;
  double std_sum = 0.0;
  for (size_t p = 0; p < valid.size(); ++p) {
    if (!stable[p] || valid[p] != measured) continue;  // filters keep valid pixels valid (tested)
    const double mean = sum[p] / measured;
    const double variance = std::max(0.0, (sum_sq[p] - measured * mean * mean) / (measured - 1));
    std_sum += std::sqrt(variance) * filtered.depth.depth_scale_m * 1e3;
    ++stats.pixels;
  }
  stats.mean_std_mm = stats.pixels > 0 ? std_sum / static_cast<double>(stats.pixels) : 0.0;
  stats.mean_invalid = static_cast<double>(invalid) / measured;
  return stats;
}

// Margins (docs/ACCURACY.md, "Depth filters on the thesis box"). Noise: the sensor model's
// disparity noise is independent per pixel and new every frame, and well within both filters'
// δ, so two bounds hold on their own: the temporal filter, an exponential average with α 0.4,
// keeps sqrt(α / (2 − α)) = 0.5 of the standard deviation, and so does the spatial filter's
// first one-directional pass (same recursion along a row); its further passes only lower it.
// Together at most 0.25; the measurement is far below (about 0.05), as the spatial passes
// average dozens of pixels. Invalid pixels: only the random dropouts can go (speckle, 0.2 % of
// the pixels, new every frame; persistence 3 fills a pixel valid in 2 of the last 4 frames);
// the fixed ones (the left band, occlusion shadows, edge and shiny-table dropouts, fixed per
// seed) stay. So the assertion asks for at least half the speckle share fewer invalid pixels.
TEST(FiltersAcceptance, ThesisPresetLowersStaticNoiseAndInvalidPixels) {
  const int frames = kSanitized ? 16 : 40;
  const int warmup = 8;
  std::vector<uint8_t> stable;
  const NoiseStats none = filtered_noise("none", frames, warmup, stable);
  const NoiseStats thesis = filtered_noise("thesis", frames, warmup, stable);
  std::printf("static pixels: %zu; frame-to-frame std %.2f mm unfiltered, %.2f mm thesis (x%.3f); "
              "invalid pixels per frame %.0f unfiltered, %.0f thesis (x%.3f)\n",
              none.pixels, none.mean_std_mm, thesis.mean_std_mm, thesis.mean_std_mm / none.mean_std_mm,
              none.mean_invalid, thesis.mean_invalid, thesis.mean_invalid / none.mean_invalid);
  RecordProperty("std_none_mm", std::to_string(none.mean_std_mm));
  RecordProperty("std_thesis_mm", std::to_string(thesis.mean_std_mm));
  RecordProperty("invalid_none", std::to_string(none.mean_invalid));
  RecordProperty("invalid_thesis", std::to_string(thesis.mean_invalid));
  ASSERT_GT(none.pixels, 848U * 480U / 2);  // most of the image is a stable wall and table
  EXPECT_EQ(thesis.pixels, none.pixels);    // no filter turned a stable pixel invalid
  EXPECT_GT(none.mean_std_mm, 1.0);         // the sensor model's noise is there to be removed
  EXPECT_LE(thesis.mean_std_mm, 0.25 * none.mean_std_mm);
  const double speckle_pixels = static_cast<double>(SimParams{}.speckle) * 848 * 480;
  EXPECT_LE(thesis.mean_invalid, none.mean_invalid - 0.5 * speckle_pixels);
}

// Issue 4: with the thesis preset at 848x480, the closest distance's mean absolute error over
// 300 frames is at most 10 mm and no frame is off by more than 40 mm. Under sanitizers the
// same check runs on 60 frames (a fifth) to keep the suite fast.
TEST(FiltersAcceptance, ThesisPresetClosestDistanceWithinTenMillimetres) {
  const int learn = 30;
  const int measured = kSanitized ? 60 : 300;
  const Config config = thesis_box("thesis", "5303", learn);
  ASSERT_EQ(config.sim.width, 848);
  ASSERT_EQ(config.sim.height, 480);
  const Simulator sim = make_simulator(config);
  Pipeline pipeline(config.pipeline);
  Frame frame;
  FrameResult result;
  double sum_abs_m = 0.0, sum_signed_m = 0.0, max_abs_m = 0.0;
  int n = 0;
  for (int i = 0; i < learn + measured; ++i) {
    sim.render(i, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state(config.robot_state.joints_rad), result);
    if (i < learn) continue;
    ASSERT_TRUE(result.valid) << "frame " << i << ": " << result.verdict.reason;
    ASSERT_TRUE(frame.truth->contact.valid) << "frame " << i;
    ASSERT_TRUE(result.contact.valid) << "frame " << i;
    const double error_m = static_cast<double>(result.contact.distance_m) - frame.truth->contact.distance_m;
    sum_abs_m += std::abs(error_m);
    sum_signed_m += error_m;
    max_abs_m = std::max(max_abs_m, std::abs(error_m));
    ++n;
  }
  ASSERT_EQ(n, measured);
  const double mae_m = sum_abs_m / n;
  std::printf("thesis preset, %d frames: mean |error| %.2f mm, signed mean %+.2f mm, max |error| %.2f mm\n", n,
              mae_m * 1e3, sum_signed_m / n * 1e3, max_abs_m * 1e3);
  RecordProperty("mae_mm", std::to_string(mae_m * 1e3));
  RecordProperty("max_mm", std::to_string(max_abs_m * 1e3));
  EXPECT_LE(mae_m, 0.010);
  EXPECT_LE(max_abs_m, 0.040);
}

// The default preset (sdk) decimates ×2: the background is learnt at the filtered resolution,
// the contact's pixel indexes the filtered image (deprojecting it with the filtered intrinsics
// gives the contact point), and the distance still follows the truth.
TEST(FiltersAcceptance, SdkPresetRunsAtTheDecimatedResolution) {
  const int learn = 10;
  const int measured = kSanitized ? 4 : 20;
  Config config = thesis_box("sdk", "6404", learn);
  config.sim.width = 424;  // a D435 mode; smaller keeps the test fast
  config.sim.height = 240;
  const Simulator sim = make_simulator(config);
  Pipeline pipeline(config.pipeline);
  FilterChain chain;  // the same chain beside the pipeline, to see the image it worked on
  chain.params = config.pipeline.filters;
  Frame frame, filtered;
  FrameResult result;
  for (int i = 0; i < learn + measured; ++i) {
    sim.render(i, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state(config.robot_state.joints_rad), result);
    chain.process(frame, filtered);
    if (i < learn) continue;
    ASSERT_TRUE(result.valid) << "frame " << i << ": " << result.verdict.reason;
    ASSERT_EQ(pipeline.background().width, 212);
    ASSERT_EQ(pipeline.background().height, 120);
    ASSERT_EQ(filtered.depth.width, 212);
    ASSERT_TRUE(result.contact.valid) << "frame " << i;
    const int pixel = result.contact.pixel;
    ASSERT_GE(pixel, 0);
    ASSERT_LT(pixel, 212 * 120);
    const Eigen::Vector2f uv(static_cast<float>(pixel % 212), static_cast<float>(pixel / 212));
    const float z_m = filtered.depth.depth_scale_m * static_cast<float>(filtered.depth.pixels[static_cast<size_t>(pixel)]);
    const Eigen::Vector3f point = *deproject(filtered.intrinsics, uv, z_m);
    EXPECT_LT((point - result.contact.closest_camera).norm(), 1e-4F) << "frame " << i;
    // Decimation doubles the pixel footprint (4.7 mm at 1 m); 30 mm bounds noise and edges.
    EXPECT_NEAR(result.contact.distance_m, frame.truth->contact.distance_m, 0.030) << "frame " << i;
  }
}

/// Closest distance minus truth, averaged while approaching and while standing still.
struct Excess {
  double approach_m = 0.0;
  double still_m = 0.0;
};

/// The person of config/walk.yaml walks straight at the robot point (along the optical axis,
/// 1 m/s, from z = 3.2 m to 2.06 m) and stands there; noise-free, so that only the filters move
/// the distance. Standing still shows what the spatial filter's smoothing of edges adds on its
/// own; the approach adds the temporal filter's lag to it.
Excess headon_excess(const std::string& preset) {
  const int learn = 10;
  Config config = load_config(scene_path("walk.yaml"), {"filters.preset=" + preset, "sim.noise=false",
                                                        "sim.width=424", "sim.height=240",
                                                        "background.frames=" + std::to_string(learn)});
  config.sim.color = false;
  const double fps = config.sim.fps, start_s = learn / fps, arrive_s = start_s + 1.14;
  for (SceneObject& object : config.scene.objects) {
    if (object.is_static) continue;
    object.first_frame = learn;
    object.path = {{start_s, {-0.3F, 0.0F, 3.2F}}, {arrive_s, {-0.3F, 0.0F, 2.06F}}};
  }
  const Simulator sim = make_simulator(config);
  Pipeline pipeline(config.pipeline);
  Frame frame;
  FrameResult result;
  // Approach: from the 5th frame on (the temporal filter's steady state) to arrival. Still: from
  // 8 frames after arrival (the filter has settled: 0.6^8 < 2 %) for 15 frames.
  const int approach_first = learn + 4, arrive = static_cast<int>(arrive_s * fps);
  const int still_first = arrive + 8, still_last = still_first + 14;
  double approach_sum_m = 0.0, still_sum_m = 0.0;
  int approach_n = 0, still_n = 0;
  for (int i = 0; i <= still_last; ++i) {
    sim.render(i, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state(config.robot_state.joints_rad), result);
    const bool approaching = i >= approach_first && i < arrive, still = i >= still_first;
    if (!approaching && !still) continue;
    EXPECT_TRUE(result.contact.valid && frame.truth->contact.valid) << preset << " frame " << i;
    if (!result.contact.valid || !frame.truth->contact.valid) continue;
    const double excess_m = static_cast<double>(result.contact.distance_m) - frame.truth->contact.distance_m;
    (approaching ? approach_sum_m : still_sum_m) += excess_m;
    ++(approaching ? approach_n : still_n);
  }
  EXPECT_GT(approach_n, 20);
  EXPECT_EQ(still_n, 15);
  return {approach_n > 0 ? approach_sum_m / approach_n : 0.0, still_n > 0 ? still_sum_m / still_n : 0.0};
}

// The temporal filter's lag errs on the unsafe side: approaching, the filtered distance is
// larger than the truth. For an exponential average with weight α on the current frame and a
// steady approach the lag is (1 − α)/α frames: 1.5 frames, 50 ms at 30 fps, 50 mm at 1 m/s
// (the per-frame change, 33 mm or 5.5 disparity units at 2 m, stays within δ = 20, so the
// filter never restarts). Asserted between 1 and 2 frames of motion; docs/ACCURACY.md,
// "Temporal filter lag", has the measurement and the lateral approach of walk.yaml.
TEST(FiltersAcceptance, TemporalLagOfAHeadOnApproachIsOneAndAHalfFrames) {
  const Excess none = headon_excess("none");
  const Excess thesis = headon_excess("thesis");
  const double lag_s = ((thesis.approach_m - thesis.still_m) - (none.approach_m - none.still_m)) / 1.0;  // 1 m/s
  std::printf("head-on approach at 1 m/s: distance - truth approaching %+.1f mm unfiltered, %+.1f mm thesis; "
              "standing %+.1f / %+.1f mm; lag %.0f ms\n",
              none.approach_m * 1e3, thesis.approach_m * 1e3, none.still_m * 1e3, thesis.still_m * 1e3, lag_s * 1e3);
  RecordProperty("lag_ms", std::to_string(lag_s * 1e3));
  EXPECT_LT(std::abs(none.approach_m), 0.003);  // noise-free and unfiltered: the truth within 3 mm
  EXPECT_GT(thesis.approach_m, none.approach_m);  // the unsafe side
  EXPECT_GT(lag_s, 1.0 / 30.0);
  EXPECT_LT(lag_s, 2.0 / 30.0);
}

}  // namespace
}  // namespace hrcsense
