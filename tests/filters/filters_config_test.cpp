// SPDX-License-Identifier: Apache-2.0
// The filter keys of the configuration (filters.preset, filters.order, filters.<block>.<option>)
// with the SDK's ranges, and the chain's per-block timings in Pipeline::process.
#include "../support/decide.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/pipeline.hpp"
#include "preset_expectations.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hrcsense {
namespace {

using B = FilterBlock;

std::vector<FilterBlock> order_of(const std::vector<std::string>& sets) {
  return load_config("", sets).pipeline.filters.order;
}

// Expects a ConfigError whose message holds every one of `needles`.
void expect_error(const std::vector<std::string>& sets, const std::vector<std::string>& needles) {
  try {
    (void)load_config("", sets);
    ADD_FAILURE() << "no error for " << sets.front();
  } catch (const ConfigError& e) {
    for (const std::string& needle : needles) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << "'" << needle << "' not in: " << e.what();
    }
  }
}

TEST(FiltersConfig, Presets) {
  EXPECT_TRUE(order_of({"filters.preset=none"}).empty());
  expect_error({"filters.preset=fast"}, {"filters.preset", "none, sdk, thesis"});
}

// No preset named: the RealSense Viewer's defaults (issue 4), every field as filters.preset=sdk.
TEST(FiltersConfig, SdkPresetAndTheDefaultHaveEveryViewerDefault) {
  const Config sdk = load_config("", {"filters.preset=sdk"});
  EXPECT_EQ(sdk.filters_preset, FilterPreset::sdk);
  test::expect_sdk_preset(sdk.pipeline.filters);
  const Config defaults = load_config("", {});
  EXPECT_EQ(defaults.filters_preset, FilterPreset::sdk);
  test::expect_sdk_preset(defaults.pipeline.filters);
}

TEST(FiltersConfig, ThesisPresetHasEveryThesisSetting) {
  const Config thesis = load_config("", {"filters.preset=thesis"});
  EXPECT_EQ(thesis.filters_preset, FilterPreset::thesis);
  test::expect_thesis_preset(thesis.pipeline.filters);
}

TEST(FiltersConfig, OrderAndEnabled) {
  EXPECT_EQ(order_of({"filters.order=[spatial, threshold]"}), (std::vector<FilterBlock>{B::spatial, B::threshold}));
  EXPECT_EQ(order_of({"filters.preset=sdk", "filters.decimation.enabled=false"}),
            (std::vector<FilterBlock>{B::threshold, B::to_disparity, B::spatial, B::temporal, B::to_depth}));
  EXPECT_EQ(order_of({"filters.preset=none", "filters.hole_filling.enabled=true"}),
            (std::vector<FilterBlock>{B::hole_filling}));
  EXPECT_EQ(order_of({"filters.order=[threshold, spatial]", "filters.spatial.enabled=false"}),
            (std::vector<FilterBlock>{B::threshold}));
  expect_error({"filters.order=[threshold]", "filters.spatial.enabled=true"}, {"filters.spatial.enabled", "filters.order"});
  expect_error({"filters.order=[median]"}, {"filters.order", "unknown block 'median'"});
  expect_error({"filters.order=[to_depth]"}, {"filters.order", "to_depth must follow to_disparity"});
  expect_error({"filters.order=[to_disparity, decimation, to_depth]"}, {"filters.order", "decimation"});
}

