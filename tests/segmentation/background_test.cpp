// SPDX-License-Identifier: Apache-2.0
// Background learning on hand-built frames: statistics, zeros, motion restarts, size changes.

#include "synthetic_frames.hpp"

#include "hrcsense/segmentation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using namespace hrcsense::testing;
using Status = BackgroundLearner::Status;

size_t pixel_index(int u, int v) { return static_cast<size_t>(v) * kWidth + u; }

// Four frames, hand-computed: pixel (5, 7) reads 2000, 2002, 0, 2004 → mean 2.002 m over its
// 3 valid samples, spread sqrt((2² + 0² + 2²) / 3) = 1.63299 mm, valid ratio 3/4. Pixel (9, 9)
// is never valid: it takes the nearest reliable mean around it, the wall's 2.000 m.
TEST(BackgroundLearner, HandComputedMeanSpreadAndValidRatio) {
  BackgroundLearner learner;
  learner.params.frames = 4;
  const uint16_t samples[4] = {2000, 2002, 0, 2004};
  for (int f = 0; f < 4; ++f) {
    Frame frame = wall_frame(f);
    fill_rect(frame, 0, 0, kWidth, kHeight, kWallRaw);  // noise-free wall
    fill_rect(frame, 5, 7, 1, 1, samples[f]);
    fill_rect(frame, 9, 9, 1, 1, 0);                     // never valid
    const Status status = learner.add(frame);
    EXPECT_EQ(status, f < 3 ? Status::learning : Status::ready) << "frame " << f;
  }
  ASSERT_TRUE(learner.ready());
  const BackgroundModel& model = learner.model();
  EXPECT_EQ(model.width, kWidth);
  EXPECT_EQ(model.height, kHeight);
  EXPECT_NEAR(model.mean_m[pixel_index(5, 7)], 2.002, 1e-6);
  EXPECT_NEAR(model.spread_m[pixel_index(5, 7)], 1.63299e-3, 1e-7);
  EXPECT_FLOAT_EQ(model.valid_ratio[pixel_index(5, 7)], 0.75F);
  EXPECT_EQ(model.mean_m[pixel_index(9, 9)], 2.0F);
  EXPECT_EQ(model.spread_m[pixel_index(9, 9)], 0.0F);
  EXPECT_EQ(model.valid_ratio[pixel_index(9, 9)], 0.0F);
  EXPECT_NEAR(model.mean_m[pixel_index(40, 30)], 2.0, 1e-6);
  EXPECT_EQ(model.spread_m[pixel_index(40, 30)], 0.0F);
  EXPECT_EQ(model.valid_ratio[pixel_index(40, 30)], 1.0F);
  EXPECT_TRUE(learner.message().empty());
}

// 100 noisy frames with random dropouts: every pixel's statistics equal a two-pass computation
// over the valid samples.
TEST(BackgroundLearner, NoisyWallMatchesTwoPassStatistics) {
  BackgroundLearner learner;
  const int frames = learner.params.frames;
  std::vector<Frame> batch;
  for (int f = 0; f < frames; ++f) {
    batch.push_back(wall_frame(f));
    // Drop a pixel now and then (every 7th frame at u + v ≡ f mod 7): ratio 85 or 86 %.
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        if ((u + v + f) % 7 == 0) batch.back().depth.pixels[pixel_index(u, v)] = 0;
      }
    }
    EXPECT_EQ(learner.add(batch.back()), f + 1 < frames ? Status::learning : Status::ready);
  }
  const BackgroundModel& model = learner.model();
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      double sum = 0.0;
      int valid = 0;
      for (const Frame& frame : batch) {
        const uint16_t raw = frame.depth.pixels[pixel_index(u, v)];
        if (raw != 0) sum += raw * 1e-3, ++valid;
      }
      const double mean = sum / valid;
      double squares = 0.0;
      for (const Frame& frame : batch) {
        const uint16_t raw = frame.depth.pixels[pixel_index(u, v)];
        if (raw != 0) squares += (raw * 1e-3 - mean) * (raw * 1e-3 - mean);
      }
      ASSERT_NEAR(model.mean_m[pixel_index(u, v)], mean, 1e-6) << u << "," << v;
      ASSERT_NEAR(model.spread_m[pixel_index(u, v)], std::sqrt(squares / valid), 1e-6) << u << "," << v;
      ASSERT_NEAR(model.valid_ratio[pixel_index(u, v)], static_cast<double>(valid) / frames, 1e-6) << u << "," << v;
    }
  }
}

