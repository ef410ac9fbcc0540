// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulated D435's sensor: true depth in, raw Z16 with stereo artefacts out.
#pragma once

#include "hrcsense/sim/sim.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>

namespace hrcsense::sim_detail {

/// Material bits in SimScratch::material_of_id.
inline constexpr uint8_t kDarkBit = 1;
inline constexpr uint8_t kShinyBit = 2;
inline constexpr uint8_t kLowTextureBit = 4;

/// Turns the noise-free depth of frame `index` into raw depth units, applying every effect of
/// docs/SIMULATOR.md that `p` enables. Reads scratch.object_ids and scratch.material_of_id
/// (filled by the ray caster), writes scratch.disparity_px, scratch.hidden and, once per seed,
/// scratch.correlated_px. `z_m` is Z per pixel, +inf where nothing was hit.
/// Deterministic: the output depends only on (p, fx_px, index, z_m, object ids).
void write_sensor_depth(const SimParams& p, float fx_px, int64_t index, const float* z_m, SimScratch& scratch,
                        DepthImage& depth);

/// The minimum range in metres that `p` implies for focal length fx_px (0: none).
float sensor_min_range_m(const SimParams& p, float fx_px);

}  // namespace hrcsense::sim_detail
