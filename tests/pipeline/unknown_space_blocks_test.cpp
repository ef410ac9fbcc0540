// SPDX-License-Identifier: Apache-2.0
// Unknown space in blocks of 16 pixels (issue A4): the SSE2 block tests against the plain ones;
// a row wider than a block, laid out by hand, whose kinds and shadow cross block boundaries;
// and the rays skipped by the bounding spheres against measuring every ray (the pre-A4 scan).

#include "src/pipeline/unknown_space_blocks.hpp"
#include "unknown_space_row.hpp"
#include "hrcsense/unknown_space.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace hrcsense {
namespace {

using unknown_space_detail::BlockBits;
using unknown_space_detail::BlockInputs;

using test::capsule;

// The reliable bits of a background of `background` means and `ratio` valid ratios, prepared
// as the pipeline prepares them.
ReliableBackground reliable_of(const std::vector<float>& background, const std::vector<float>& ratio) {
  BackgroundModel model;
  model.mean_m = background;
  model.valid_ratio = ratio;
  return reliable_background(model, 0.95F);
}

#if defined(__SSE2__)
TEST(UnknownSpaceBlocks, Sse2BitsEqualThePlainOnes) {
  constexpr size_t kPixels = 16 * 64;
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> pick(0, 9);
  std::vector<uint16_t> raw(kPixels), envelope(kPixels);
  std::vector<uint8_t> mask(kPixels);
  std::vector<float> background(kPixels), ratio(kPixels);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < kPixels; ++i) {
    raw[i] = pick(rng) < 4 ? 0 : static_cast<uint16_t>(1000 + pick(rng));
    envelope[i] = pick(rng) < 2 ? static_cast<uint16_t>(900 + pick(rng)) : 0;
    mask[i] = pick(rng) < 3 ? 1 : 0;
    const int b = pick(rng);
    background[i] = b == 0 ? 0.0F : b == 1 ? nan : b == 2 ? -0.0F : 2.0F;
    const int r = pick(rng);
    ratio[i] = r == 0 ? nan : r < 4 ? 0.94F : r == 4 ? 0.95F : 1.0F;
  }
  const ReliableBackground reliable = reliable_of(background, ratio);
  BlockInputs full{raw.data(), mask.data(), envelope.data(), background.data(), reliable.bits.data()};
  BlockInputs bare{raw.data(), nullptr, nullptr, background.data(), nullptr};
  for (const BlockInputs& in : {full, bare}) {
    for (size_t first = 0; first < kPixels; first += 16) {
      const BlockBits plain = unknown_space_detail::block_bits_plain(in, first, 16);
      const BlockBits sse2 = unknown_space_detail::block_bits_sse2(in, first);
      EXPECT_EQ(plain.no_depth, sse2.no_depth) << first;
      EXPECT_EQ(plain.envelope, sse2.envelope) << first;
      EXPECT_EQ(plain.foreground, sse2.foreground) << first;
      EXPECT_EQ(plain.reliable, sse2.reliable) << first;
    }
  }
}
#endif

// The reliable bits are the rule written out per pixel: known (mean > 0) and valid in at least
// 0.95 of the learning frames; NaN is neither. Read 16 at a time from any pixel, they are the
// same bits, the last pixels included (the padding).
TEST(UnknownSpaceBlocks, ReliableBitsFollowTheRuleFromAnyPixel) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> mean = {2.0F, 0.0F, nan, -0.0F, 2.0F, 2.0F, 2.0F, 1.0F, 3.0F, 2.0F, 2.0F};
  const std::vector<float> ratio = {1.0F, 1.0F, 1.0F, 1.0F, 0.95F, 0.9499F, nan, 0.96F, 1.0F, 0.0F, 1.0F};
  const std::vector<bool> expected = {true, false, false, false, true, false, false, true, true, false, true};
  const ReliableBackground reliable = reliable_of(mean, ratio);
  ASSERT_EQ(reliable.pixels, mean.size());
  for (size_t i = 0; i < mean.size(); ++i) {
    EXPECT_EQ(((reliable.bits[i / 8] >> (i % 8)) & 1U) != 0, expected[i]) << i;
    const uint32_t word = unknown_space_detail::reliable_bits16(reliable.bits.data(), i);
    for (size_t k = 0; k < 16; ++k) {
      const bool bit = ((word >> k) & 1U) != 0;
      EXPECT_EQ(bit, i + k < mean.size() && expected[i + k]) << i << " + " << k;
    }
  }
  // Without valid ratios nothing is reliable.
  BackgroundModel no_ratios;
  no_ratios.mean_m = mean;
  const ReliableBackground none = reliable_background(no_ratios, 0.95F);
  for (uint8_t byte : none.bits) EXPECT_EQ(byte, 0);
}