// A 10x10 box at 1 m crosses the image during the first batch: that batch is discarded with a
// message giving the share of moving pixels, and the next, still batch is learnt.
TEST(BackgroundLearner, MovingBlobRestartsThenStillBatchIsReady) {
  BackgroundLearner learner;
  learner.params.frames = 20;
  std::vector<uint8_t> covered(static_cast<size_t>(kWidth) * kHeight, 0);
  for (int f = 0; f < 20; ++f) {
    Frame frame = wall_frame(f);
    const int u0 = 2 * f;  // 2 px per frame, left to right
    fill_rect(frame, u0, 20, 10, 10, 1000);
    for (int v = 20; v < 30; ++v) {
      for (int u = u0; u < u0 + 10; ++u) covered[pixel_index(u, v)] = 1;
    }
    const Status status = learner.add(frame);
    EXPECT_EQ(status, f < 19 ? Status::learning : Status::restarted) << "frame " << f;
  }
  EXPECT_FALSE(learner.ready());
  EXPECT_EQ(learner.frames_seen(), 0);
  // A pixel covered k of 20 times has spread sqrt(p(1 - p)) · 1 m ≥ 0.218 m (p = k/20 ≥ 0.05),
  // far above the limit, while the ±2 mm wall never moves: exactly the covered pixels move, and
  // those whose 3x3 square (clipped to the image) is covered count.
  size_t moving = 0;
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      bool all = true;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const int nu = u + du, nv = v + dv;
          if (nu >= 0 && nu < kWidth && nv >= 0 && nv < kHeight) all = all && covered[pixel_index(nu, nv)] != 0;
        }
      }
      moving += all ? 1 : 0;
    }
  }
  EXPECT_EQ(moving, 47U * 8U);  // u 0..46 (the image's left edge clips), v 21..28
  char expected[64];
  std::snprintf(expected, sizeof expected, "%.1f %% of pixels changed during the last 20 frames",
                100.0 * moving / (kWidth * kHeight));
  EXPECT_NE(learner.message().find(expected), std::string::npos) << learner.message();
  EXPECT_NE(learner.message().find("limit 0.2 %"), std::string::npos) << learner.message();
  EXPECT_NE(learner.message().find("moving"), std::string::npos) << learner.message();

  for (int f = 20; f < 40; ++f) {
    EXPECT_EQ(learner.add(wall_frame(f)), f < 39 ? Status::learning : Status::ready) << "frame " << f;
  }
  ASSERT_TRUE(learner.ready());
  for (const float mean : learner.model().mean_m) ASSERT_NEAR(mean, 2.0, 0.0021);

  // Frames after ready are ignored.
  Frame late = wall_frame(40);
  fill_rect(late, 0, 0, kWidth, kHeight, 500);
  EXPECT_EQ(learner.add(late), Status::ready);
  EXPECT_NEAR(learner.model().mean_m[pixel_index(3, 3)], 2.0, 0.0021);
}

// Pixels whose validity flickers are unreliable, not motion: a 20x20 patch valid in 4 of 10
// frames does not restart learning (it is 13 % of the image), while a 20x20 patch valid in 9 of
// 10 frames stays reliable with its own statistics.
TEST(BackgroundLearner, FlickeringValidityIsNotMotion) {
  BackgroundLearner learner;
  learner.params.frames = 10;
  Status status = Status::learning;
  for (int f = 0; f < 10; ++f) {
    Frame frame = wall_frame(f);
    if (f % 3 != 0) fill_rect(frame, 4, 4, 20, 20, 0);  // valid in frames 0, 3, 6, 9
    if (f == 4) fill_rect(frame, 40, 20, 20, 20, 0);    // valid 90 % of the time
    status = learner.add(frame);
  }
  ASSERT_EQ(status, Status::ready) << learner.message();
  const BackgroundModel& model = learner.model();
  EXPECT_NEAR(model.valid_ratio[pixel_index(10, 10)], 0.4, 1e-6);
  EXPECT_NEAR(model.valid_ratio[pixel_index(50, 30)], 0.9, 1e-6);
  // Pixel (50, 30) keeps its own mean over 9 samples, 2.000 m ± 2 mm.
  double sum = 0.0;
  for (int f = 0; f < 10; ++f) sum += f == 4 ? 0.0 : kWallRaw + wall_noise(50, 30, f);
  EXPECT_NEAR(model.mean_m[pixel_index(50, 30)], sum / 9.0 * 1e-3, 1e-6);
}

