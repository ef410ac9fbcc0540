// SPDX-License-Identifier: Apache-2.0
// hrcsense — depth filters that behave bit for bit like the RealSense SDK's processing blocks
// (specs/depth-filters.md): threshold, decimation, depth↔disparity, spatial, temporal, hole filling.
#pragma once

#include "hrcsense/types.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hrcsense {

/// A disparity image as the SDK's DISPARITY32: float, in 1/32-pixel units; 0 means "no data".
struct DisparityImage {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;  ///< row-major, width * height

  /// Sets the size; keeps the buffer's capacity, so reuse does not allocate.
  void resize(int w, int h) {
    width = w;
    height = h;
    pixels.resize(static_cast<size_t>(w) * h);
  }
};

// ---- instruction set ----------------------------------------------------------------------

/// Which instruction set the fast filter loops may use. Every choice gives the same bits.
enum class FilterIsa { best, portable };
/// `best` (the default) lets the filters take AVX2 loops where the CPU has them; `portable`
/// forces the baseline SSE2 (or plain C++) loops for the whole process. A test hook: tests run
/// both against the plain references. Not meant to be switched while filters run.
void set_filter_isa(FilterIsa isa);
/// "avx2", "sse2" or "scalar": the loops the filters take now.
const char* filter_isa_name();

// ---- threshold (spec §3) ------------------------------------------------------------------

/// Keeps depths in [min_m, max_m], compared in float32 as the SDK does (so max 1.5 m drops
/// raw 1500 at 1 mm units: 1500 · 0.001f > 1.5f). Ranges: both in [0, 16] m.
struct ThresholdParams {
  float min_m = 0.1F;  ///< metres, inclusive
  float max_m = 4.0F;  ///< metres, inclusive
};
/// Writes 0 where the depth is outside [min_m, max_m]; in place.
void apply_threshold(const ThresholdParams& params, DepthImage& depth);

// ---- decimation (spec §4) -----------------------------------------------------------------

/// Block-wise down-sampling by `magnitude` (1–8): lower median of the non-zero pixels for 2–3,
/// truncated integer mean of them otherwise. The output is zero-padded to multiples of 4.
struct DecimationParams {
  int magnitude = 2;  ///< scale factor s, 1–8
};
/// Decimates `in` into `out` (reused) and scales the intrinsics as the SDK does (fx/s, ppx/s,
/// no half-pixel correction; width/height the padded size). Precondition: `out` is not `in`.
void decimate(const DecimationParams& params, const DepthImage& in, const Intrinsics& in_intrinsics,
              DepthImage& out, Intrinsics& out_intrinsics);

// ---- depth ↔ disparity (spec §2) ----------------------------------------------------------

/// The SDK's conversion factor F = baseline_m · fx · 32 / depth_scale_m in float32, with fx
/// of the frame being converted (after decimation, the decimated fx). Disparity = F / raw.
float disparity_factor(float stereo_baseline_mm, float fx_px, float depth_scale_m);
/// disparity = F / raw for every non-zero raw, else 0; `out` is resized (no allocation on reuse).
void depth_to_disparity(const DepthImage& in, float factor, DisparityImage& out);
/// raw = uint16(F / disparity + 0.5) for every normal disparity, else 0. Keeps out.depth_scale_m.
void disparity_to_depth(const DisparityImage& in, float factor, DepthImage& out);

// ---- spatial (spec §5) --------------------------------------------------------------------

