// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulated sensor model (specs/d435-sensor-model.md §3–4, and the structured-light
// camera of docs/SIMULATOR.md): visibility from the right imager (or projector), working range,
// dropouts, flying pixels, edge flicker, disparity noise, quantisation.

#include "sim_sensor.hpp"

#include "sim_geometry.hpp"
#include "sim_noise.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

namespace hrcsense::sim_detail {
namespace {

constexpr uint64_t kGolden = 0x9E3779B97F4A7C15ULL;
// Salts that give each random effect its own stream from the one seed.
constexpr uint64_t kFixedSalt = 0x5DEECE66DULL;
constexpr uint64_t kMaterialSalt = 0xC2B2AE3D27D4EB4FULL;
constexpr uint64_t kSpeckleSalt = 0x165667B19E3779F9ULL;
constexpr uint64_t kCorrelatedSalt = 0x27D4EB2F165667C5ULL;
constexpr uint64_t kFlickerSalt = 0x94D049BB133111EBULL;
constexpr uint64_t kRangeSalt = 0xBF58476D1CE4E5B9ULL;

/// A uniform in [0, 1) from 24 bits of `bits` starting at `shift`.
inline float unit24(uint64_t bits, int shift) {
  return static_cast<float>((bits >> shift) & 0xFFFFFFU) * (1.0F / 16777216.0F);
}

/// Noise-free disparity d = fx·B / Z per pixel (0 where nothing was hit).
void compute_disparity(const float* z_m, float fxb_px_m, size_t n, float* disparity_px) {
  for (size_t i = 0; i < n; ++i) {
    // Hits have z > 0 and misses +inf, which gives 0. No select: GCC keeps float selects
    // as branches (trapping math), and this loop should vectorise.
    disparity_px[i] = fxb_px_m / std::max(std::numeric_limits<float>::min(), z_m[i]);
  }
}

/// Marks pixels that have no depth for geometric reasons. The depth image is the left
/// imager's; the right imager sits at +B along x, rows rectified, so a point at left column u
/// with disparity d appears at right column x_r = u − d. It is outside the right image when
/// x_r < −0.5 (the left band, first fx·B/Z columns). It is hidden from the right imager when a
/// pixel further right in the same row lands at or left of x_r: that pixel's point is nearer
/// and lies on the right camera's ray to this one. (Surfaces hidden in both views cast such a
/// shadow through the surface that hides them, so scanning the visible pixels is exact.)
/// Outside the working range (disparity above max_disparity_px or below min_disparity_px)
/// there is no depth either.
void mark_hidden(const SimParams& p, float max_disparity_px, float min_disparity_px, int width, int height,
                 const float* disparity_px, uint8_t* hidden) {
  // A step smaller than this is rounding, not occlusion: x_r grows by (1 − ∂d/∂u) per column,
  // which is > 0 for every surface the right imager sees at more than grazing incidence.
  constexpr float kEpsPx = 1e-3F;
  // The running minimum of x_r from the right is a serial chain per row: four rows at once so
  // that their chains overlap in the pipeline, over chunks of columns whose minima are kept so
  // that the tests then run along the row, branch-free, and vectorise. Misses (d = 0, x_r = u)
  // may join the minimum: x_r of a miss right of a hit exceeds the hit's own, so it never
  // makes the hit look shadowed.
  constexpr int kRows = 4;
  constexpr int kChunk = 256;
  const float band_limit = p.left_band ? -0.5F : -std::numeric_limits<float>::infinity();
  const float shadow_eps = p.occlusion_shadows ? kEpsPx : std::numeric_limits<float>::infinity();
  std::array<float, kRows * kChunk> min_right{};  // per row of the group and column of the chunk
  for (int v0 = 0; v0 < height; v0 += kRows) {
    const int rows = std::min(kRows, height - v0);
    std::array<const float*, kRows> d_row{};
    for (int k = 0; k < kRows; ++k) {
      // A short last group repeats its last row, so that the chain loop has a fixed count.
      d_row[k] = disparity_px + static_cast<size_t>(v0 + std::min(k, rows - 1)) * width;
    }
    std::array<float, kRows> running{};
    running.fill(std::numeric_limits<float>::infinity());
    for (int end = width; end > 0; end -= kChunk) {
      const int begin = std::max(0, end - kChunk);
      for (int u = end - 1; u >= begin; --u) {
        const auto column = static_cast<float>(u);
        for (int k = 0; k < kRows; ++k) {
          min_right[static_cast<size_t>(k * kChunk + (u - begin))] = running[k];
          running[k] = std::min(running[k], column - d_row[k][u]);
        }
      }
      for (int k = 0; k < rows; ++k) {
        const float* d = d_row[k];
        const float* m = min_right.data() + static_cast<size_t>(k * kChunk);  // column begin + j at m[j]
        uint8_t* out = hidden + static_cast<size_t>(v0 + k) * width;
        for (int u = begin; u < end; ++u) {
          const float xr = static_cast<float>(u) - d[u];
          // Bitwise, not ||: short-circuits would be branches.
          const int hit = d[u] > 0.0F;
          const int outside = xr < band_limit;
          const int shadowed = xr > m[u - begin] + shadow_eps;
          const int too_near = d[u] > max_disparity_px;
          const int too_far = d[u] < min_disparity_px;
          out[u] = static_cast<uint8_t>(hit & (outside | shadowed | too_near | too_far));
        }
      }
    }
  }
}

/// A smooth, zero-mean disparity error fixed per seed: Gaussian values on a grid of
/// `correlated_cell_px`, bilinearly interpolated. Computed only when the key changes.
void ensure_correlated(const SimParams& p, int width, int height, SimScratch& scratch) {
  const size_t n = static_cast<size_t>(width) * height;
  if (!(p.correlated_noise_px > 0.0F)) return;
  const int cell = std::max(2, p.correlated_cell_px);
  uint64_t key = mix64(p.seed ^ kCorrelatedSalt);
  key = mix64(key ^ (static_cast<uint64_t>(cell) << 32) ^ static_cast<uint64_t>(width) * 65536U ^
              static_cast<uint64_t>(height));
  uint32_t sigma_bits = 0;
  static_assert(sizeof sigma_bits == sizeof p.correlated_noise_px);
  std::copy_n(reinterpret_cast<const char*>(&p.correlated_noise_px), 4, reinterpret_cast<char*>(&sigma_bits));
  key = mix64(key ^ sigma_bits);
  if (scratch.correlated_key == key && scratch.correlated_px.size() == n) return;
  const int nodes_x = width / cell + 2;
  const int nodes_y = height / cell + 2;
  std::vector<float> nodes(static_cast<size_t>(nodes_x) * nodes_y);
  NormalStream normal(mix64(p.seed ^ kCorrelatedSalt));
  for (float& value : nodes) value = p.correlated_noise_px * normal.next();
  // Bilinear interpolation lowers the variance between nodes; rescale so that σ holds on average
  // (E[w²] summed over the four weights is (2/3)² per axis for uniform positions).
  const float gain = 1.5F;
  scratch.correlated_px.resize(n);
  for (int v = 0; v < height; ++v) {
    const float gy = static_cast<float>(v) / static_cast<float>(cell);
    const int y0 = static_cast<int>(gy);
    const float fy = gy - static_cast<float>(y0);
    for (int u = 0; u < width; ++u) {
      const float gx = static_cast<float>(u) / static_cast<float>(cell);
      const int x0 = static_cast<int>(gx);
      const float fx = gx - static_cast<float>(x0);
      const float* r0 = &nodes[static_cast<size_t>(y0) * nodes_x + x0];
      const float* r1 = r0 + nodes_x;
      const float top = r0[0] + fx * (r0[1] - r0[0]);
      const float bottom = r1[0] + fx * (r1[1] - r1[0]);
      scratch.correlated_px[static_cast<size_t>(v) * width + u] = gain * (top + fy * (bottom - top));
    }
  }
  scratch.correlated_key = key;
}

/// The 4-neighbour across the largest true-disparity step above `jump_px`, or -1: the pixel
/// then lies on no depth edge.
inline ptrdiff_t edge_neighbour(const float* d, int u, int v, int width, int height, size_t i, float jump_px) {
  const float di = d[i];
  float best = jump_px;
  ptrdiff_t j = -1;
  const auto consider = [&](ptrdiff_t k) {
    const float step = std::abs(d[k] - di);
    if (step > best) {
      best = step;
      j = k;
    }
  };
  if (u > 0) consider(static_cast<ptrdiff_t>(i) - 1);
  if (u + 1 < width) consider(static_cast<ptrdiff_t>(i) + 1);
  if (v > 0) consider(static_cast<ptrdiff_t>(i) - width);
  if (v + 1 < height) consider(static_cast<ptrdiff_t>(i) + width);
  return j;
}

/// Whether a material patch drops a pixel of `material` (bits) in the patch whose hash is `h`
/// (fixed per seed; patches of cell × cell pixels).
inline bool material_drop(const SimParams& p, uint8_t material, uint64_t h) {
  return ((material & kDarkBit) != 0 && unit24(h, 0) < p.dark_dropout) ||
         ((material & kShinyBit) != 0 && unit24(h, 20) < p.shiny_dropout) ||
         ((material & kLowTextureBit) != 0 && unit24(h, 40) < p.low_texture_dropout);
}

/// Isolated random dropouts, new every frame: the gaps between them are geometric, so the
/// cost is per dropout, not per pixel.
class SpeckleStream {
 public:
  SpeckleStream(uint64_t seed, float rate) : state_(seed), rate_(rate) {
    log_keep_ = rate > 0.0F && rate < 1.0F ? std::log1p(-static_cast<double>(rate)) : 0.0;
  }
  /// The first dropped pixel (max() when none).
  size_t first() { return rate_ > 0.0F ? gap() : kNone; }
  /// The dropped pixel after pixel i.
  size_t after(size_t i) { return i + 1 + gap(); }

