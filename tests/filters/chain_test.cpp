// SPDX-License-Identifier: Apache-2.0
// The chain: block names, presets (every field), order checks, the depth-domain fallback without a baseline,
// decimated intrinsics, and repeatability after a reset.
#include "hrcsense/filters.hpp"
#include "preset_expectations.hpp"

#include <gtest/gtest.h>

#include <random>

namespace hrcsense {
namespace {

Frame noisy_frame(uint32_t seed, float baseline_mm) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0F, 4.0F);
  Frame f;
  f.depth.resize(64, 48);
  for (int v = 0; v < 48; ++v)
    for (int u = 0; u < 64; ++u)
      f.depth.pixels[static_cast<size_t>(v) * 64 + u] =
          (u * 7 + v * 3) % 23 == 0 ? 0 : static_cast<uint16_t>((u < 32 ? 1000.0F : 1500.0F) + noise(rng));
  f.intrinsics.width = 64;
  f.intrinsics.height = 48;
  f.intrinsics.fx = f.intrinsics.fy = 60.0F;
  f.intrinsics.ppx = 32.0F;
  f.intrinsics.ppy = 24.0F;
  f.stereo_baseline_mm = baseline_mm;
  return f;
}

TEST(FilterChain, NamesRoundTrip) {
  for (const FilterBlock block : kFilterBlocks) EXPECT_EQ(filter_block_from_name(filter_block_name(block)), block);
  EXPECT_FALSE(filter_block_from_name("median"));
}

TEST(FilterChain, Presets) {
  EXPECT_TRUE(filter_preset(FilterPreset::none).order.empty());
  EXPECT_STREQ(filter_domain(filter_preset(FilterPreset::none), 50.0F), "none");
  for (const FilterPreset preset : kFilterPresets) EXPECT_EQ(check_filter_order(filter_preset(preset).order), "");
  EXPECT_STREQ(filter_preset_name(FilterPreset::none), "none");
  EXPECT_STREQ(filter_preset_name(FilterPreset::sdk), "sdk");
  EXPECT_STREQ(filter_preset_name(FilterPreset::thesis), "thesis");
}

TEST(FilterChain, SdkPresetHasEveryViewerDefault) { test::expect_sdk_preset(filter_preset(FilterPreset::sdk)); }

TEST(FilterChain, ThesisPresetHasEveryThesisSetting) { test::expect_thesis_preset(filter_preset(FilterPreset::thesis)); }

// The presets as they run: sdk decimates ×2 (fx halved), thesis keeps the source's intrinsics.
TEST(FilterChain, PresetsIntrinsics) {
  Intrinsics source;
  source.width = 848;
  source.height = 480;
  source.fx = source.fy = 418.0F;
  source.ppx = 424.0F;
  source.ppy = 240.0F;
  const Intrinsics sdk = filtered_intrinsics(filter_preset(FilterPreset::sdk), source);
  EXPECT_EQ(sdk.width, 424);  // 848 / 2, already a multiple of 4
  EXPECT_EQ(sdk.height, 240);
  EXPECT_EQ(sdk.fx, 209.0F);
  EXPECT_EQ(sdk.ppx, 212.0F);
  const Intrinsics thesis = filtered_intrinsics(filter_preset(FilterPreset::thesis), source);
  EXPECT_EQ(thesis.width, 848);
  EXPECT_EQ(thesis.fx, 418.0F);
}

TEST(FilterChain, OrderChecks) {
  using B = FilterBlock;
  EXPECT_EQ(check_filter_order({B::spatial, B::spatial}), "spatial appears twice");
  EXPECT_EQ(check_filter_order({B::to_depth}), "to_depth must follow to_disparity");
  EXPECT_EQ(check_filter_order({B::to_disparity, B::spatial}), "to_disparity must be followed by to_depth");
  EXPECT_NE(check_filter_order({B::to_disparity, B::decimation, B::to_depth}), "");
  EXPECT_EQ(check_filter_order({B::to_disparity, B::hole_filling, B::to_depth, B::threshold}), "");
}

TEST(FilterChain, WithoutBaselineRunsInTheDepthDomain) {
  FilterChain chain;
  chain.params = filter_preset(FilterPreset::thesis);
  Frame out;
  chain.process(noisy_frame(1, 0.0F), out);
  EXPECT_FALSE(chain.disparity_domain());
  ASSERT_EQ(chain.block_count(), 2U);
  EXPECT_EQ(chain.block(0), FilterBlock::spatial);
  EXPECT_EQ(chain.block(1), FilterBlock::temporal);
  // Same as running the two blocks by hand on depth.
  Frame in = noisy_frame(1, 0.0F);
  spatial_filter(chain.params.spatial, in.depth);
  TemporalFilter temporal;
  temporal.params = chain.params.temporal;
  temporal.apply(in.depth);
  EXPECT_EQ(out.depth.pixels, in.depth.pixels);
  chain.process(noisy_frame(2, 50.0F), out);
  EXPECT_TRUE(chain.disparity_domain());
  EXPECT_EQ(chain.block_count(), 4U);
}

TEST(FilterChain, DecimationScalesTheFramesIntrinsics) {
  FilterChain chain;
  chain.params = filter_preset(FilterPreset::sdk);
  Frame out;
  chain.process(noisy_frame(3, 50.0F), out);
  EXPECT_EQ(out.depth.width, 32);
  EXPECT_EQ(out.depth.height, 24);
  EXPECT_EQ(out.intrinsics.width, 32);
  EXPECT_EQ(out.intrinsics.fx, 30.0F);
  EXPECT_EQ(out.intrinsics.ppy, 12.0F);
}

TEST(FilterChain, ResetGivesIdenticalOutputAndNoFilterInvalidatesValidPixels) {
  FilterChain chain;
  chain.params = filter_preset(FilterPreset::thesis);
  chain.params.order.push_back(FilterBlock::hole_filling);
  std::vector<std::vector<uint16_t>> first;
  Frame out;
  for (uint32_t seed = 0; seed < 5; ++seed) {
    const Frame in = noisy_frame(seed, 50.0F);
    chain.process(in, out);
    for (size_t i = 0; i < in.depth.pixels.size(); ++i) {
      if (in.depth.pixels[i] != 0) {
        ASSERT_NE(out.depth.pixels[i], 0) << i;
      }
    }
    first.push_back(out.depth.pixels);
  }
  chain.reset();
  for (uint32_t seed = 0; seed < 5; ++seed) {
    chain.process(noisy_frame(seed, 50.0F), out);
    EXPECT_EQ(out.depth.pixels, first[seed]);
  }
}

}  // namespace
}  // namespace hrcsense
