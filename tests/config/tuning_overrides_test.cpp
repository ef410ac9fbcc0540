// SPDX-License-Identifier: Apache-2.0
// tuning_overrides: what hrcsense-view's "save tuned parameters" writes must read back as the
// tuned pipeline, through the same parser as any configuration file.

#include "config_test_util.hpp"

#include <fstream>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

TEST(TuningOverrides, NameEveryTunedKeyOfTheChain) {
  const Config config = load_config("", {"filters.preset=thesis"});
  const std::vector<std::string> sets = tuning_overrides(tuning_of(config.pipeline));
  const auto has = [&](const std::string& prefix) {
    for (const std::string& set : sets) {
      if (set.rfind(prefix, 0) == 0) return true;
    }
    return false;
  };
  for (const FilterBlock block : config.pipeline.filters.order) {
    if (block == FilterBlock::to_disparity || block == FilterBlock::to_depth) continue;  // no options
    EXPECT_TRUE(has(std::string("filters.") + filter_block_name(block) + ".")) << filter_block_name(block);
  }
  EXPECT_TRUE(has("foreground.k_sigma="));
  EXPECT_TRUE(has("foreground.min_margin_m="));
  EXPECT_TRUE(has("foreground.min_object_mm="));
  EXPECT_TRUE(has("proximity.backend="));
}

TEST(TuningOverrides, ReadBackAsTheTunedValuesAndSaveAsAConfigThatLoads) {
  test::TempDir dir;
  const std::string base = dir.write("cell.yaml", "filters:\n  preset: sdk\nsafety:\n  slow_distance_m: 1.25\n");
  const Config config = load_config(base, {});
  LiveTuning tuning = tuning_of(config.pipeline);
  tuning.filters.spatial.alpha = 0.7F;
  tuning.filters.spatial.delta = 31;
  tuning.filters.temporal.alpha = 0.15F;
  tuning.filters.temporal.persistence = 5;
  tuning.foreground.k_sigma = 3.5F;
  tuning.foreground.min_margin_m = 0.03F;
  tuning.foreground.min_object_mm = 55.0F;
  tuning.backend = ProximityBackend::kdtree;

  const Config tuned = load_config(base, tuning_overrides(tuning));
  EXPECT_EQ(tuned.pipeline.filters.spatial.alpha, 0.7F);
  EXPECT_EQ(tuned.pipeline.filters.spatial.delta, 31);
  EXPECT_EQ(tuned.pipeline.filters.temporal.alpha, 0.15F);
  EXPECT_EQ(tuned.pipeline.filters.temporal.persistence, 5);
  EXPECT_EQ(tuned.pipeline.foreground.k_sigma, 3.5F);
  EXPECT_EQ(tuned.pipeline.foreground.min_margin_m, 0.03F);
  EXPECT_EQ(tuned.pipeline.foreground.min_object_mm, 55.0F);
  EXPECT_EQ(tuned.pipeline.backend, ProximityBackend::kdtree);
  EXPECT_EQ(tuned.pipeline.safety.slow_distance_m, 1.25F);  // what was not tuned stays
  EXPECT_EQ(tuned.pipeline.filters.order, config.pipeline.filters.order);

  // The effective configuration, saved, is a file `hrcsense run --config` reads to the same.
  const std::string saved = dir.path() + "/tuned.yaml";
  std::ofstream(saved) << tuned.canonical_yaml;
  const Config reloaded = load_config(saved, {});
  EXPECT_EQ(config_hash(reloaded), config_hash(tuned));
  EXPECT_EQ(reloaded.pipeline.filters.spatial.alpha, 0.7F);
  EXPECT_EQ(reloaded.pipeline.backend, ProximityBackend::kdtree);
}

TEST(TuningOverrides, OutOfRangeValuesAreRefusedByTheParser) {
  const Config config = load_config("", {});
  LiveTuning tuning = tuning_of(config.pipeline);
  tuning.filters.spatial.alpha = 0.1F;  // the SDK's range is [0.25, 1]
  test::expect_config_error("", tuning_overrides(tuning), {"filters.spatial.alpha"});
}

}  // namespace
}  // namespace hrcsense