/// The SDK's edge-preserving spatial filter. The depth and disparity domains run different
/// code, as in the SDK; δ is in the raw units of the image in both (mm, or 1/32 px).
struct SpatialParams {
  float alpha = 0.5F;  ///< weight of the current pixel, 0.25–1 (1: no smoothing)
  int delta = 20;      ///< edge threshold in raw units of the image, 1–50
  int magnitude = 2;   ///< iterations of horizontal + vertical passes, 1–5
  int holes_fill = 0;  ///< 0 off; k = 1–5 gives radius 2^k (5: 255), filling radius − 1 pixels
};
/// The hole-filling radius of `holes_fill` (0, 2, 4, 8, 16, 255).
int spatial_holes_radius(int holes_fill);
/// The spatial filter's working memory (a transposed strip of rows, one line of state), owned
/// by the caller and reused so that filtering does not allocate after the first frame of a
/// size. Carries no result from one call to the next; one scratch per thread.
struct SpatialScratch {
  std::vector<uint16_t> depth_strip, depth_fill;
  std::vector<float> disparity_strip, disparity_line;
};
/// Filters depth in place (the SDK's Z16 path: rounding, hole filling inside the passes).
void spatial_filter(const SpatialParams& params, DepthImage& depth, SpatialScratch& scratch);
/// Filters disparity in place (the SDK's float path: hole filling once after the passes).
void spatial_filter(const SpatialParams& params, DisparityImage& disparity, SpatialScratch& scratch);
/// The same with a scratch of its own: allocates on every call (tests, one-off use).
void spatial_filter(const SpatialParams& params, DepthImage& depth);
void spatial_filter(const SpatialParams& params, DisparityImage& disparity);

// ---- temporal (spec §6) -------------------------------------------------------------------

/// The SDK's temporal filter: exponential smoothing across frames and hole filling from an
/// 8-frame validity history.
struct TemporalParams {
  float alpha = 0.4F;   ///< weight of the current frame, 0–1
  int delta = 20;       ///< agreement threshold in raw units (strict <), 1–100
  int persistence = 3;  ///< 0 off, 1 valid 8/8, 2 2/last 3, 3 2/last 4, 4 2/8, 5 1/last 2, 6 1/last 5, 7 1/8, 8 always
};

/// Holds the temporal filter's state. The state is reset (as on a new stream) when the
/// parameters, the size or the domain change, or on reset(); unlike the SDK, every parameter
/// change therefore takes effect on the next frame.
class TemporalFilter {
 public:
  TemporalParams params;
  /// Filters one depth frame in place; results truncate to integers as the SDK's do.
  void apply(DepthImage& depth);
  /// Filters one disparity frame in place.
  void apply(DisparityImage& disparity);
  /// Forgets every pixel's history (the next frame starts a new sequence).
  void reset();

 private:
  template <typename T>
  void apply_to(T* pixels, int width, int height, bool disparity);

  std::vector<uint16_t> last_depth_;
  std::vector<float> last_disparity_;
  std::vector<uint8_t> history_;
  std::array<uint8_t, 256> fill_lut_{};  ///< bit k: fill allowed at phase k for this history
  TemporalParams state_params_;          ///< the parameters the state was built with
  int width_ = 0, height_ = 0;
  bool disparity_ = false;
  bool has_state_ = false;
  int phase_ = 0;  ///< 0–7, advances after every frame
};

// ---- hole filling (spec §7) ---------------------------------------------------------------

/// The SDK's hole-filling filter: 0 fill from left, 1 farthest from around (largest value; in
/// the disparity domain that is the nearest surface), 2 nearest from around (starts from the
/// pixel above even when it is empty, as the SDK).
struct HoleFillingParams {
  int mode = 1;  ///< 0, 1 or 2
};
/// Fills holes in place.
void fill_holes(const HoleFillingParams& params, DepthImage& depth);
/// Fills holes in place; empty means the bit pattern of +0.0.
void fill_holes(const HoleFillingParams& params, DisparityImage& disparity);

// ---- the chain ----------------------------------------------------------------------------

/// The blocks of a chain, named as in the goldens' cases.json and the configuration.
enum class FilterBlock { threshold, decimation, to_disparity, spatial, temporal, to_depth, hole_filling };
/// Every block, in hrcsense's documented order (threshold first).
inline constexpr std::array<FilterBlock, 7> kFilterBlocks{
    FilterBlock::threshold, FilterBlock::decimation, FilterBlock::to_disparity, FilterBlock::spatial,
    FilterBlock::temporal,  FilterBlock::to_depth,   FilterBlock::hole_filling};