// An unreliable pixel (valid in fewer than half of the frames) learns nothing from its own
// samples: it takes the background of the reliable pixels closest to it in the image, the nearer
// one when two are equally close, and stays unknown (0) beyond fill_radius_px (3). Band A,
// columns 20..29, lies between a box at 1.500 m (columns 16..19) and the wall at 2.000 m
// (from column 30) and read 1.000 m once (a person passing): columns 20..22 take the box,
// 27..29 the wall, 23..26 are more than 3 px from both. Band B, column 40 alone, lies between
// the wall (column 39) and a box at 1.200 m (columns 41..44): it takes the box.
TEST(BackgroundLearner, UnreliablePixelsTakeClosestReliableBackground) {
  BackgroundLearner learner;
  learner.params.frames = 4;
  learner.params.fill_radius_px = 3;
  for (int f = 0; f < 4; ++f) {
    Frame frame = wall_frame(f);
    fill_rect(frame, 0, 0, kWidth, kHeight, kWallRaw);  // noise-free: exact means
    fill_rect(frame, 16, 0, 4, kHeight, 1500);
    fill_rect(frame, 20, 0, 10, kHeight, f == 1 ? 1000 : 0);
    fill_rect(frame, 40, 0, 1, kHeight, 0);
    fill_rect(frame, 41, 0, 4, kHeight, 1200);
    ASSERT_NE(learner.add(frame), Status::restarted) << learner.message();
  }
  ASSERT_TRUE(learner.ready());
  const BackgroundModel& model = learner.model();
  const float expected[] = {1.5F, 1.5F, 1.5F, 0.0F, 0.0F, 0.0F, 0.0F, 2.0F, 2.0F, 2.0F};
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 20; u < 30; ++u) {
      EXPECT_FLOAT_EQ(model.mean_m[pixel_index(u, v)], expected[u - 20]) << u << "," << v;
      EXPECT_EQ(model.valid_ratio[pixel_index(u, v)], 0.25F) << u << "," << v;
    }
    EXPECT_FLOAT_EQ(model.mean_m[pixel_index(40, v)], 1.2F) << v;
    EXPECT_FLOAT_EQ(model.mean_m[pixel_index(39, v)], 2.0F) << v;
  }
}

// A pixel never valid in a batch of unseen_min_frames (10) frames or more cannot be measured
// there (a shiny patch): it stays unknown, so that anything measured there later counts. After
// 9 frames "never valid" is weak evidence, and it is filled like a flickering pixel.
TEST(BackgroundLearner, NeverValidInALongBatchStaysUnknown) {
  for (const int frames : {9, 10}) {
    BackgroundLearner learner;
    learner.params.frames = frames;
    for (int f = 0; f < frames; ++f) {
      Frame frame = wall_frame(f);
      fill_rect(frame, 0, 0, kWidth, kHeight, kWallRaw);
      fill_rect(frame, 30, 20, 4, 4, 0);
      learner.add(frame);
    }
    ASSERT_TRUE(learner.ready()) << frames;
    EXPECT_FLOAT_EQ(learner.model().mean_m[pixel_index(31, 21)], frames >= 10 ? 0.0F : 2.0F) << frames;
  }
}

