// SPDX-License-Identifier: Apache-2.0
// hrcsense config — the depth filter chain: filters.preset, filters.order and
// filters.<block>.<option> with the RealSense SDK's option ranges (specs/depth-filters.md).
#include "key_reader.hpp"

#include "hrcsense/number_text.hpp"

#include <algorithm>
#include <string>

namespace hrcsense::config_detail {
namespace {

// A float option with the SDK's inclusive range; the error names the key and the range.
void ranged(KeyReader& r, const std::string& key, float& value, float min, float max, const char* range) {
  r.number(key, value, Bound::any);
  if (!(value >= min && value <= max)) {
    r.fail(key, float_text(value) + " is outside the SDK's range " + range);
  }
}

std::vector<FilterBlock> read_order(KeyReader& r, const std::vector<FilterBlock>& preset_order, bool& given) {
  const YAML::Node node = r.raw("filters.order");
  given = node.IsDefined() && !node.IsNull();
  std::vector<FilterBlock> order = preset_order;
  if (given) {
    if (!node.IsSequence()) r.fail("filters.order", "expected a list of block names, e.g. [threshold, spatial]");
    order.clear();
    for (const YAML::Node& item : node) {
      const auto block = item.IsScalar() ? filter_block_from_name(item.Scalar()) : std::nullopt;
      if (!block) {
        r.fail("filters.order", "unknown block '" + (item.IsScalar() ? item.Scalar() : std::string("?")) +
                                    "'; expected threshold, decimation, to_disparity, spatial, temporal, "
                                    "to_depth or hole_filling");
      }
      order.push_back(*block);
    }
  }
  return order;
}

// `enabled` switches a block of the order off; without filters.order it can also switch a
// block on, in the documented position.
std::vector<FilterBlock> apply_enabled(KeyReader& r, const std::vector<FilterBlock>& order, bool order_given) {
  bool enabled[kFilterBlocks.size()] = {};
  for (const FilterBlock block : kFilterBlocks) {
    const std::string key = std::string("filters.") + filter_block_name(block) + ".enabled";
    bool& on = enabled[static_cast<size_t>(block)];
    on = has_block(order, block);
    r.flag(key, on);
    if (on && order_given && !has_block(order, block)) r.fail(key, "the block is not in filters.order; add it there");
  }
  std::vector<FilterBlock> result;
  for (const FilterBlock block : order_given ? order : std::vector<FilterBlock>(kFilterBlocks.begin(), kFilterBlocks.end())) {
    if (enabled[static_cast<size_t>(block)]) result.push_back(block);
  }
  return result;
}

void read_options(KeyReader& r, FilterChainParams& f) {
  ranged(r, "filters.threshold.min", f.threshold.min_m, 0.0F, 16.0F, "[0, 16] m");
  ranged(r, "filters.threshold.max", f.threshold.max_m, 0.0F, 16.0F, "[0, 16] m");
  if (f.threshold.min_m > f.threshold.max_m) {
    r.fail_pair("filters.threshold.min", "filters.threshold.max",
                "expected min <= max, got " + float_text(f.threshold.min_m) + " m > " + float_text(f.threshold.max_m) + " m");
  }
  r.integer("filters.decimation.magnitude", f.decimation.magnitude, 1, 8);
  ranged(r, "filters.spatial.alpha", f.spatial.alpha, 0.25F, 1.0F, "[0.25, 1]");
  r.integer("filters.spatial.delta", f.spatial.delta, 1, 50);
  r.integer("filters.spatial.magnitude", f.spatial.magnitude, 1, 5);
  r.integer("filters.spatial.holes_fill", f.spatial.holes_fill, 0, 5);
  ranged(r, "filters.temporal.alpha", f.temporal.alpha, 0.0F, 1.0F, "[0, 1]");
  r.integer("filters.temporal.delta", f.temporal.delta, 1, 100);
  r.integer("filters.temporal.persistence", f.temporal.persistence, 0, 8);
  r.integer("filters.hole_filling.mode", f.hole_filling.mode, 0, 2);
}

// Every option with its block: an option tuned for a block that is not in the chain would be
// silently ignored (temporal.persistence on the `none` preset), so a value other than the
// preset's is an error. The preset's own value is accepted, so that the effective
// configuration (which spells out every option) reads back.
using OptionValue = double (*)(const FilterChainParams&);
struct BlockOption {
  FilterBlock block;
  const char* key;
  OptionValue value;
};
const BlockOption kBlockOptions[] = {
    {FilterBlock::threshold, "filters.threshold.min", [](const FilterChainParams& f) -> double { return f.threshold.min_m; }},
    {FilterBlock::threshold, "filters.threshold.max", [](const FilterChainParams& f) -> double { return f.threshold.max_m; }},
    {FilterBlock::decimation, "filters.decimation.magnitude",
     [](const FilterChainParams& f) -> double { return f.decimation.magnitude; }},
    {FilterBlock::spatial, "filters.spatial.alpha", [](const FilterChainParams& f) -> double { return f.spatial.alpha; }},
    {FilterBlock::spatial, "filters.spatial.delta", [](const FilterChainParams& f) -> double { return f.spatial.delta; }},
    {FilterBlock::spatial, "filters.spatial.magnitude",
     [](const FilterChainParams& f) -> double { return f.spatial.magnitude; }},
    {FilterBlock::spatial, "filters.spatial.holes_fill",
     [](const FilterChainParams& f) -> double { return f.spatial.holes_fill; }},
    {FilterBlock::temporal, "filters.temporal.alpha", [](const FilterChainParams& f) -> double { return f.temporal.alpha; }},
    {FilterBlock::temporal, "filters.temporal.delta", [](const FilterChainParams& f) -> double { return f.temporal.delta; }},
    {FilterBlock::temporal, "filters.temporal.persistence",
     [](const FilterChainParams& f) -> double { return f.temporal.persistence; }},
    {FilterBlock::hole_filling, "filters.hole_filling.mode",
     [](const FilterChainParams& f) -> double { return f.hole_filling.mode; }},
};

void refuse_options_outside_the_chain(KeyReader& r, const Config& c, const FilterChainParams& preset) {
  const FilterChainParams& f = c.pipeline.filters;
  for (const BlockOption& option : kBlockOptions) {
    if (has_block(f.order, option.block) || option.value(f) == option.value(preset)) continue;
    r.fail(option.key, std::string("the ") + filter_block_name(option.block) +
                           " block is not in the chain (filters.preset " + filter_preset_name(c.filters_preset) +
                           "), so this option would be ignored; add the block to filters.order or remove the option");
  }
}

}  // namespace

void read_filters(KeyReader& r, Config& c) {
  // Without filters.preset the default of Config::filters_preset stands: "sdk", the chain a
  // RealSense Viewer user runs, so that settings tuned there carry over unchanged.
  r.choice("filters.preset", c.filters_preset, kFilterPresets, filter_preset_name);
  FilterChainParams& f = c.pipeline.filters;
  f = filter_preset(c.filters_preset);
  bool order_given = false;
  const std::vector<FilterBlock> order = read_order(r, f.order, order_given);
  f.order = apply_enabled(r, order, order_given);
  const std::string problem = check_filter_order(f.order);
  if (!problem.empty()) r.fail("filters.order", problem);
  YAML::Node effective(YAML::NodeType::Sequence);
  for (const FilterBlock block : f.order) effective.push_back(filter_block_name(block));
  r.set_effective("filters.order", effective);
  const FilterChainParams preset = f;
  read_options(r, f);
  refuse_options_outside_the_chain(r, c, preset);
}

}  // namespace hrcsense::config_detail

namespace hrcsense {

std::vector<std::string> tuning_overrides(const LiveTuning& tuning) {
  const auto entry = [](const char* key, double value) { return std::string(key) + "=" + float_digits_text(value); };
  std::vector<std::string> sets;
  for (const config_detail::BlockOption& option : config_detail::kBlockOptions) {
    // Options of blocks outside the chain are refused by read_filters (they would be ignored).
    if (has_block(tuning.filters.order, option.block)) sets.push_back(entry(option.key, option.value(tuning.filters)));
  }
  sets.push_back(entry("foreground.k_sigma", tuning.foreground.k_sigma));
  sets.push_back(entry("foreground.min_margin_m", tuning.foreground.min_margin_m));
  sets.push_back(entry("foreground.min_object_mm", tuning.foreground.min_object_mm));
  sets.push_back(std::string("proximity.backend=") + proximity_backend_name(tuning.backend));
  return sets;
}

}  // namespace hrcsense
