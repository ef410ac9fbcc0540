// SPDX-License-Identifier: Apache-2.0
// Changes to FilterChain::params between frames: a parameter change takes effect on the next
// frame, and a change of resolution (here: of the decimation magnitude) resets the temporal
// filter, so the chain's output equals that of a fresh chain built with the new parameters.
#include "hrcsense/filters.hpp"

#include <gtest/gtest.h>

#include <random>

namespace hrcsense {
namespace {

Frame noisy_wall(uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0F, 6.0F);
  Frame f;
  f.depth.resize(64, 48);
  for (size_t i = 0; i < f.depth.pixels.size(); ++i) {
    f.depth.pixels[i] = i % 17 == 0 ? 0 : static_cast<uint16_t>(1200.0F + noise(rng));
  }
  f.intrinsics.width = 64;
  f.intrinsics.height = 48;
  f.intrinsics.fx = f.intrinsics.fy = 60.0F;
  f.intrinsics.ppx = 32.0F;
  f.intrinsics.ppy = 24.0F;
  f.stereo_baseline_mm = 50.0F;
  return f;
}

TEST(FilterChainChanges, SpatialParameterChangeTakesEffectOnTheNextFrame) {
  FilterChain chain;
  chain.params.order = {FilterBlock::to_disparity, FilterBlock::spatial, FilterBlock::to_depth};
  Frame out;
  chain.process(noisy_wall(1), out);
  chain.params.spatial.alpha = 0.9F;
  chain.params.spatial.delta = 3;
  chain.process(noisy_wall(2), out);

  FilterChain fresh;
  fresh.params = chain.params;
  Frame expected;
  fresh.process(noisy_wall(2), expected);
  EXPECT_EQ(out.depth.pixels, expected.depth.pixels);
  FilterChain old_params;
  old_params.params.order = chain.params.order;
  Frame unchanged;
  old_params.process(noisy_wall(2), unchanged);
  EXPECT_NE(out.depth.pixels, unchanged.depth.pixels);  // the change did something
}

TEST(FilterChainChanges, ResolutionChangeResetsTheTemporalFilter) {
  FilterChain chain;
  chain.params = filter_preset(FilterPreset::sdk);
  Frame out;
  for (uint32_t seed = 1; seed <= 3; ++seed) chain.process(noisy_wall(seed), out);
  ASSERT_EQ(out.depth.width, 32);
  chain.params.decimation.magnitude = 4;  // 16x12: the temporal history no longer fits
  chain.process(noisy_wall(4), out);
  EXPECT_EQ(out.depth.width, 16);
  EXPECT_EQ(out.depth.height, 12);
  EXPECT_EQ(out.intrinsics.fx, 15.0F);

  FilterChain fresh;
  fresh.params = chain.params;
  Frame expected;
  fresh.process(noisy_wall(4), expected);
  EXPECT_EQ(out.depth.pixels, expected.depth.pixels);

  // Back at 32x24 the state starts over again, rather than resuming the old 32x24 history.
  chain.params.decimation.magnitude = 2;
  chain.process(noisy_wall(5), out);
  FilterChain fresh2;
  fresh2.params = chain.params;
  fresh2.process(noisy_wall(5), expected);
  EXPECT_EQ(out.depth.pixels, expected.depth.pixels);
}

TEST(FilterChainChanges, TemporalParameterChangeRestartsTheHistory) {
  FilterChain chain;
  chain.params = filter_preset(FilterPreset::thesis);
  Frame out;
  for (uint32_t seed = 1; seed <= 3; ++seed) chain.process(noisy_wall(seed), out);
  chain.params.temporal.alpha = 0.8F;
  chain.process(noisy_wall(4), out);
  FilterChain fresh;
  fresh.params = chain.params;
  Frame expected;
  fresh.process(noisy_wall(4), expected);
  EXPECT_EQ(out.depth.pixels, expected.depth.pixels);
}

}  // namespace
}  // namespace hrcsense