// Motion must cover an area: a 2 px wide line that alternates between 2 m and 1 m (a flickering
// depth edge: 96 px, 3 % of the image) is not motion with the default motion_min_width_px = 3,
// but is with 1; a 6x6 block alternating the same way is (its 4x4 core, 0.52 % > 0.2 %).
TEST(BackgroundLearner, MotionMustBeWiderThanAnEdge) {
  struct Case {
    int motion_min_width_px;
    int v0, w, h;
    Status expected;
  };
  for (const Case& c : {Case{3, 0, 2, kHeight, Status::ready}, Case{1, 0, 2, kHeight, Status::restarted},
                        Case{3, 10, 6, 6, Status::restarted}}) {
    BackgroundLearner learner;
    learner.params.frames = 4;
    learner.params.motion_min_width_px = c.motion_min_width_px;
    Status status = Status::learning;
    for (int f = 0; f < 4; ++f) {
      Frame frame = wall_frame(f);
      fill_rect(frame, 20, c.v0, c.w, c.h, f % 2 == 0 ? 2000 : 1000);
      status = learner.add(frame);
    }
    EXPECT_EQ(status, c.expected) << c.motion_min_width_px << " " << c.w << "x" << c.h << ": " << learner.message();
  }
}

// Without a stereo baseline the noise floor is learnt: every pixel reads 2000, 2000, 2006 mm →
// mean 2.002 m, spread sqrt((2² + 2² + 4²) / 3) = 2.8284 mm. Three Gaussian samples have a median
// spread of σ · sqrt(median χ²₂ / 3) = σ · 0.68427 (Wilson–Hilferty: 2 · (1 − 1/9)³ = 1.40466), so
// σ / z² = 2.8284e-3 / (2.002² · 0.68427) = 1.03131e-3 per metre, and every spread is raised to
// σ(2.002 m) = 4.1335 mm. With a baseline the stereo model is used and spreads stay measured.
TEST(BackgroundLearner, NoiseFloorIsLearntWithoutBaseline) {
  for (const float baseline_mm : {0.0F, kBaselineMm}) {
    BackgroundLearner learner;
    learner.params.frames = 3;
    for (int f = 0; f < 3; ++f) {
      Frame frame = wall_frame(f);
      frame.stereo_baseline_mm = baseline_mm;
      fill_rect(frame, 0, 0, kWidth, kHeight, f == 2 ? 2006 : 2000);
      ASSERT_NE(learner.add(frame), Status::restarted) << learner.message();
    }
    const BackgroundModel& model = learner.model();
    if (baseline_mm == 0.0F) {
      EXPECT_NEAR(learner.noise_per_z2(), 1.03131e-3, 2e-8);
      EXPECT_NEAR(model.spread_m[pixel_index(30, 20)], 4.1335e-3, 2e-7);
    } else {
      // 0.08 px / (200 px · 0.05 m) = 8e-3 per metre.
      EXPECT_NEAR(learner.noise_per_z2(), 8e-3, 1e-9);
      EXPECT_NEAR(model.spread_m[pixel_index(30, 20)], 2.8284e-3, 1e-7);
    }
    EXPECT_NEAR(model.mean_m[pixel_index(30, 20)], 2.002, 1e-6);
  }
}

// A batch in which most of the view moves must not pass as noise: the median spread would be
// the motion's, so the learnt noise is capped at max_noise_per_z2 (0.01 / m) and the motion
// shows. The left 40 columns alternate between 1 m and 3 m (62 % of the image).
TEST(BackgroundLearner, LearntNoiseIsCappedSoThatLargeMotionRestarts) {
  BackgroundLearner learner;
  learner.params.frames = 3;
  Status status = Status::learning;
  for (int f = 0; f < 3; ++f) {
    Frame frame = wall_frame(f);
    frame.stereo_baseline_mm = 0.0F;
    fill_rect(frame, 0, 0, 40, kHeight, f == 1 ? 1000 : 3000);
    status = learner.add(frame);
  }
  EXPECT_EQ(status, Status::restarted);
  EXPECT_FLOAT_EQ(static_cast<float>(learner.noise_per_z2()), 0.01F);
  // Without the cap the median (spread 0.943 m at mean 2.333 m: 0.254 / m after the 3-sample
  // correction) would have called the 1 m → 3 m jumps noise.
  learner.params.max_noise_per_z2 = 1.0F;
  for (int f = 0; f < 3; ++f) {
    Frame frame = wall_frame(f);
    frame.stereo_baseline_mm = 0.0F;
    fill_rect(frame, 0, 0, 40, kHeight, f == 1 ? 1000 : 3000);
    status = learner.add(frame);
  }
  EXPECT_EQ(status, Status::ready);
}