TEST(FiltersConfig, OptionsAndTheSdkRanges) {
  const Config c = load_config("", {"filters.spatial.alpha=0.3", "filters.spatial.delta=50", "filters.temporal.alpha=0",
                                     "filters.threshold.max=16", "filters.hole_filling.enabled=true",
                                     "filters.hole_filling.mode=2"});
  EXPECT_EQ(c.pipeline.filters.spatial.alpha, 0.3F);
  EXPECT_EQ(c.pipeline.filters.spatial.delta, 50);
  EXPECT_EQ(c.pipeline.filters.temporal.alpha, 0.0F);
  EXPECT_EQ(c.pipeline.filters.threshold.max_m, 16.0F);
  EXPECT_EQ(c.pipeline.filters.hole_filling.mode, 2);
  expect_error({"filters.spatial.alpha=0.2"}, {"filters.spatial.alpha", "[0.25, 1]"});
  expect_error({"filters.spatial.delta=51"}, {"filters.spatial.delta", "[1, 50]"});
  expect_error({"filters.spatial.magnitude=0"}, {"filters.spatial.magnitude", "[1, 5]"});
  expect_error({"filters.spatial.holes_fill=6"}, {"filters.spatial.holes_fill", "[0, 5]"});
  expect_error({"filters.temporal.alpha=1.01"}, {"filters.temporal.alpha", "[0, 1]"});
  expect_error({"filters.temporal.delta=101"}, {"filters.temporal.delta", "[1, 100]"});
  expect_error({"filters.temporal.persistence=9"}, {"filters.temporal.persistence", "[0, 8]"});
  expect_error({"filters.decimation.magnitude=9"}, {"filters.decimation.magnitude", "[1, 8]"});
  expect_error({"filters.hole_filling.mode=3"}, {"filters.hole_filling.mode", "[0, 2]"});
  expect_error({"filters.threshold.max=16.5"}, {"filters.threshold.max", "[0, 16] m"});
  expect_error({"filters.threshold.min=2", "filters.threshold.max=1"}, {"filters.threshold.min", "max"});
  expect_error({"filters.spatial.beta=1"}, {"filters.spatial.beta"});
}

// A tuned option of a block that is not in the chain would be ignored: an error naming it
// (A3). The preset's own value is accepted, so that the effective configuration reads back.
TEST(FiltersConfig, OptionOfABlockOutsideTheChainIsAnError) {
  expect_error({"filters.preset=none", "filters.temporal.persistence=5"},
               {"filters.temporal.persistence", "not in the chain", "filters.preset none"});
  expect_error({"filters.hole_filling.mode=2"}, {"filters.hole_filling.mode", "hole_filling block"});  // sdk: no hole fill
  expect_error({"filters.spatial.enabled=false", "filters.spatial.alpha=0.3"}, {"filters.spatial.alpha"});
  const FilterChainParams none_defaults = filter_preset(FilterPreset::none);
  const Config same = load_config("", {"filters.preset=none", "filters.temporal.persistence=" +
                                                                  std::to_string(none_defaults.temporal.persistence)});
  EXPECT_TRUE(same.pipeline.filters.order.empty());
  const Config c = load_config("", {"filters.preset=none", "filters.temporal.enabled=true",
                                    "filters.temporal.persistence=5"});
  EXPECT_EQ(c.pipeline.filters.temporal.persistence, 5);
}

TEST(FiltersPipeline, EveryBlockIsTimedUnderItsName) {
  PipelineParams params;
  params.filters = filter_preset(FilterPreset::thesis);
  params.filters.order.insert(params.filters.order.begin(), B::threshold);
  params.background.frames = 5;
  Pipeline pipeline(params);
  Frame frame;
  frame.depth.resize(32, 24);
  std::fill(frame.depth.pixels.begin(), frame.depth.pixels.end(), uint16_t{1000});
  frame.intrinsics.width = 32;
  frame.intrinsics.height = 24;
  frame.intrinsics.fx = frame.intrinsics.fy = 30.0F;
  frame.stereo_baseline_mm = 50.0F;
  FrameResult result;
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  std::vector<std::string> stages;
  for (const StageTiming& timing : result.timings) stages.emplace_back(timing.stage);
  EXPECT_EQ(stages, (std::vector<std::string>{"threshold", "to_disparity", "spatial", "temporal", "to_depth", "background"}));
  frame.stereo_baseline_mm = 0.0F;  // no baseline: the blocks run on depth, no transforms
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  stages.clear();
  for (const StageTiming& timing : result.timings) stages.emplace_back(timing.stage);
  EXPECT_EQ(stages, (std::vector<std::string>{"threshold", "spatial", "temporal", "background"}));
}

}  // namespace
}  // namespace hrcsense
