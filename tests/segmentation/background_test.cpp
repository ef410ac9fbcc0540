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

size_t at(int u, int v) { return static_cast<size_t>(v) * kWidth + u; }

// Four frames, hand-computed: pixel (5, 7) reads 2000, 2002, 0, 2004 → mean 2.002 m over its
// 3 valid samples, spread sqrt((2² + 0² + 2²) / 3) = 1.63299 mm, valid ratio 3/4.
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
  EXPECT_NEAR(model.mean_m[at(5, 7)], 2.002, 1e-6);
  EXPECT_NEAR(model.spread_m[at(5, 7)], 1.63299e-3, 1e-7);
  EXPECT_FLOAT_EQ(model.valid_ratio[at(5, 7)], 0.75F);
  EXPECT_EQ(model.mean_m[at(9, 9)], 0.0F);
  EXPECT_EQ(model.valid_ratio[at(9, 9)], 0.0F);
  EXPECT_NEAR(model.mean_m[at(40, 30)], 2.0, 1e-6);
  EXPECT_EQ(model.spread_m[at(40, 30)], 0.0F);
  EXPECT_EQ(model.valid_ratio[at(40, 30)], 1.0F);
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
        if ((u + v + f) % 7 == 0) batch.back().depth.pixels[at(u, v)] = 0;
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
        const uint16_t raw = frame.depth.pixels[at(u, v)];
        if (raw != 0) sum += raw * 1e-3, ++valid;
      }
      const double mean = sum / valid;
      double squares = 0.0;
      for (const Frame& frame : batch) {
        const uint16_t raw = frame.depth.pixels[at(u, v)];
        if (raw != 0) squares += (raw * 1e-3 - mean) * (raw * 1e-3 - mean);
      }
      ASSERT_NEAR(model.mean_m[at(u, v)], mean, 1e-6) << u << "," << v;
      ASSERT_NEAR(model.spread_m[at(u, v)], std::sqrt(squares / valid), 1e-6) << u << "," << v;
      ASSERT_NEAR(model.valid_ratio[at(u, v)], static_cast<double>(valid) / frames, 1e-6) << u << "," << v;
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
      for (int u = u0; u < u0 + 10; ++u) covered[at(u, v)] = 1;
    }
    const Status status = learner.add(frame);
    EXPECT_EQ(status, f < 19 ? Status::learning : Status::restarted) << "frame " << f;
  }
  EXPECT_FALSE(learner.ready());
  EXPECT_EQ(learner.frames_seen(), 0);
  // A pixel covered k of 20 times has spread sqrt(p(1 - p)) · 1 m ≥ 0.218 m (p = k/20 ≥ 0.05),
  // far above the limit, while the ±2 mm wall never moves: exactly the covered pixels move.
  size_t moving = 0;
  for (const uint8_t c : covered) moving += c;
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
  EXPECT_NEAR(learner.model().mean_m[at(3, 3)], 2.0, 0.0021);
}

// Pixels valid in only 20..80 % of a batch had something come and go: they count as moving,
// while pixels valid in 90 % of the frames do not.
TEST(BackgroundLearner, FlickeringValidityCountsAsMotion) {
  BackgroundLearner flicker;
  flicker.params.frames = 10;
  BackgroundLearner dropouts;
  dropouts.params.frames = 10;
  Status flicker_status = Status::learning;
  Status dropout_status = Status::learning;
  for (int f = 0; f < 10; ++f) {
    Frame half = wall_frame(f);
    if (f % 2 == 0) fill_rect(half, 10, 10, 3, 3, 0);  // 9 px valid half of the time
    flicker_status = flicker.add(half);
    Frame rare = wall_frame(f);
    if (f == 4) fill_rect(rare, 10, 10, 20, 20, 0);  // 400 px valid 90 % of the time
    dropout_status = dropouts.add(rare);
  }
  // 9 of 3072 valid pixels = 0.29 % > 0.2 %.
  EXPECT_EQ(flicker_status, Status::restarted);
  EXPECT_NE(flicker.message().find("0.3 %"), std::string::npos) << flicker.message();
  EXPECT_EQ(dropout_status, Status::ready);
  EXPECT_NEAR(dropouts.model().valid_ratio[at(15, 15)], 0.9, 1e-6);
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
      EXPECT_NEAR(learner.model().spread_m[at(3, 3)], 0.05, 1e-6);
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