// The motion limit is max(6 σ_model(mean), 3 cm): σ_model(2 m) = 2² · 0.08 / (200 · 0.05) = 32 mm
// with the baseline, so a ±50 mm alternation (spread 50 mm) is noise; without a baseline only
// the 3 cm floor is left and the same pixels move.
TEST(BackgroundLearner, MotionLimitUsesNoiseModelOnlyWithBaseline) {
  for (const float baseline_mm : {kBaselineMm, 0.0F}) {
    BackgroundLearner learner;
    learner.params.frames = 10;
    Status status = Status::learning;
    for (int f = 0; f < 10; ++f) {
      Frame frame = wall_frame(f);
      frame.stereo_baseline_mm = baseline_mm;
      fill_rect(frame, 0, 0, 8, 8, static_cast<uint16_t>(f % 2 == 0 ? 1950 : 2050));
      status = learner.add(frame);
    }
    EXPECT_EQ(status, baseline_mm > 0.0F ? Status::ready : Status::restarted) << baseline_mm;
    if (baseline_mm > 0.0F) {
      EXPECT_NEAR(learner.model().spread_m[pixel_index(3, 3)], 0.05, 1e-6);
    }
  }
}

// A new image size in the middle of a batch restarts learning; the new frame starts the batch.
TEST(BackgroundLearner, SizeChangeRestarts) {
  BackgroundLearner learner;
  learner.params.frames = 3;
  EXPECT_EQ(learner.add(wall_frame(0)), Status::learning);
  EXPECT_EQ(learner.add(wall_frame(1)), Status::learning);
  EXPECT_EQ(learner.add(wall_frame(2, 32, 24)), Status::restarted);
  EXPECT_NE(learner.message().find("64x48 to 32x24"), std::string::npos) << learner.message();
  EXPECT_EQ(learner.frames_seen(), 1);
  EXPECT_EQ(learner.add(wall_frame(3, 32, 24)), Status::learning);
  EXPECT_EQ(learner.add(wall_frame(4, 32, 24)), Status::ready);
  EXPECT_EQ(learner.model().width, 32);
  EXPECT_EQ(learner.model().height, 24);
  EXPECT_EQ(learner.model().mean_m.size(), 32U * 24U);
}

