// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulated D435's colour camera: flat per-object colours.
#pragma once

#include "hrcsense/types.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace hrcsense::sim_detail {

/// Writes the rgb8 image of a colour camera whose ray caster found object `ids` per pixel
/// (0: nothing): each pixel the flat colour `color_of_id[id]`. Reuses out's buffer.
void write_color(const std::vector<uint16_t>& ids, const std::vector<std::array<uint8_t, 3>>& color_of_id, int width,
                 int height, ColorImage& out);

}  // namespace hrcsense::sim_detail
