// SPDX-License-Identifier: Apache-2.0
// hrcsense — per-background tables of the foreground extractor: the background test solved
// once per pixel into a raw-depth threshold, and the flood fill's jump limit per raw depth.
#pragma once

#include "hrcsense/segmentation.hpp"

#include <cstdint>

namespace hrcsense::segmentation_detail {

// Neighbouring foreground pixels belong to one object unless their depths jump by
// max(kJumpMinM, kJumpSigmas · σ_model(z)) or more, at the farther of the two depths (a jump of
// exactly the limit splits them).
inline constexpr float kJumpMinM = 0.05F;
inline constexpr float kJumpSigmas = 4.0F;

/// The constants of the per-pixel background test, as the frame's camera gives them.
struct NearerTest {
  float depth_scale_m;  ///< metres per raw unit (> 0)
  float k_sigma;        ///< ForegroundParams::k_sigma (≥ 0)
  float k_model;        ///< k_sigma · σ_model(z) / z², metres⁻¹ (≥ 0; 0 without a baseline)
  float min_margin_m;   ///< ForegroundParams::min_margin_m
};

/// σ_model(z) / z² in metres⁻¹ for a camera with focal length `fx_px` and stereo baseline
/// `baseline_mm`; 0 when either is unknown (≤ 0), so that only the other margins apply.
float sigma_per_z2(float fx_px, float baseline_mm, float subpixel_rms_px);

/// The background test in float, exactly as the per-frame test used to evaluate it: raw depth
/// `raw` (> 0) is nearer than a known background of mean `mean_m` and spread `spread_m` by more
/// than max(k_sigma · spread, k_model · z², min_margin_m). Non-increasing in `raw` (the left
/// side grows with z, the margin too), which is what makes a threshold exact.
bool nearer_than_background(uint16_t raw, float mean_m, float spread_m, const NearerTest& test);

/// How many raw depths, counted from 1, pass nearer_than_background for this pixel: the pixel
/// is a candidate iff 1 ≤ raw ≤ returned value, i.e. iff uint16(raw − 1) < returned value.
/// Exact (the float test decides the boundary), whatever the rounding of the closed form.
uint16_t nearer_raw_count(float mean_m, float spread_m, const NearerTest& test);

/// Fills `count[i]` with nearer_raw_count() for every known pixel (mean > 0) and 0 elsewhere,
/// and `unknown[i]` with `unknown_state` where the background was never valid, 0 elsewhere.
void build_nearer_table(const BackgroundModel& background, const NearerTest& test, uint8_t unknown_state,
                        uint16_t* count, uint8_t* unknown);

/// Fills `limit[r]` for every raw depth r in 0..65535 with the flood fill's jump limit at r in
/// raw units, rounded up (for integer steps d: d < limit ⇔ d < ceil(limit)); `jump_per_z2` is
/// kJumpSigmas · σ_model(z) / z² in metres⁻¹. Non-decreasing in r.
void build_jump_limits(float depth_scale_m, float jump_per_z2, int32_t* limit);

}  // namespace hrcsense::segmentation_detail