// The envelope's rectangle (RobotPixels' bounds): unknown space reads the envelope only in the
// runs and blocks that meet it. A row of 70 is scanned as a run of 64 (columns 6-69), then its
// first 6 columns; the envelope lies at 2-3. The rectangle of the whole row and that of just
// those columns give the same counts; one at columns 40-69 leaves the first block unread, so
// that 2 and 3 count as unknown, which shows the envelope there was not read.
TEST(UnknownSpaceBlocks, TheEnvelopeIsReadOnlyWhereItsRectangleMeetsTheScan) {
  test::UnknownSpaceRow<70> row(5);
  for (size_t u : {2U, 3U}) row.from[u] = 1000, row.to[u] = 1100;
  for (size_t u : {2U, 3U, 30U, 40U, 69U}) row.depth.pixels[u] = 0;
  const auto run = [&](int u0, int u1) {
    RobotPixels envelope{row.from.data(), row.to.data(), u0, 0, u1, 1};
    return unknown_space(row.depth, row.in, row.background, row.mask, &envelope, Pose::Identity(), row.robot, 0.0F,
                         row.no_depth_frames);
  };
  const UnknownSpace whole = run(0, 70), tight = run(2, 4), elsewhere = run(40, 70);
  EXPECT_EQ(whole.no_depth_pixels, 3U);  // 30, 40 and 69: 2 and 3 are the envelope
  EXPECT_EQ(tight.no_depth_pixels, whole.no_depth_pixels);
  EXPECT_EQ(tight.distance_m, whole.distance_m);
  EXPECT_EQ(elsewhere.no_depth_pixels, 5U);
}

// A span of blocks is quiet exactly when none of its blocks has a bit set, in both variants;
// one event (no depth, envelope or foreground) anywhere in 64 pixels makes it busy.
TEST(UnknownSpaceBlocks, QuietSpanHasNoBitInAnyBlock) {
  constexpr size_t kSpan = unknown_space_detail::kSpanBlocks * unknown_space_detail::kBlockPx;
  constexpr size_t kPixels = kSpan * 48;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pick(0, 199);
  std::vector<uint16_t> raw(kPixels), envelope(kPixels);
  std::vector<uint8_t> mask(kPixels);
  std::vector<float> background(kPixels, 2.0F), ratio(kPixels, 1.0F);
  for (size_t i = 0; i < kPixels; ++i) {  // ~1 % each: about half the spans see an event
    raw[i] = pick(rng) == 0 ? 0 : static_cast<uint16_t>(1000 + pick(rng));
    envelope[i] = pick(rng) == 0 ? static_cast<uint16_t>(900 + pick(rng)) : 0;
    mask[i] = pick(rng) == 0 ? 1 : 0;
  }
  const ReliableBackground reliable = reliable_of(background, ratio);
  BlockInputs full{raw.data(), mask.data(), envelope.data(), background.data(), reliable.bits.data()};
  BlockInputs bare{raw.data(), nullptr, nullptr, background.data(), nullptr};
  int quiet = 0, busy = 0;
  for (const BlockInputs& in : {full, bare}) {
    for (size_t first = 0; first < kPixels; first += kSpan) {
      bool expected = true;
      for (size_t block = first; block < first + kSpan; block += 16) {
        const BlockBits b = unknown_space_detail::block_bits_plain(in, block, 16);
        expected = expected && (b.no_depth | b.envelope | b.foreground) == 0;
      }
      (expected ? quiet : busy)++;
      EXPECT_EQ(unknown_space_detail::span_quiet_plain(in, first), expected) << first;
#if defined(__SSE2__)
      EXPECT_EQ(unknown_space_detail::span_quiet_sse2(in, first), expected) << first;
#endif
    }
  }
  EXPECT_GT(quiet, 5);
  EXPECT_GT(busy, 5);
}

