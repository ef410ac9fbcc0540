// SPDX-License-Identifier: Apache-2.0
// Spatial filter: hand-worked rows in both domains (spec §5), edge preservation, iterations,
// hole filling (every holes_fill mode 1–5, hand-worked), properties, and equality with the
// plain reference in reference.hpp.
#include "hrcsense/filters.hpp"
#include "reference.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <utility>
#include <vector>

namespace hrcsense {
namespace {

// Two identical rows, so the vertical passes change nothing (spec: prefer H >= 2).
DepthImage two_rows(const std::vector<uint16_t>& row) {
  DepthImage d;
  d.resize(static_cast<int>(row.size()), 2);
  std::copy(row.begin(), row.end(), d.pixels.begin());
  std::copy(row.begin(), row.end(), d.pixels.begin() + static_cast<ptrdiff_t>(row.size()));
  return d;
}

DisparityImage two_float_rows(const std::vector<float>& row) {
  DisparityImage d;
  d.resize(static_cast<int>(row.size()), 2);
  std::copy(row.begin(), row.end(), d.pixels.begin());
  std::copy(row.begin(), row.end(), d.pixels.begin() + static_cast<ptrdiff_t>(row.size()));
  return d;
}

template <typename T>
std::vector<T> first_row(const std::vector<T>& pixels, size_t w) {
  return std::vector<T>(pixels.begin(), pixels.begin() + static_cast<ptrdiff_t>(w));
}

TEST(SpatialDepth, WorkedExampleOfTheSpec) {
  DepthImage d = two_rows({1000, 1010, 1030, 0, 1000});
  spatial_filter(SpatialParams{0.5F, 20, 1, 0}, d);
  // L→R: 1010 vs 1000 → 1005.5 → 1005; 1030 vs 1005 differs by 25 > 20, kept.
  // R→L: 1000 vs 1005 → 1002.5 + 0.5 → 1003.
  EXPECT_EQ(first_row(d.pixels, 5), (std::vector<uint16_t>{1003, 1005, 1030, 0, 1000}));
  EXPECT_EQ(d.pixels[5], 1003);  // second row identical
}

TEST(SpatialDepth, SecondIterationStartsFromTheFirst) {
  DepthImage d = two_rows({1000, 1010, 1030, 0, 1000});
  spatial_filter(SpatialParams{0.5F, 20, 2, 0}, d);
  // From [1003, 1005, 1030, 0, 1000]: L→R 1005 vs 1003 → 1004; R→L 1003 vs 1004 → 1003.5 + 0.5 → 1004.
  EXPECT_EQ(first_row(d.pixels, 5), (std::vector<uint16_t>{1004, 1004, 1030, 0, 1000}));
}

TEST(SpatialDepth, InclusiveDeltaLeftToRight) {
  DepthImage d = two_rows({1000, 1020, 1020, 1020});
  spatial_filter(SpatialParams{0.5F, 20, 1, 0}, d);
  // L→R: |1020-1000| = 20 <= δ → 1010; then 1020 vs 1010 → 1015; column 3 is never visited L→R.
  // R→L: 1015 vs 1020 → 1018 (1017.5 + 0.5); 1010 vs 1018 → 1014; 1000 vs 1014 → 1007.
  EXPECT_EQ(first_row(d.pixels, 4), (std::vector<uint16_t>{1007, 1014, 1018, 1020}));
}

TEST(SpatialDisparity, WorkedRowComparesUnsmoothedNeighboursStrictly) {
  DisparityImage d = two_float_rows({100.0F, 110.0F, 130.0F, 0.0F, 100.0F});
  spatial_filter(SpatialParams{0.5F, 20, 1, 0}, d);
  // L→R: 110 vs 100 → 105; |110-130| = 20 is not < 20: an edge, kept; 0 breaks the chain.
  // R→L over [100, 0, 130, 105, 100] reversed: 105 vs 130 differs by 25 (edge, state 105);
  // 100 vs 105 → 0.5·100 + 0.5·105 = 102.5 (no rounding in this domain).
  EXPECT_EQ(first_row(d.pixels, 5), (std::vector<float>{102.5F, 105.0F, 130.0F, 0.0F, 100.0F}));
}

TEST(SpatialDepth, HoleFillRadiusTwoFillsOnePixelFromEachSide) {
  DepthImage d = two_rows({1000, 0, 0, 0, 0, 1000, 1000});
  spatial_filter(SpatialParams{0.5F, 20, 1, 1}, d);
  EXPECT_EQ(first_row(d.pixels, 7), (std::vector<uint16_t>{1000, 1000, 0, 0, 1000, 1000, 1000}));
}

TEST(SpatialDepth, HoleFillRadiusFourFillsThreeAndGrowsWithIterations) {
  const std::vector<uint16_t> row{1000, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1000, 1000};  // 12 holes
  DepthImage once = two_rows(row);
  spatial_filter(SpatialParams{0.5F, 20, 1, 2}, once);
  EXPECT_EQ(first_row(once.pixels, 15),
            (std::vector<uint16_t>{1000, 1000, 1000, 1000, 0, 0, 0, 0, 0, 0, 1000, 1000, 1000, 1000, 1000}));
  DepthImage twice = two_rows(row);
  spatial_filter(SpatialParams{0.5F, 20, 2, 2}, twice);  // the fill runs in every iteration
  EXPECT_EQ(first_row(twice.pixels, 15), std::vector<uint16_t>(15, 1000));
}

TEST(SpatialDisparity, HoleFillRunsOnceAfterTheIterations) {
  const std::vector<float> row{100.0F, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 100.0F, 100.0F};
  DisparityImage d = two_float_rows(row);
  spatial_filter(SpatialParams{0.5F, 20, 2, 2}, d);
  std::vector<float> expected(15, 100.0F);
  for (int u = 4; u <= 9; ++u) expected[static_cast<size_t>(u)] = 0.0F;
  EXPECT_EQ(first_row(d.pixels, 15), expected);
}

TEST(SpatialDisparity, LastColumnTakesTheNextRowsFirstPixelAsTheSdk) {
  DisparityImage d;
  d.resize(3, 2);
  d.pixels = {100.0F, 100.0F, 0.0F,  //
              50.0F, 100.0F, 0.0F};
  spatial_filter(SpatialParams{1.0F, 20, 1, 1}, d);
  // L→R fills both last columns from their left; nothing is left for the R→L pass.
  EXPECT_EQ(d.pixels, (std::vector<float>{100.0F, 100.0F, 100.0F, 50.0F, 100.0F, 100.0F}));
  d.pixels = {100.0F, 0.0F, 0.0F,  //
              50.0F, 0.0F, 0.0F};
  spatial_filter(SpatialParams{1.0F, 20, 1, 1}, d);
  // L→R fills column 1; R→L: row 0's last column copies row 1's first pixel (50),
  // row 1's last column has no right neighbour and stays empty.
  EXPECT_EQ(d.pixels, (std::vector<float>{100.0F, 100.0F, 50.0F, 50.0F, 50.0F, 0.0F}));
}

// A row written as runs of (value, count), so that long rows of holes read at a glance.
template <typename T>
std::vector<T> runs(const std::vector<std::pair<T, int>>& parts) {
  std::vector<T> row;
  for (const auto& [value, count] : parts) row.insert(row.end(), static_cast<size_t>(count), value);
  return row;
}

// holes_fill 3–5 (radius 8, 16, 255) on a hole run between 1000 mm (left) and 1500 mm (right):
// the two sides differ by 500 > δ, so no blend crosses the run; blends among equal values
// give the value back (0.5·x + 0.5·x + 0.5 truncates to x), and the two identical rows leave
// the vertical passes nothing to change. Only the fill moves values.
using DepthRuns = std::vector<std::pair<uint16_t, int>>;
using FloatRuns = std::vector<std::pair<float, int>>;

TEST(SpatialDepth, HoleFillModeThreeRadiusEightFillsSevenFromEachSide) {
  // 20 holes in columns 1..20, W = 23.
  DepthImage once = two_rows(runs<uint16_t>(DepthRuns{{1000, 1}, {0, 20}, {1500, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 1, 3}, once);
  // L→R: the counter reaches 1..7 < 8 in columns 1..7 (filled with 1000); at column 8 it is
  // 8, not < 8, so 8 stays 0, and 9..21 see an invalid left neighbour (nothing happens).
  // R→L (counter reset): column 21 = 1500 is valid; columns 20..14 get counts 1..7 and take
  // 1500; 13 reaches 8 and stays 0; 12..8 see an invalid right neighbour.
  // Left: 8 × 1000 (columns 0..7), 6 holes (8..13), 9 × 1500 (14..22).
  const std::vector<uint16_t> expected = runs<uint16_t>(DepthRuns{{1000, 8}, {0, 6}, {1500, 9}});
  EXPECT_EQ(first_row(once.pixels, 23), expected);
  EXPECT_EQ(std::vector<uint16_t>(once.pixels.begin() + 23, once.pixels.end()), expected);  // second row alike
  // Magnitude 2: the second iteration's L→R starts from column 7 (1000) and fills 8..13 with
  // counts 1..6 < 8; column 14 (1500) is valid, 500 > δ apart, kept. The depth path fills in
  // every iteration, so the run closes.
  DepthImage twice = two_rows(runs<uint16_t>(DepthRuns{{1000, 1}, {0, 20}, {1500, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 2, 3}, twice);
  EXPECT_EQ(first_row(twice.pixels, 23), runs<uint16_t>(DepthRuns{{1000, 14}, {1500, 9}}));
}

TEST(SpatialDisparity, HoleFillModeThreeFillsSevenFromEachSideOnceAfterTheIterations) {
  // The same row in disparity units: 100 left, 150 right (50 apart, an edge at δ 20).
  for (const int magnitude : {1, 2}) {
    DisparityImage d = two_float_rows(runs<float>(FloatRuns{{100.0F, 1}, {0.0F, 20}, {150.0F, 2}}));
    spatial_filter(SpatialParams{0.5F, 20, magnitude, 3}, d);
    // The smoothing passes change nothing (edges, holes, equal values: 0.5·150 + 0.5·150 is
    // exactly 150). Then one fill: L→R counts 1..7 < 8 over columns 1..7 (copy 100), 8..20
    // count on without filling; columns 21, 22 are data. R→L: columns 20..14 count 1..7 (copy
    // 150), 13..8 count 8..13. Column 22 holds data, so the SDK's next-row quirk never shows.
    // Unlike the depth path, a second iteration does not fill further: the fill runs once.
    EXPECT_EQ(first_row(d.pixels, 23), runs<float>(FloatRuns{{100.0F, 8}, {0.0F, 6}, {150.0F, 9}}))
        << "magnitude " << magnitude;
  }
}

TEST(SpatialDepth, HoleFillModeFourRadiusSixteenFillsFifteenFromEachSide) {
  // 40 holes in columns 1..40, W = 43.
  DepthImage d = two_rows(runs<uint16_t>(DepthRuns{{1000, 1}, {0, 40}, {1500, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 1, 4}, d);
  // L→R: counts 1..15 < 16 fill columns 1..15 with 1000; 16 stays 0 (count 16).
  // R→L: counts 1..15 fill columns 40..26 with 1500; 25 stays 0. Left: 16..25, 10 holes.
  EXPECT_EQ(first_row(d.pixels, 43), runs<uint16_t>(DepthRuns{{1000, 16}, {0, 10}, {1500, 17}}));
}

TEST(SpatialDisparity, HoleFillModeFourFillsFifteenFromEachSide) {
  DisparityImage d = two_float_rows(runs<float>(FloatRuns{{100.0F, 1}, {0.0F, 40}, {150.0F, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 1, 4}, d);
  // As the depth path with one iteration: columns 1..15 ← 100, 40..26 ← 150, 16..25 stay 0.
  EXPECT_EQ(first_row(d.pixels, 43), runs<float>(FloatRuns{{100.0F, 16}, {0.0F, 10}, {150.0F, 17}}));
}

TEST(SpatialDepth, HoleFillModeFiveRadius255FillsUpTo254FromEachSide) {
  // The 40-hole run of mode 4: counts 1..40 < 255, so L→R alone fills all of it with the
  // left value; column 41 (1500) is then valid next to 1000, 500 > δ, kept. R→L finds no hole.
  DepthImage d = two_rows(runs<uint16_t>(DepthRuns{{1000, 1}, {0, 40}, {1500, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 1, 5}, d);
  EXPECT_EQ(first_row(d.pixels, 43), runs<uint16_t>(DepthRuns{{1000, 41}, {1500, 2}}));
  // "Unlimited" is 254: 600 holes in columns 1..600 (W = 603). L→R fills 1..254 (counts up to
  // 254 < 255), 255 stays 0; R→L fills 600..347 with 1500, 346 stays 0: holes 255..346 (92) stay.
  DepthImage wide = two_rows(runs<uint16_t>(DepthRuns{{1000, 1}, {0, 600}, {1500, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 1, 5}, wide);
  EXPECT_EQ(first_row(wide.pixels, 603), runs<uint16_t>(DepthRuns{{1000, 255}, {0, 92}, {1500, 256}}));
}

TEST(SpatialDisparity, HoleFillModeFiveFillsUpTo254FromEachSide) {
  DisparityImage d = two_float_rows(runs<float>(FloatRuns{{100.0F, 1}, {0.0F, 40}, {150.0F, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 1, 5}, d);
  // L→R: counts 1..40 < 255 copy 100 into all 40; R→L then finds no +0.0 pixel.
  EXPECT_EQ(first_row(d.pixels, 43), runs<float>(FloatRuns{{100.0F, 41}, {150.0F, 2}}));
  DisparityImage wide = two_float_rows(runs<float>(FloatRuns{{100.0F, 1}, {0.0F, 600}, {150.0F, 2}}));
  spatial_filter(SpatialParams{0.5F, 20, 1, 5}, wide);
  // Columns 1..254 ← 100, 600..347 ← 150, 255..346 stay 0 (as the depth path).
  EXPECT_EQ(first_row(wide.pixels, 603), runs<float>(FloatRuns{{100.0F, 255}, {0.0F, 92}, {150.0F, 256}}));
}

// Two flat-ish halves a step apart: nothing crosses a step larger than δ.
TEST(Spatial, NeverSmoothsAcrossAStepLargerThanDelta) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> noise(0, 5);
  DepthImage d;
  d.resize(40, 30);
  for (int v = 0; v < 30; ++v)
    for (int u = 0; u < 40; ++u) d.pixels[static_cast<size_t>(v) * 40 + u] = static_cast<uint16_t>((u < 20 ? 1000 : 1100) + noise(rng));
  DepthImage depth = d;
  spatial_filter(SpatialParams{0.25F, 20, 5, 0}, depth);
  DisparityImage disparity;
  const float f = disparity_factor(50.0F, 418.26F, 0.001F);  // 1000 mm → 669 units, 1100 mm → 608
  depth_to_disparity(d, f, disparity);
  spatial_filter(SpatialParams{0.25F, 20, 5, 0}, disparity);
  for (int v = 0; v < 30; ++v) {
    for (int u = 0; u < 40; ++u) {
      const size_t i = static_cast<size_t>(v) * 40 + u;
      if (u < 20) {
        EXPECT_LE(depth.pixels[i], 1005) << u << "," << v;
        EXPECT_GE(disparity.pixels[i], f / 1010.0F) << u << "," << v;
      } else {
        EXPECT_GE(depth.pixels[i], 1100) << u << "," << v;
        EXPECT_LE(disparity.pixels[i], f / 1095.0F) << u << "," << v;
      }
    }
  }
}

DepthImage random_depth_with_holes(std::mt19937& rng, int w, int h) {
  std::uniform_int_distribution<int> value(900, 1100);
  std::uniform_int_distribution<int> hole(0, 9);
  DepthImage d;
  d.resize(w, h);
  for (uint16_t& p : d.pixels) p = hole(rng) == 0 ? 0 : static_cast<uint16_t>(value(rng));
  return d;
}

TEST(Spatial, AlphaOneWithoutHoleFillChangesNothing) {
  std::mt19937 rng(11);
  const DepthImage in = random_depth_with_holes(rng, 64, 48);
  DepthImage depth = in;
  spatial_filter(SpatialParams{1.0F, 50, 5, 0}, depth);
  EXPECT_EQ(depth.pixels, in.pixels);
  DisparityImage disparity, original;
  depth_to_disparity(in, 669216.0F, original);
  disparity = original;
  spatial_filter(SpatialParams{1.0F, 50, 5, 0}, disparity);
  EXPECT_EQ(disparity.pixels, original.pixels);
}

TEST(Spatial, NeverInvalidatesAValidPixel) {
  std::mt19937 rng(13);
  for (int holes = 0; holes <= 5; ++holes) {
    const DepthImage in = random_depth_with_holes(rng, 50, 40);
    DepthImage depth = in;
    spatial_filter(SpatialParams{0.3F, 30, 3, holes}, depth);
    DisparityImage disparity;
    depth_to_disparity(in, 669216.0F, disparity);
    spatial_filter(SpatialParams{0.3F, 30, 3, holes}, disparity);
    for (size_t i = 0; i < in.pixels.size(); ++i) {
      if (in.pixels[i] == 0) continue;
      EXPECT_NE(depth.pixels[i], 0) << i;
      EXPECT_GT(disparity.pixels[i], 0.0F) << i;
    }
  }
}

// The library against the plain reference, every option set, on random images.
TEST(Spatial, EqualsThePlainReferenceBitForBit) {
  std::mt19937 rng(17);
  const SpatialParams options[] = {{0.5F, 20, 2, 0}, {0.25F, 1, 1, 1}, {0.4F, 50, 5, 3},
                                   {0.77F, 8, 3, 5}, {1.0F, 20, 2, 2}, {0.5F, 20, 2, 4}};
  for (const SpatialParams& q : options) {
    const DepthImage in = random_depth_with_holes(rng, 37, 23);
    DepthImage ours = in, theirs = in;
    spatial_filter(q, ours);
    reference::spatial_depth(q, theirs);
    EXPECT_EQ(ours.pixels, theirs.pixels) << q.alpha << " " << q.delta << " " << q.magnitude << " " << q.holes_fill;
    DisparityImage a, b;
    depth_to_disparity(in, 669216.0F, a);
    b = a;
    spatial_filter(q, a);
    reference::spatial_disparity(q, b);
    EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(float)), 0)
        << q.alpha << " " << q.delta << " " << q.magnitude << " " << q.holes_fill;
  }
}

}  // namespace
}  // namespace hrcsense
