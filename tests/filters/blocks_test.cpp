// SPDX-License-Identifier: Apache-2.0
// Hand-worked tests of the stateless blocks: threshold, depth↔disparity, decimation, hole filling.
#include "hrcsense/filters.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace hrcsense {
namespace {

DepthImage image(int w, int h, std::vector<uint16_t> pixels) {
  DepthImage d;
  d.width = w;
  d.height = h;
  d.pixels = std::move(pixels);
  return d;
}

TEST(Threshold, BoundariesAreComparedInFloat32) {
  DepthImage d = image(8, 1, {0, 149, 150, 1499, 1500, 3999, 4000, 4001});
  apply_threshold(ThresholdParams{0.15F, 1.5F}, d);
  // 150 · 0.001f >= 0.15f keeps 150; 1500 · 0.001f = 1.50000007 > 1.5f drops 1500 (spec §3, §11).
  EXPECT_EQ(d.pixels, (std::vector<uint16_t>{0, 0, 150, 1499, 0, 0, 0, 0}));
  DepthImage e = image(4, 1, {0, 3999, 4000, 4001});
  apply_threshold(ThresholdParams{0.0F, 4.0F}, e);
  EXPECT_EQ(e.pixels, (std::vector<uint16_t>{0, 3999, 4000, 0}));  // 4000 · 0.001f <= 4.0f
}

TEST(Disparity, FactorAndRoundTripOfEveryValue) {
  const float f = disparity_factor(50.0F, 418.26F, 0.001F);
  EXPECT_NEAR(f, 0.05 * 418.26 * 32 / 0.001, 0.5);  // 669216 in 1/32 px · mm
  DepthImage d = image(256, 256, {});
  d.pixels.resize(65536);
  for (size_t i = 0; i < d.pixels.size(); ++i) d.pixels[i] = static_cast<uint16_t>(i);
  DisparityImage disparity;
  depth_to_disparity(d, f, disparity);
  EXPECT_EQ(disparity.pixels[0], 0.0F);
  EXPECT_EQ(disparity.pixels[1000], f / 1000.0F);
  DepthImage back;
  disparity_to_depth(disparity, f, back);
  EXPECT_EQ(back.pixels, d.pixels);  // spec §2: exact for every uint16
}

TEST(Disparity, NonNormalValuesGiveZero) {
  DisparityImage disparity;
  disparity.resize(4, 1);
  disparity.pixels = {0.0F, -0.0F, 1e-40F, 100.0F};
  DepthImage out;
  disparity_to_depth(disparity, 1000.0F, out);
  EXPECT_EQ(out.pixels, (std::vector<uint16_t>{0, 0, 0, 10}));  // 1000/100 + 0.5 → 10
}

TEST(Decimation, LowerMedianOfNonZeroForTwoAndPaddingToFour) {
  const DepthImage in = image(4, 4, {10, 0, 0, 0,   //
                                     30, 20, 0, 0,  //
                                     7, 9, 4, 3,    //
                                     0, 0, 2, 1});
  Intrinsics intr;
  intr.width = 4;
  intr.height = 4;
  intr.fx = 400.0F;
  intr.fy = 401.0F;
  intr.ppx = 3.0F;
  intr.ppy = 1.0F;
  DepthImage out;
  Intrinsics out_intr;
  decimate(DecimationParams{2}, in, intr, out, out_intr);
  // real 2x2, padded to 4x4; blocks: {10,30,20} → 20, {} → 0, {7,9} → 7 (lower), {4,3,2,1} → 2.
  ASSERT_EQ(out.width, 4);
  ASSERT_EQ(out.height, 4);
  EXPECT_EQ(out.pixels, (std::vector<uint16_t>{20, 0, 0, 0, 7, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(out_intr.width, 4);
  EXPECT_EQ(out_intr.fx, 200.0F);
  EXPECT_EQ(out_intr.fy, 200.5F);
  EXPECT_EQ(out_intr.ppx, 1.5F);  // plain division, no half-pixel correction
  EXPECT_EQ(out_intr.ppy, 0.5F);
}

TEST(Decimation, MedianOfNineForThreeAndTruncatedMeanForFour) {
  DepthImage in3 = image(3, 3, {9, 1, 8, 2, 7, 3, 6, 4, 5});
  DepthImage out;
  Intrinsics intr, out_intr;
  decimate(DecimationParams{3}, in3, intr, out, out_intr);
  EXPECT_EQ(out.pixels[0], 5);  // 5th smallest of 1..9
  EXPECT_EQ(out.width, 4);      // 1 → padded to 4

  std::vector<uint16_t> block(16, 10);
  block[0] = block[5] = block[10] = block[15] = 0;  // holes do not count
  block[3] = 13;                                     // 11 · 10 + 13 = 123 over 12 → 10.25 → 10
  DepthImage in4 = image(4, 4, block);
  decimate(DecimationParams{4}, in4, intr, out, out_intr);
  EXPECT_EQ(out.pixels[0], 10);
  block[3] = 22;  // 132 / 12 = 11 exactly
  in4 = image(4, 4, block);
  decimate(DecimationParams{4}, in4, intr, out, out_intr);
  EXPECT_EQ(out.pixels[0], 11);
}

TEST(Decimation, OutputSizesOfTheSpec) {
  const auto size = [](int w, int h, int s) {
    DepthImage in = image(w, h, std::vector<uint16_t>(static_cast<size_t>(w) * h, 1000));
    DepthImage out;
    Intrinsics intr, out_intr;
    decimate(DecimationParams{s}, in, intr, out, out_intr);
    return std::make_pair(out.width, out.height);
  };
  EXPECT_EQ(size(1280, 720, 3), std::make_pair(428, 240));
  EXPECT_EQ(size(848, 480, 2), std::make_pair(424, 240));
  EXPECT_EQ(size(848, 480, 3), std::make_pair(284, 160));
  EXPECT_EQ(size(640, 480, 3), std::make_pair(216, 160));
  EXPECT_EQ(size(848, 480, 5), std::make_pair(172, 96));
}

// 4 wide, 3 high; only the middle row can change in modes 1 and 2.
const std::vector<uint16_t> kHoles{5, 6, 7, 8,  //
                                   0, 0, 9, 0,  //
                                   4, 0, 3, 2};

TEST(HoleFilling, FromLeftNeverFillsColumnZero) {
  DepthImage d = image(4, 3, kHoles);
  fill_holes(HoleFillingParams{0}, d);
  EXPECT_EQ(d.pixels, (std::vector<uint16_t>{5, 6, 7, 8, 0, 0, 9, 9, 4, 4, 3, 2}));
}

TEST(HoleFilling, FarthestTakesTheLargestOfFiveNeighbours) {
  DepthImage d = image(4, 3, kHoles);
  fill_holes(HoleFillingParams{1}, d);
  // (1,1): max(up-left 5, up 6, left 0, down-left 4, down 0) = 6; (3,1): max(7, 8, 9, 3, 2) = 9.
  EXPECT_EQ(d.pixels, (std::vector<uint16_t>{5, 6, 7, 8, 0, 6, 9, 9, 4, 0, 3, 2}));
}

TEST(HoleFilling, NearestTakesTheSmallestNonEmptyStartingFromAbove) {
  DepthImage d = image(4, 3, kHoles);
  fill_holes(HoleFillingParams{2}, d);
  // (1,1): from up 6, then 5, 4 → 4; (3,1): from 8, then 7, 3, 2 → 2 (right is never looked at).
  EXPECT_EQ(d.pixels, (std::vector<uint16_t>{5, 6, 7, 8, 0, 4, 9, 2, 4, 0, 3, 2}));
  // SDK quirk: an empty pixel above keeps the hole empty; farthest fills it.
  const std::vector<uint16_t> quirk{5, 0, 7, 3, 0, 4, 1, 1, 1};
  DepthImage nearest = image(3, 3, quirk);
  fill_holes(HoleFillingParams{2}, nearest);
  EXPECT_EQ(nearest.pixels[4], 0);
  DepthImage farthest = image(3, 3, quirk);
  fill_holes(HoleFillingParams{1}, farthest);
  EXPECT_EQ(farthest.pixels[4], 5);
}

TEST(HoleFilling, FarthestInDisparityIsTheLargestDisparity) {
  DisparityImage d;
  d.resize(3, 3);
  d.pixels = {1.0F, 2.0F, 3.0F, 4.0F, 0.0F, 6.0F, 7.0F, 8.0F, 9.0F};
  fill_holes(HoleFillingParams{1}, d);
  EXPECT_EQ(d.pixels[4], 8.0F);  // max(1, 2, 4, 7, 8): the nearest surface in depth
}

}  // namespace
}  // namespace hrcsense