// The first pixels of a row left over by whole blocks: read as the row's first whole block with
// its low bits kept, they are the plain per-pixel bits of those pixels.
TEST(UnknownSpaceBlocks, HeadOfARowEqualsThePlainBits) {
  constexpr size_t kPixels = 40;
  std::vector<uint16_t> raw(kPixels, 1500), envelope(kPixels, 0);
  std::vector<uint8_t> mask(kPixels, 0);
  std::vector<float> background(kPixels, 2.0F), ratio(kPixels, 1.0F);
  for (size_t i : {1U, 4U, 9U, 12U}) raw[i] = 0;  // 9 and 12 lie beyond a head of 8
  envelope[4] = envelope[10] = 900;
  mask[6] = mask[11] = 1;
  ratio[1] = 0.5F;
  const ReliableBackground reliable = reliable_of(background, ratio);
  const BlockInputs in{raw.data(), mask.data(), envelope.data(), background.data(), reliable.bits.data()};
  for (int count = 1; count < 16; ++count) {
    const BlockBits plain = unknown_space_detail::block_bits_plain(in, 0, count);
    const BlockBits head = unknown_space_detail::block_bits_head(in, 0, count, static_cast<int>(kPixels));
    EXPECT_EQ(plain.no_depth, head.no_depth) << count;
    EXPECT_EQ(plain.envelope, head.envelope) << count;
    EXPECT_EQ(plain.foreground, head.foreground) << count;
    EXPECT_EQ(plain.reliable, head.reliable) << count;
  }
  const BlockBits eight = unknown_space_detail::block_bits_head(in, 0, 8, static_cast<int>(kPixels));
  EXPECT_EQ(eight.no_depth, 0b00010010U);  // 1 and 4
  EXPECT_EQ(eight.envelope, 0b00010000U);
  EXPECT_EQ(eight.foreground, 0b01000000U);
  EXPECT_EQ(eight.reliable, 0U);  // 1 flickered while learning, 4 is the envelope
}

TEST(UnknownSpaceBlocks, KindsOfOneBlockByHand) {
  // Pixel 0 measured, 1 no depth over a reliable background, 2 no depth over an unknown one,
  // 3 foreground, 4 in the envelope without depth, 5 no depth over a flickering background.
  std::vector<uint16_t> raw{1500, 0, 0, 1200, 0, 0}, envelope{0, 0, 0, 0, 800, 0};
  std::vector<uint8_t> mask{0, 0, 0, 1, 0, 0};
  std::vector<float> background{2, 2, 0, 2, 2, 2}, ratio{1, 1, 1, 1, 1, 0.5F};
  const ReliableBackground reliable = reliable_of(background, ratio);
  const BlockInputs in{raw.data(), mask.data(), envelope.data(), background.data(), reliable.bits.data()};
  const auto kinds = unknown_space_detail::kinds_of(unknown_space_detail::block_bits_plain(in, 0, 6));
  EXPECT_EQ(kinds.gap, 0b000010U);
  EXPECT_EQ(kinds.never_valid, 0b100100U);
  EXPECT_EQ(kinds.hidden, 0b001000U);
  EXPECT_EQ(kinds.envelope, 0b010000U);
}

// One row of 40 pixels (unknown_space_row.hpp): blocks [24, 39] and [8, 23] and the 8 pixels
// [0, 7] left over; every gap an old one (5 frames without depth) unless a test says otherwise.
struct WideRow : test::UnknownSpaceRow<40> {
  WideRow() : UnknownSpaceRow(5) {}
};