// After the first frame of a size, further batches reuse the same buffers.
TEST(BackgroundLearner, BatchesReuseBuffers) {
  BackgroundLearner learner;
  learner.params.frames = 2;
  Frame moving = wall_frame(0);
  learner.add(moving);
  const float* mean_before = learner.model().mean_m.data();
  fill_rect(moving, 0, 0, 32, 48, 1000);  // half the image jumps by 1 m
  EXPECT_EQ(learner.add(moving), Status::restarted);
  EXPECT_EQ(learner.add(wall_frame(2)), Status::learning);
  EXPECT_EQ(learner.add(wall_frame(3)), Status::ready);
  EXPECT_EQ(learner.model().mean_m.data(), mean_before);
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// background.motion_max_distance_m. A 40x30 view (fx = fy = 400, centre 19.5, 14.5, camera
// frame = base frame) of a wall at 3 m with a 10x10 block at u, v 0..9 that jumps between
// 2.0 and 2.8 m every frame: mean 2.4 m, spread 0.4 m, far above the noise of the still wall,
// so 100 of 1200 pixels move (8 %, far above max_moving_share 0.2 %). The block's pixel (5, 5)
// lies at (−14.5/400·2.4, −9.5/400·2.4, 2.4) = (−0.087, −0.057, 2.4).
Frame jumping_block_frame(int index) {
  Frame frame;
  frame.index = index;
  frame.intrinsics.width = 40;
  frame.intrinsics.height = 30;
  frame.intrinsics.fx = frame.intrinsics.fy = 400.0F;
  frame.intrinsics.ppx = 19.5F;
  frame.intrinsics.ppy = 14.5F;
  frame.depth.resize(40, 30);
  for (int v = 0; v < 30; ++v) {
    for (int u = 0; u < 40; ++u) {
      const bool block = u < 10 && v < 10;
      frame.depth.pixels[static_cast<size_t>(v) * 40 + u] = block ? (index % 2 == 0 ? 2000 : 2800) : 3000;
    }
  }
  return frame;
}

RobotModel robot_point_at(const Eigen::Vector3f& p) {
  RobotModel robot;
  robot.capsules.push_back(Capsule{p, p, 0.0F, 0});
  return robot;
}

Status learn_batch(BackgroundLearner& learner, const MotionRegion* region) {
  Status status = Status::learning;
  for (int i = 0; i < learner.params.frames; ++i) status = learner.add(jumping_block_frame(i), region);
  return status;
}

TEST(BackgroundMotionRegion, MotionFarFromTheRobotDoesNotRestartLearning) {
  BackgroundLearner learner;
  learner.params.frames = 4;
  // The robot point 0.5 m behind the camera: the block is sqrt(0.087² + 0.057² + 2.9²) ≈ 2.90 m
  // away, beyond the default 2 m.
  const RobotModel robot = robot_point_at({0.0F, 0.0F, -0.5F});
  const MotionRegion region{Pose::Identity(), &robot, AlignedBox{}};
  ASSERT_EQ(learn_batch(learner, &region), Status::ready) << learner.message();
  EXPECT_EQ(learner.unsettled_pixels(), 100U);
  // The block's background is unknown (anything there later is foreground in the workspace);
  // the wall's is the wall.
  const BackgroundModel& model = learner.model();
  EXPECT_EQ(model.mean_m[5 * 40 + 5], 0.0F);
  EXPECT_NEAR(model.mean_m[20 * 40 + 30], 3.0F, 1e-6F);
}

TEST(BackgroundMotionRegion, MotionNearTheRobotStillRestarts) {
  // The robot point 1 m in front of the camera: the block is ≈ 1.40 m from it.
  const RobotModel robot = robot_point_at({0.0F, 0.0F, 1.0F});
  const MotionRegion region{Pose::Identity(), &robot, AlignedBox{}};
  BackgroundLearner near;
  near.params.frames = 4;
  EXPECT_EQ(learn_batch(near, &region), Status::restarted);
  // Judged by its mean (2.4 m, 1.40 m from the robot) the block would be out of a 1.3 m reach;
  // its nearest sample (2.0 m: (−0.0725, −0.0475, 2.0), 1.004 m from the robot) is inside it.
  BackgroundLearner mean_outside;
  mean_outside.params.frames = 4;
  mean_outside.params.motion_max_distance_m = 1.3F;
  EXPECT_EQ(learn_batch(mean_outside, &region), Status::restarted);
  // A reach of 0.9 m puts both out of it.
  BackgroundLearner short_reach;
  short_reach.params.frames = 4;
  short_reach.params.motion_max_distance_m = 0.9F;
  EXPECT_EQ(learn_batch(short_reach, &region), Status::ready);
  // Without a robot (no state, no region) motion counts everywhere, as before.
  BackgroundLearner everywhere;
  everywhere.params.frames = 4;
  EXPECT_EQ(learn_batch(everywhere, nullptr), Status::restarted);
  const RobotModel no_capsules;
  const MotionRegion empty{Pose::Identity(), &no_capsules, AlignedBox{}};
  BackgroundLearner empty_robot;
  empty_robot.params.frames = 4;
  EXPECT_EQ(learn_batch(empty_robot, &empty), Status::restarted);
}

TEST(BackgroundMotionRegion, MotionOutsideTheWorkspaceDoesNotCount) {
  // Near the robot, but the workspace ends at z = 1.9 m in front of the camera: the block (its
  // mean 2.4 m, its nearest sample 2.0 m) is outside it.
  const RobotModel robot = robot_point_at({0.0F, 0.0F, 1.0F});
  AlignedBox workspace;
  workspace.max.z() = 1.9F;
  const MotionRegion region{Pose::Identity(), &robot, workspace};
  BackgroundLearner learner;
  learner.params.frames = 4;
  EXPECT_EQ(learn_batch(learner, &region), Status::ready);
  EXPECT_EQ(learner.unsettled_pixels(), 100U);
}

}  // namespace
}  // namespace hrcsense
