// SPDX-License-Identifier: Apache-2.0
// Every field of the "sdk" and "thesis" filter presets, written out from docs/FILTERS.md
// ("Presets"), specs/depth-filters.md §8 (SDK defaults) and the thesis's settings, for
// chain_test.cpp (filter_preset) and filters_config_test.cpp (filters.preset in a config).
#pragma once

#include "hrcsense/filters.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace hrcsense::test {

/// The SDK's option defaults for the blocks a preset leaves at their defaults (spec §8).
inline void expect_sdk_option_defaults_except_spatial_and_temporal(const FilterChainParams& p) {
  EXPECT_EQ(p.threshold.min_m, 0.1F);  // the block's own default, not the C++ wrapper's 0.15
  EXPECT_EQ(p.threshold.max_m, 4.0F);
  EXPECT_EQ(p.decimation.magnitude, 2);
  EXPECT_EQ(p.hole_filling.mode, 1);  // farthest from around, used when hole_filling is enabled
}

/// "sdk": the RealSense Viewer's defaults — threshold 0.1–4 m, decimation ×2, the disparity
/// domain, spatial α 0.5 δ 20 magnitude 2 holes_fill 0, temporal α 0.4 δ 20 persistence 3,
/// hole filling off; threshold first (spec §1).
inline void expect_sdk_preset(const FilterChainParams& p) {
  using B = FilterBlock;
  EXPECT_EQ(p.order, (std::vector<FilterBlock>{B::threshold, B::decimation, B::to_disparity, B::spatial, B::temporal,
                                               B::to_depth}));
  expect_sdk_option_defaults_except_spatial_and_temporal(p);
  EXPECT_EQ(p.spatial.alpha, 0.5F);
  EXPECT_EQ(p.spatial.delta, 20);
  EXPECT_EQ(p.spatial.magnitude, 2);
  EXPECT_EQ(p.spatial.holes_fill, 0);
  EXPECT_EQ(p.temporal.alpha, 0.4F);
  EXPECT_EQ(p.temporal.delta, 20);
  EXPECT_EQ(p.temporal.persistence, 3);
  EXPECT_STREQ(filter_domain(p, 50.0F), "disparity");
  EXPECT_STREQ(filter_domain(p, 0.0F), "depth");  // no baseline: the documented fallback
}

/// "thesis": no threshold, no decimation, the disparity domain, spatial α 0.4 δ 20 magnitude 2
/// (holes_fill left at the SDK's 0: the thesis names no spatial hole filling), temporal α 0.4
/// δ 20 persistence 3, no hole-filling block; the unused blocks keep the SDK's defaults.
inline void expect_thesis_preset(const FilterChainParams& p) {
  using B = FilterBlock;
  EXPECT_EQ(p.order, (std::vector<FilterBlock>{B::to_disparity, B::spatial, B::temporal, B::to_depth}));
  EXPECT_EQ(p.spatial.alpha, 0.4F);
  EXPECT_EQ(p.spatial.delta, 20);
  EXPECT_EQ(p.spatial.magnitude, 2);
  EXPECT_EQ(p.spatial.holes_fill, 0);
  EXPECT_EQ(p.temporal.alpha, 0.4F);
  EXPECT_EQ(p.temporal.delta, 20);
  EXPECT_EQ(p.temporal.persistence, 3);
  expect_sdk_option_defaults_except_spatial_and_temporal(p);
  EXPECT_STREQ(filter_domain(p, 50.0F), "disparity");
  EXPECT_STREQ(filter_domain(p, 0.0F), "depth");
}

}  // namespace hrcsense::test