 private:
  static constexpr size_t kNone = std::numeric_limits<size_t>::max() / 2;
  size_t gap() {
    if (rate_ >= 1.0F) return 0;
    state_ += kGolden;
    const double u = (static_cast<double>(mix64(state_) >> 11) + 0.5) * 0x1.0p-53;
    const double g = std::floor(std::log(u) / log_keep_);
    return g < 1e15 ? static_cast<size_t>(g) : kNone;
  }
  uint64_t state_;
  float rate_;
  double log_keep_ = 0.0;
};

/// Noisy disparity → raw depth: add σ·g, quantise to the disparity step, Z = fx·B / d, round
/// to the depth unit. 0 when the noisy disparity is not positive or the depth out of range.
struct NoisyDepth {
  float fxb;
  float sigma_px;
  float step_px;    ///< 0: no quantisation
  float inv_step;   ///< 1 / step_px
  float inv_scale;
  uint16_t operator()(float d, float g) const {
    d += sigma_px * g;
    // Round to the nearest step. Truncation is floor for x ≥ 0, and for x < 0 both give a
    // disparity ≤ 0, which has no depth either way; it avoids a libm call per pixel.
    // |d| < 2^31 · step for any surface farther than a micrometre.
    if (step_px > 0.0F) d = static_cast<float>(static_cast<int32_t>(d * inv_step + 0.5F)) * step_px;
    const float r = fxb / d * inv_scale + 0.5F;
    return d > 0.0F && r >= 1.0F && r < 65536.0F ? static_cast<uint16_t>(r) : 0;
  }
};

/// Pixels beside a depth edge: a share drops out, a share of the far side flies (the matching
/// window straddles the edge and takes in the nearer surface, whose texture dominates it, so
/// the disparity lands between the two; the near side keeps its own). Fixed per pixel and seed,
/// so that a still scene has still holes; with edge_flicker, drawn anew every frame from
/// `frame_seed`, and that share of the pixels that keep a depth take the other side's instead.
void apply_edges(const SimParams& p, uint64_t frame_seed, int width, int height, const float* d_true,
                 const float* correlated, const float* g, const uint8_t* hidden, const NoisyDepth& to_raw,
                 uint16_t* raw, std::vector<uint8_t>& row_steps) {
  const bool flicker = p.edge_flicker > 0.0F;
  const uint64_t edge_seed = flicker ? mix64(frame_seed ^ kFlickerSalt) : mix64(p.seed ^ kFixedSalt);
  row_steps.resize(static_cast<size_t>(width));
  uint8_t* steps = row_steps.data();
  for (int v = 0; v < height; ++v) {
    // Most pixels lie on no edge: screen the interior of the row branch-free (it vectorises),
    // then look closer only at pixels with a large step to some neighbour. Border rows and
    // columns skip the screen.
    const size_t row = static_cast<size_t>(v) * width;
    const bool border_row = v == 0 || v + 1 == height;
    if (!border_row) {
      for (int u = 1; u + 1 < width; ++u) {
        const size_t i = row + u;
        const float di = d_true[i];
        const float left = std::abs(d_true[i - 1] - di);
        const float right = std::abs(d_true[i + 1] - di);
        const float up = std::abs(d_true[i - width] - di);
        const float down = std::abs(d_true[i + width] - di);
        // The comparison stored as is: a `? 1 : 0` would stay a branch and stop vectorisation.
        steps[u] = static_cast<uint8_t>(std::max(std::max(left, right), std::max(up, down)) > p.edge_jump_px);
      }
      steps[0] = 1;
      steps[width - 1] = 1;
    }
    for (int u = 0; u < width; ++u) {
      if (!border_row) {
        // Eight screened pixels at a time: most words of the screen are all zero.
        for (uint64_t word = 0; u + 8 <= width; u += 8) {
          std::memcpy(&word, steps + u, 8);
          if (word != 0) break;
        }
        if (u == width) break;
        if (steps[u] == 0) continue;
      }
      const size_t i = row + u;
      if (hidden[i] != 0 || !(d_true[i] > 0.0F)) continue;
      const ptrdiff_t j = edge_neighbour(d_true, u, v, width, height, i, p.edge_jump_px);
      if (j < 0) continue;
      const uint64_t h = mix64(edge_seed + i * kGolden);
      if (unit24(h, 0) < p.edge_dropout) {
        raw[i] = 0;
      } else if (flicker && unit24(mix64(h), 0) < p.edge_flicker) {
        // The other side's depth, near for a far pixel and far for a near one, with this pixel's noise.
        raw[i] = to_raw(d_true[j] + (correlated != nullptr ? correlated[i] : 0.0F), g[i]);
      } else if (d_true[j] > d_true[i] && unit24(h, 24) < p.flying_pixels) {
        const float d = d_true[i] + unit24(h, 40) * (d_true[j] - d_true[i]);
        raw[i] = to_raw(d + (correlated != nullptr ? correlated[i] : 0.0F), g[i]);
      }
    }
  }
}

/// Dark, shiny and low-texture surfaces drop out in patches, fixed per seed.
void apply_materials(const SimParams& p, int width, int height, const uint16_t* ids, const uint8_t* material_of_id,
                     uint16_t* raw) {
  const uint64_t material_seed = mix64(p.seed ^ kMaterialSalt);
  const int cell = std::max(1, p.material_cell_px);
  const uint64_t cells_x = static_cast<uint64_t>((width + cell - 1) / cell);
  for (int v = 0; v < height; ++v) {
    const uint64_t row_cells = static_cast<uint64_t>(v / cell) * cells_x;
    const size_t row = static_cast<size_t>(v) * width;
    // Neighbouring pixels share a patch: hash each patch once per run of its pixels.
    uint64_t hashed_cell = std::numeric_limits<uint64_t>::max();
    uint64_t h = 0;
    for (int u = 0; u < width; ++u) {
      const size_t i = row + u;
      const uint8_t material = material_of_id[ids[i]];
      if (material == 0 || raw[i] == 0) continue;
      const uint64_t c = row_cells + static_cast<uint64_t>(u / cell);
      if (c != hashed_cell) {
        h = mix64(material_seed + c * kGolden);
        hashed_cell = c;
      }
      if (material_drop(p, material, h)) raw[i] = 0;
    }
  }
}

/// A working range (max_range_m > 0): no depth measured nearer than `min_range_m` or beyond
/// max_range_m. With `dropouts`, from range_dropout_start_m on a share growing as the square of
/// the way to max_range_m drops out, drawn anew every frame: the returned pattern fades with
/// distance, so far pixels come and go.
void apply_working_range(const SimParams& p, float min_range_m, bool dropouts, uint64_t frame_seed, size_t n,
                         uint16_t* raw) {
  // Limits in raw units, rounded as the depth is: 4.5 m keeps 4500 mm and drops 4501.
  const auto to_units = [&p](float z_m) { return std::lround(static_cast<double>(z_m) / p.depth_scale_m); };
  const long min_units = to_units(min_range_m);
  const long max_units = to_units(p.max_range_m);
  const long start_units = to_units(p.range_dropout_start_m);
  const auto ramp_units = static_cast<float>(max_units - start_units);
  dropouts = dropouts && p.range_dropout > 0.0F && ramp_units > 0.0F;
  const uint64_t range_seed = mix64(frame_seed ^ kRangeSalt);
  for (size_t i = 0; i < n; ++i) {
    const long units = raw[i];
    if (units == 0) continue;
    if (units < min_units || units > max_units) {
      raw[i] = 0;
    } else if (dropouts && units > start_units) {
      const float t = static_cast<float>(units - start_units) / ramp_units;
      if (unit24(mix64(range_seed + i * kGolden), 0) < p.range_dropout * t * t) raw[i] = 0;
    }
  }
}

/// Exact depth, rounded to the unit, where the stereo geometry gives any (noise off).
void write_exact_depth(const float* z_m, const float* disparity_px, const uint8_t* hidden, float inv_scale, size_t n,
                       uint16_t* raw) {
  for (size_t i = 0; i < n; ++i) {
    const float r = z_m[i] * inv_scale + 0.5F;
    const bool ok = disparity_px[i] > 0.0F && hidden[i] == 0 && r >= 1.0F && r < 65536.0F;
    raw[i] = ok ? static_cast<uint16_t>(r) : 0;
  }
}

/// The dense pass, branch-free so that it vectorises: every visible pixel (d_true > 0, not
/// hidden) gets its noisy depth, drawn from the true disparity d_true (px), the correlated
/// part (px, or none) and one normal draw `g`; every other pixel 0.
void write_noisy_depth(NoisyDepth to_raw, const float* d_true, const float* correlated, const float* g,
                       const uint8_t* hidden, size_t n, uint16_t* raw) {
  const float step = to_raw.step_px;
  if (correlated != nullptr || !(step > 0.0F)) {
    for (size_t i = 0; i < n; ++i) {
      const uint16_t r = to_raw(d_true[i] + (correlated != nullptr ? correlated[i] : 0.0F), g[i]);
      raw[i] = d_true[i] > 0.0F && hidden[i] == 0 ? r : 0;
    }
    return;
  }
  // The default: quantised, no correlated part. Written out so that it vectorises.
  const float fxb = to_raw.fxb;
  const float inv_scale = to_raw.inv_scale;
  const float sigma = to_raw.sigma_px;
  const float inv_step = 1.0F / step;
  for (size_t i = 0; i < n; ++i) {
    const float d = static_cast<float>(static_cast<int32_t>((d_true[i] + sigma * g[i]) * inv_step + 0.5F)) * step;
    const float r = fxb / std::max(std::numeric_limits<float>::min(), d) * inv_scale + 0.5F;
    // Bitwise & and integer masks instead of selects, a clamped conversion: branch-free, so
    // that it vectorises (GCC keeps float selects as branches under trapping math).
    const int ok = (d_true[i] > 0.0F) & (hidden[i] == 0) & (d > 0.0F) & (r >= 1.0F) & (r < 65536.0F);
    const auto value = static_cast<int32_t>(std::min(r, 65535.0F));
    raw[i] = static_cast<uint16_t>(value & -ok);
  }
}

}  // namespace

float sensor_min_range_m(const SimParams& p, float fx_px) {
  if (p.min_range_m > 0.0F) return p.min_range_m;
  if (!(p.max_disparity_px > 0.0F)) return 0.0F;
  return fx_px * p.baseline_mm * 1e-3F / p.max_disparity_px;
}

void write_sensor_depth(const SimParams& p, float fx_px, int64_t index, const float* z_m, SimScratch& scratch,
                        DepthImage& depth) {
  const int width = depth.width;
  const int height = depth.height;
  const size_t n = static_cast<size_t>(width) * height;
  const float fxb = fx_px * p.baseline_mm * 1e-3F;  // pixels · metres
  scratch.disparity_px.resize(n);
  scratch.hidden.resize(n);
  const float min_range = sensor_min_range_m(p, fx_px);
  const float max_disparity = min_range > 0.0F ? fxb / min_range : std::numeric_limits<float>::infinity();
  // A working range also ends far away (structured light); 0: no true depth is too far.
  const float min_disparity = p.max_range_m > 0.0F ? fxb / p.max_range_m : 0.0F;
  compute_disparity(z_m, fxb, n, scratch.disparity_px.data());
  mark_hidden(p, max_disparity, min_disparity, width, height, scratch.disparity_px.data(), scratch.hidden.data());

  const float inv_scale = 1.0F / p.depth_scale_m;
  const uint64_t frame_seed = mix64(mix64(p.seed) ^ (static_cast<uint64_t>(index) * kGolden));
  uint16_t* raw = depth.pixels.data();
  if (!p.noise) {
    write_exact_depth(z_m, scratch.disparity_px.data(), scratch.hidden.data(), inv_scale, n, raw);
    if (p.max_range_m > 0.0F) apply_working_range(p, min_range, false, frame_seed, n, raw);
    return;
  }
  // One draw per pixel, hit or not, so that a pixel's noise does not depend on the scene.
  scratch.normal_draws.resize(n);
  fill_normal_rows(frame_seed, width, height, scratch.normal_draws.data());
  ensure_correlated(p, width, height, scratch);
  const float* correlated = p.correlated_noise_px > 0.0F ? scratch.correlated_px.data() : nullptr;
  const float step = p.disparity_step_px;
  const NoisyDepth to_raw{fxb, p.disparity_noise_px, step, step > 0.0F ? 1.0F / step : 0.0F, inv_scale};
  const float* d_true = scratch.disparity_px.data();
  const float* g = scratch.normal_draws.data();
  const uint8_t* hidden = scratch.hidden.data();
  write_noisy_depth(to_raw, d_true, correlated, g, hidden, n, raw);
  // Sparse fix-ups. Flying pixels first (they re-compute a value); dropouts only ever zero one.
  apply_edges(p, frame_seed, width, height, d_true, correlated, g, hidden, to_raw, raw, scratch.row_steps);
  apply_materials(p, width, height, scratch.object_ids.data(), scratch.material_of_id.data(), raw);
  if (p.max_range_m > 0.0F) apply_working_range(p, min_range, true, frame_seed, n, raw);
  SpeckleStream speckle(mix64(frame_seed ^ kSpeckleSalt), p.speckle);
  for (size_t i = speckle.first(); i < n; i = speckle.after(i)) raw[i] = 0;
}

}  // namespace hrcsense::sim_detail