TEST(UnknownSpaceBlocks, KindsAndShadowAcrossBlocks) {
  WideRow row;
  // The envelope at 26-27 (front at 1 m) shadows fx·B·(1/1 − 1/2) = 2.5 px, so up to 3 + 1 = 4 px
  // to its left: 22-25, across the boundary between the first two blocks. 21 is beyond it.
  for (int u : {26, 27}) row.from[u] = 1000, row.to[u] = 1100, row.depth.pixels[u] = 0;
  for (int u : {21, 22, 25}) row.depth.pixels[u] = 0;
  row.depth.pixels[35] = 1500;  // foreground at 1.5 m
  row.mask[35] = 1;
  row.depth.pixels[2] = 0;  // in the pixels left over
  row.depth.pixels[5] = 0;  // unknown background there: never valid
  row.background.mean_m[5] = 0.0F;
  row.depth.pixels[12] = 0;  // a fresh dropout
  row.no_depth_frames[12] = 1;
  const UnknownSpace u = row.run();
  EXPECT_EQ(u.robot_shadow_pixels, 2U);  // 22 and 25
  EXPECT_EQ(u.no_depth_pixels, 2U);      // 21 and 2
  EXPECT_EQ(u.hidden_pixels, 1U);        // 35
  EXPECT_EQ(u.never_valid_pixels, 1U);   // 5
  EXPECT_EQ(u.dropout_pixels, 1U);       // 12
  // The nearest is pixel 21's ray x = 0.21·z (z from 0.2 to 2 m), whose closest approach to the
  // capsule's axis (x = 0.3, z = 1) lies inside that range: |0.3 − 0.21| / √(1 + 0.21²) − 0.05.
  // Pixel 2's (0.28 / √1.0004 − 0.05 ≈ 0.23 m) and 35's (from (0.525, 0, 1.5): ≈ 0.50 m) are farther.
  EXPECT_NEAR(u.distance_m, 0.09 / std::sqrt(1.0 + 0.21 * 0.21) - 0.05, 1e-5);
}

// Rays skipped by the bounding spheres would never have given a smaller distance: an image full
// of unknown rays and an arm of several capsules give exactly the minimum over every ray.
TEST(UnknownSpaceBlocks, SkippedRaysNeverHoldTheMinimum) {
  constexpr int kWidth = 53, kHeight = 31;  // not a multiple of the block
  Intrinsics in;
  in.width = kWidth;
  in.height = kHeight;
  in.fx = in.fy = 40.0F;
  in.ppx = 26.0F;
  in.ppy = 15.0F;
  // The camera 2.4 m from the arm, looking at it; the rays end 0.5-1.2 m out, before they reach
  // it, so the smallest distance is a ray's far end near some capsule and never 0.
  const Eigen::Vector3d camera(2.0, 0.3, 1.4), forward = (Eigen::Vector3d(0.3, 0, 0.3) - camera).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  Pose T_base_camera = Pose::Identity();
  T_base_camera.linear() << right, forward.cross(right), forward;  // columns: camera x, y, z in the base frame
  T_base_camera.translation() = camera;
  RobotModel robot;
  robot.capsules.push_back(capsule({0, 0, 0}, {0, 0, 0.4F}, 0.08F));
  robot.capsules.push_back(capsule({0, 0, 0.4F}, {0.4F, 0.1F, 0.5F}, 0.06F));
  robot.capsules.push_back(capsule({0.4F, 0.1F, 0.5F}, {0.7F, -0.2F, 0.3F}, 0.05F));
  robot.capsules.push_back(capsule({0.7F, -0.2F, 0.3F}, {0.7F, -0.2F, 0.3F}, 0.04F));  // a sphere
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> depth_m(0.5F, 1.2F);
  for (int trial = 0; trial < 5; ++trial) {
    DepthImage depth;
    depth.resize(kWidth, kHeight);
    BackgroundModel background;
    background.mean_m.resize(depth.pixels.size());
    background.valid_ratio.assign(depth.pixels.size(), 1.0F);
    float expected_m = std::numeric_limits<float>::infinity();
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const size_t i = static_cast<size_t>(v) * kWidth + static_cast<size_t>(u);
        background.mean_m[i] = depth_m(rng);
        depth.pixels[i] = 0;  // every pixel without depth: unknown from 0.2 m to the background
        const RaySegment s = ray_segment(in, T_base_camera, u, v, 0.2F, background.mean_m[i]);
        expected_m = std::min(expected_m, segment_capsule_distance(s.from_base, s.to_base, robot));
      }
    }
    const UnknownSpace got = unknown_space(depth, in, background, {}, nullptr, T_base_camera, robot, 0.0F, {});
    ASSERT_TRUE(std::isfinite(expected_m) && expected_m > 0.0F) << expected_m << " in trial " << trial;
    EXPECT_EQ(got.no_depth_pixels, depth.pixels.size());
    EXPECT_EQ(got.distance_m, expected_m) << "trial " << trial;
    robot.capsules[1].b.y() += 0.15F;  // swing the arm sideways between trials
  }
}

}  // namespace
}  // namespace hrcsense
