// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the chain: block names, presets, order checks and FilterChain.
#include "hrcsense/filters.hpp"

#include <algorithm>

namespace hrcsense {

bool has_block(const std::vector<FilterBlock>& order, FilterBlock block) {
  return std::find(order.begin(), order.end(), block) != order.end();
}

const char* filter_block_name(FilterBlock block) {
  switch (block) {
    case FilterBlock::threshold: return "threshold";
    case FilterBlock::decimation: return "decimation";
    case FilterBlock::to_disparity: return "to_disparity";
    case FilterBlock::spatial: return "spatial";
    case FilterBlock::temporal: return "temporal";
    case FilterBlock::to_depth: return "to_depth";
    case FilterBlock::hole_filling: return "hole_filling";
  }
  return "unknown";
}

std::optional<FilterBlock> filter_block_from_name(std::string_view name) {
  for (const FilterBlock block : kFilterBlocks) {
    if (name == filter_block_name(block)) return block;
  }
  return std::nullopt;
}

const char* filter_preset_name(FilterPreset preset) {
  switch (preset) {
    case FilterPreset::none: return "none";
    case FilterPreset::sdk: return "sdk";
    case FilterPreset::thesis: return "thesis";
  }
  return "unknown";
}

FilterChainParams filter_preset(FilterPreset preset) {
  FilterChainParams chain;
  switch (preset) {
    case FilterPreset::none: break;
    case FilterPreset::sdk:
      // The RealSense Viewer's defaults: everything on except hole filling, in the order of
      // specs/depth-filters.md §1 (threshold first).
      chain.order = {FilterBlock::threshold, FilterBlock::decimation, FilterBlock::to_disparity,
                     FilterBlock::spatial,   FilterBlock::temporal,   FilterBlock::to_depth};
      break;
    case FilterPreset::thesis:
      // The 2020 thesis: spatial α 0.4, δ 20, magnitude 2; temporal persistence 3, α 0.4, δ 20;
      // no decimation. The thesis does not say which domain it used; we use disparity.
      chain.order = {FilterBlock::to_disparity, FilterBlock::spatial, FilterBlock::temporal, FilterBlock::to_depth};
      chain.spatial.alpha = 0.4F;
      chain.spatial.delta = 20;
      chain.spatial.magnitude = 2;
      chain.temporal = TemporalParams{0.4F, 20, 3};
      break;
  }
  return chain;
}

Intrinsics filtered_intrinsics(const FilterChainParams& params, const Intrinsics& source) {
  if (!has_block(params.order, FilterBlock::decimation)) {
    return source;
  }
  // Decimating an empty image of the source's size keeps one definition of the output size
  // (padding included); called once per run, so the allocation does not matter.
  DepthImage in, out;
  in.resize(source.width, source.height);
  Intrinsics result;
  decimate(params.decimation, in, source, out, result);
  return result;
}

const char* filter_domain(const FilterChainParams& params, float stereo_baseline_mm) {
  if (params.order.empty()) return "none";
  const bool wants_disparity =
      has_block(params.order, FilterBlock::to_disparity);
  return wants_disparity && stereo_baseline_mm > 0.0F ? "disparity" : "depth";
}

std::string check_filter_order(const std::vector<FilterBlock>& order) {
  bool seen[kFilterBlocks.size()] = {};
  bool in_disparity = false;
  for (const FilterBlock block : order) {
    const auto index = static_cast<size_t>(block);
    const std::string name = filter_block_name(block);
    if (seen[index]) return name + " appears twice";
    seen[index] = true;
    if (block == FilterBlock::to_disparity) in_disparity = true;
    if (block == FilterBlock::to_depth) {
      if (!in_disparity) return "to_depth must follow to_disparity";
      in_disparity = false;
    }
    if (in_disparity && (block == FilterBlock::threshold || block == FilterBlock::decimation)) {
      return name + " works on depth only; put it before to_disparity or after to_depth";
    }
  }
  if (in_disparity) return "to_disparity must be followed by to_depth";
  return {};
}

void FilterChain::start(const Frame& in, Frame& out) {
  out.index = in.index;
  out.timestamp_ns = in.timestamp_ns;
  out.intrinsics = in.intrinsics;
  out.stereo_baseline_mm = in.stereo_baseline_mm;
  out.depth.depth_scale_m = in.depth.depth_scale_m;
  out.depth.resize(in.depth.width, in.depth.height);
  std::copy(in.depth.pixels.begin(), in.depth.pixels.end(), out.depth.pixels.begin());
  out.color.reset();
  out.truth.reset();

  // Without a baseline the transforms are skipped and the blocks between them work on depth.
  const bool wants_disparity =
      has_block(params.order, FilterBlock::to_disparity);
  disparity_domain_ = wants_disparity && in.stereo_baseline_mm > 0.0F;
  planned_.clear();
  for (const FilterBlock block : params.order) {
    const bool transform = block == FilterBlock::to_disparity || block == FilterBlock::to_depth;
    if (transform && !disparity_domain_) continue;
    planned_.push_back(block);
  }
  in_disparity_ = false;
}

void FilterChain::run_block(size_t i, Frame& frame) {
  switch (planned_[i]) {
    case FilterBlock::threshold:
      apply_threshold(params.threshold, frame.depth);
      break;
    case FilterBlock::decimation: {
      Intrinsics intrinsics;
      decimate(params.decimation, frame.depth, frame.intrinsics, decimated_, intrinsics);
      frame.depth = decimated_;  // copy-assignment reuses frame.depth's capacity
      frame.intrinsics = intrinsics;
      break;
    }
    case FilterBlock::to_disparity:
      factor_ = disparity_factor(frame.stereo_baseline_mm, frame.intrinsics.fx, frame.depth.depth_scale_m);
      depth_to_disparity(frame.depth, factor_, disparity_);
      in_disparity_ = true;
      break;
    case FilterBlock::spatial:
      if (in_disparity_) {
        spatial_filter(params.spatial, disparity_, spatial_scratch_);
      } else {
        spatial_filter(params.spatial, frame.depth, spatial_scratch_);
      }
      break;
    case FilterBlock::temporal:
      temporal_.params = params.temporal;
      if (in_disparity_) {
        temporal_.apply(disparity_);
      } else {
        temporal_.apply(frame.depth);
      }
      break;
    case FilterBlock::to_depth:
      disparity_to_depth(disparity_, factor_, frame.depth);
      in_disparity_ = false;
      break;
    case FilterBlock::hole_filling:
      if (in_disparity_) {
        fill_holes(params.hole_filling, disparity_);
      } else {
        fill_holes(params.hole_filling, frame.depth);
      }
      break;
  }
}

void FilterChain::process(const Frame& in, Frame& out) {
  start(in, out);
  for (size_t i = 0; i < block_count(); ++i) run_block(i, out);
}

}  // namespace hrcsense