/// "threshold", "decimation", ... (static strings, used as timing keys).
const char* filter_block_name(FilterBlock block);
std::optional<FilterBlock> filter_block_from_name(std::string_view name);

/// What the chain runs: the blocks in order and each block's parameters.
struct FilterChainParams {
  std::vector<FilterBlock> order;  ///< empty: no filtering. Each block at most once.
  ThresholdParams threshold;
  DecimationParams decimation;
  SpatialParams spatial;
  TemporalParams temporal;
  HoleFillingParams hole_filling;
};

/// `filters.preset`: the chain a configuration starts from.
enum class FilterPreset {
  none,    ///< no filters
  sdk,     ///< the RealSense Viewer's defaults
  thesis,  ///< the 2020 thesis's settings
};
inline constexpr FilterPreset kFilterPresets[] = {FilterPreset::none, FilterPreset::sdk, FilterPreset::thesis};
/// The configuration's name of a preset (static string): "none", "sdk" or "thesis".
const char* filter_preset_name(FilterPreset preset);
/// The preset's chain: its order and its options.
FilterChainParams filter_preset(FilterPreset preset);

/// The intrinsics of the chain's output for a source with intrinsics `source`: decimation
/// scales them, the other blocks keep them. This is the resolution the pipeline learns its
/// background at and the image that Contact::pixel indexes.
Intrinsics filtered_intrinsics(const FilterChainParams& params, const Intrinsics& source);

/// Where the chain's smoothing blocks run for a source with this stereo baseline: "none" (empty
/// chain), "disparity", or "depth" (no to_disparity in the order, or no baseline to convert with).
const char* filter_domain(const FilterChainParams& params, float stereo_baseline_mm);

/// Why `order` cannot run, or empty when it can: a block twice, threshold or decimation
/// inside the disparity domain, to_depth without to_disparity before it or the reverse.
std::string check_filter_order(const std::vector<FilterBlock>& order);

/// Whether `block` is in `order`.
bool has_block(const std::vector<FilterBlock>& order, FilterBlock block);

/// Runs a chain on frames. Without a stereo baseline (Frame::stereo_baseline_mm 0) the
/// disparity transforms are skipped and the blocks between them run in the depth domain.
/// Parameters are read at every frame, so a change takes effect on the next frame.
class FilterChain {
 public:
  FilterChainParams params;  ///< precondition: check_filter_order(params.order) is empty

  /// Copies `in`'s depth, intrinsics, index, timestamp and baseline into `out` (reusing its
  /// buffers; colour and ground truth are not copied) and plans this frame's blocks.
  void start(const Frame& in, Frame& out);
  /// Blocks planned by the last start(), in order.
  size_t block_count() const { return planned_.size(); }
  FilterBlock block(size_t i) const { return planned_[i]; }
  /// Runs planned block `i` on `frame` (the `out` of start()); blocks run in order.
  void run_block(size_t i, Frame& frame);
  /// start() and every block.
  void process(const Frame& in, Frame& out);
  /// Whether the last frame went through the disparity domain.
  bool disparity_domain() const { return disparity_domain_; }
  /// The disparity image between to_disparity and to_depth (for taps and tests).
  const DisparityImage& disparity() const { return disparity_; }
  /// Resets the temporal filter.
  void reset() { temporal_.reset(); }

 private:
  std::vector<FilterBlock> planned_;
  bool disparity_domain_ = false;
  bool in_disparity_ = false;
  float factor_ = 0.0F;
  DisparityImage disparity_;
  DepthImage decimated_;
  SpatialScratch spatial_scratch_;
  TemporalFilter temporal_;
};

}  // namespace hrcsense
