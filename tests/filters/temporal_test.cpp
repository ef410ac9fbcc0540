// SPDX-License-Identifier: Apache-2.0
// Temporal filter: α and δ by hand, every persistence mode against a history that passes and
// one that fails its rule (spec §6), state resets, and equality with the plain reference.
#include "hrcsense/filters.hpp"
#include "reference.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace hrcsense {
namespace {

// Runs a one-pixel sequence (2x2 image, all four pixels alike) and returns the outputs.
std::vector<uint16_t> run(const TemporalParams& params, const std::vector<uint16_t>& inputs) {
  TemporalFilter filter;
  filter.params = params;
  std::vector<uint16_t> outputs;
  DepthImage d;
  for (const uint16_t value : inputs) {
    d.resize(2, 2);
    std::fill(d.pixels.begin(), d.pixels.end(), value);
    filter.apply(d);
    outputs.push_back(d.pixels[3]);
  }
  return outputs;
}

uint16_t last_output(int persistence, const std::vector<uint16_t>& inputs) {
  return run(TemporalParams{0.4F, 20, persistence}, inputs).back();
}

constexpr uint16_t V = 1000;  // a valid sample

std::vector<uint16_t> seq(std::initializer_list<std::pair<uint16_t, int>> runs) {
  std::vector<uint16_t> s;
  for (const auto& [value, count] : runs) s.insert(s.end(), static_cast<size_t>(count), value);
  return s;
}

TEST(Temporal, WorkedExampleOfTheSpec) {
  // 0.4 · 1010 + 0.6 · 1000 = 1004 (truncated); mode 3 then fills 3 frames and gives up.
  EXPECT_EQ(run(TemporalParams{0.4F, 20, 3}, {1000, 1010, 0, 0, 0, 0}),
            (std::vector<uint16_t>{1000, 1004, 1004, 1004, 1004, 0}));
}

TEST(Temporal, AlphaBlendsAndTruncates) {
  // 0.1 · 1019 + 0.9 · 1000 = 1001.9 → 1001 (no rounding); then 0.1 · 1000 + 0.9 · 1001 = 1000.9 → 1000.
  EXPECT_EQ(run(TemporalParams{0.1F, 20, 0}, {1000, 1019, 1000}), (std::vector<uint16_t>{1000, 1001, 1000}));
  // α = 0: the first value holds while new samples agree.
  EXPECT_EQ(run(TemporalParams{0.0F, 20, 0}, {1000, 1015, 985}), (std::vector<uint16_t>{1000, 1000, 1000}));
}

TEST(Temporal, DeltaIsStrictAndAJumpRestarts) {
  // |1020 − 1000| = 20 is not < 20: the new value is taken as is and becomes the reference.
  EXPECT_EQ(run(TemporalParams{0.5F, 20, 0}, {1000, 1020, 1030}), (std::vector<uint16_t>{1000, 1020, 1025}));
  EXPECT_EQ(run(TemporalParams{0.5F, 21, 0}, {1000, 1020}), (std::vector<uint16_t>{1000, 1010}));
  // A jump forgets the history: mode 3 at frame 3 sees only frame 2 valid → no fill.
  EXPECT_EQ(run(TemporalParams{0.4F, 20, 3}, {V, V, 1100, 0}).back(), 0);
  EXPECT_EQ(run(TemporalParams{0.4F, 20, 3}, {V, V, V, 0}).back(), V);
}

TEST(Temporal, Persistence0NeverFills) {
  EXPECT_EQ(last_output(0, seq({{V, 8}, {0, 1}})), 0);
  EXPECT_EQ(run(TemporalParams{0.4F, 20, 0}, {1000, 1010}).back(), 1004);  // smoothing still runs
}

TEST(Temporal, Persistence1NeedsTheLastEightValid) {
  EXPECT_EQ(last_output(1, seq({{V, 8}, {0, 1}})), V);  // frame 8: frames 0–7 valid
  EXPECT_EQ(last_output(1, seq({{V, 7}, {0, 1}})), 0);  // frame 7: frame t-8 does not exist
  EXPECT_EQ(last_output(1, seq({{V, 8}, {0, 2}})), 0);  // frame 9: frame 8 was a hole
}

TEST(Temporal, Persistence2NeedsTwoOfTheLastThree) {
  EXPECT_EQ(last_output(2, seq({{V, 2}, {0, 2}})), V);  // frame 3: frames 2,1,0 = 0,V,V
  EXPECT_EQ(last_output(2, seq({{V, 2}, {0, 3}})), 0);  // frame 4: frames 3,2,1 = 0,0,V
}

TEST(Temporal, Persistence3NeedsTwoOfTheLastFour) {
  EXPECT_EQ(last_output(3, seq({{V, 2}, {0, 3}})), V);  // frame 4: 0,0,V,V
  EXPECT_EQ(last_output(3, seq({{V, 2}, {0, 4}})), 0);  // frame 5: 0,0,0,V
}

TEST(Temporal, Persistence4NeedsTwoOfTheLastEight) {
  EXPECT_EQ(last_output(4, seq({{V, 2}, {0, 7}})), V);  // frame 8: frames 0,1 valid
  EXPECT_EQ(last_output(4, seq({{V, 2}, {0, 8}})), 0);  // frame 9: only frame 1 in the window
}

TEST(Temporal, Persistence5NeedsOneOfTheLastTwo) {
  EXPECT_EQ(last_output(5, seq({{V, 1}, {0, 2}})), V);  // frame 2: frames 1,0 = 0,V
  EXPECT_EQ(last_output(5, seq({{V, 1}, {0, 3}})), 0);  // frame 3: frames 2,1 = 0,0
}

TEST(Temporal, Persistence6NeedsOneOfTheLastFive) {
  EXPECT_EQ(last_output(6, seq({{V, 1}, {0, 5}})), V);  // frame 5
  EXPECT_EQ(last_output(6, seq({{V, 1}, {0, 6}})), 0);  // frame 6
}

TEST(Temporal, Persistence7NeedsOneOfTheLastEight) {
  EXPECT_EQ(last_output(7, seq({{V, 1}, {0, 8}})), V);  // frame 8: frame 0 is t-8
  EXPECT_EQ(last_output(7, seq({{V, 1}, {0, 9}})), 0);  // frame 9
}

TEST(Temporal, Persistence8AlwaysFillsOnceSeen) {
  EXPECT_EQ(last_output(8, seq({{V, 1}, {0, 30}})), V);
  EXPECT_EQ(last_output(8, seq({{0, 5}})), 0);  // never valid: nothing to fill with
}

TEST(Temporal, FillingDoesNotUpdateTheStoredValue) {
  // Mode 8 fills with 1004 while holes last; the next valid 1015 blends with 1004.
  // 0.4 · 1015 + 0.6 · 1004 = 1008.4 → 1008.
  EXPECT_EQ(run(TemporalParams{0.4F, 20, 8}, {1000, 1010, 0, 0, 1015}),
            (std::vector<uint16_t>{1000, 1004, 1004, 1004, 1008}));
}

TEST(Temporal, ParameterOrSizeChangeResetsTheState) {
  TemporalFilter filter;
  DepthImage d;
  d.resize(2, 2);
  std::fill(d.pixels.begin(), d.pixels.end(), uint16_t{1000});
  filter.apply(d);
  filter.params.alpha = 0.5F;  // takes effect at once and starts over
  std::fill(d.pixels.begin(), d.pixels.end(), uint16_t{1010});
  filter.apply(d);
  EXPECT_EQ(d.pixels[0], 1010);  // no blend with the forgotten 1000
  d.resize(4, 1);
  std::fill(d.pixels.begin(), d.pixels.end(), uint16_t{0});
  filter.apply(d);
  EXPECT_EQ(d.pixels[0], 0);  // new size: nothing to fill from
}

TEST(Temporal, AllZeroFrameIsFilledFromHistory) {
  EXPECT_EQ(run(TemporalParams{0.4F, 20, 3}, {1000, 1000, 0}), (std::vector<uint16_t>{1000, 1000, 1000}));
}

// The library (rotating history, as the SDK) against the shift-register reference.
TEST(Temporal, EqualsThePlainReferenceBitForBit) {
  std::mt19937 rng(23);
  std::uniform_int_distribution<int> value(950, 1050);
  std::uniform_int_distribution<int> hole(0, 2);
  for (int persistence = 0; persistence <= 8; ++persistence) {
    const TemporalParams q{persistence == 4 ? 0.1F : 0.4F, persistence == 6 ? 100 : 20, persistence};
    TemporalFilter ours;
    ours.params = q;
    TemporalFilter ours_disparity;
    ours_disparity.params = q;
    reference::Temporal<uint16_t> depth_ref{q, {}, {}};
    reference::Temporal<float> disparity_ref{q, {}, {}};
    DepthImage d;
    DisparityImage disparity;
    for (int frame = 0; frame < 30; ++frame) {
      d.resize(17, 9);
      for (uint16_t& p : d.pixels) p = hole(rng) == 0 ? 0 : static_cast<uint16_t>(value(rng));
      depth_to_disparity(d, 669216.0F, disparity);
      std::vector<uint16_t> expected = d.pixels;
      std::vector<float> expected_disparity = disparity.pixels;
      ours.apply(d);
      depth_ref.apply(expected);
      ours_disparity.apply(disparity);
      disparity_ref.apply(expected_disparity);
      ASSERT_EQ(d.pixels, expected) << "persistence " << persistence << " frame " << frame;
      ASSERT_EQ(disparity.pixels, expected_disparity) << "persistence " << persistence << " frame " << frame;
    }
  }
}

TEST(Temporal, NeverInvalidatesAValidPixelAndAlphaOneKeepsValidPixels) {
  std::mt19937 rng(29);
  std::uniform_int_distribution<int> value(500, 3000);
  TemporalFilter filter;
  filter.params = TemporalParams{1.0F, 100, 8};
  DepthImage d;
  for (int frame = 0; frame < 12; ++frame) {
    d.resize(16, 16);
    for (uint16_t& p : d.pixels) p = value(rng) < 900 ? 0 : static_cast<uint16_t>(value(rng));
    const std::vector<uint16_t> in = d.pixels;
    filter.apply(d);
    for (size_t i = 0; i < in.size(); ++i) {
      if (in[i] != 0) {
        EXPECT_EQ(d.pixels[i], in[i]);
      }
    }
  }
}

}  // namespace
}  // namespace hrcsense
