// SPDX-License-Identifier: Apache-2.0
// hrcsense — per-background tables of the foreground extractor (see foreground_tables.hpp).

#include "foreground_tables.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace hrcsense::segmentation_detail {
namespace {

constexpr uint32_t kRawValues = 65536;

/// Where z + max(a, c·z², min_margin) reaches `mean_m`, in metres, from the real-valued
/// formula: the float test decides the exact boundary, this only says where to look. The left
/// side grows with z, so the root is unique: on the flat part z = mean − max(a, min_margin),
/// on the quadratic part c·z² + z − mean = 0.
double estimated_boundary_m(float mean_m, float spread_m, const NearerTest& test) {
  const double a = static_cast<double>(test.k_sigma) * spread_m;
  const double flat = std::max(std::isfinite(a) ? a : 0.0, static_cast<double>(test.min_margin_m));
  const double m = mean_m;
  const double c = test.k_model;
  const double z_flat = m - flat;
  if (c <= 0.0 || c * z_flat * z_flat <= flat) return z_flat;
  return (std::sqrt(1.0 + 4.0 * c * m) - 1.0) / (2.0 * c);
}

}  // namespace

float sigma_per_z2(float fx_px, float baseline_mm, float subpixel_rms_px) {
  if (baseline_mm <= 0.0F || fx_px <= 0.0F) return 0.0F;
  return static_cast<float>(stereo_depth_sigma_m(1.0, fx_px, baseline_mm, subpixel_rms_px));
}

bool nearer_than_background(uint16_t raw, float mean_m, float spread_m, const NearerTest& test) {
  // The same operations, in the same order and precision, as the vectorised test this table
  // replaced, so that the mask stays bit for bit what it was.
  const float z = static_cast<float>(raw) * test.depth_scale_m;
  const float a = test.k_sigma * spread_m;
  const float b = test.k_model * z * z;
  const float ab = a > b ? a : b;
  const float margin = ab > test.min_margin_m ? ab : test.min_margin_m;
  return z < mean_m - margin;
}

uint16_t nearer_raw_count(float mean_m, float spread_m, const NearerTest& test) {
  const auto nearer = [&](uint32_t raw) {
    return nearer_than_background(static_cast<uint16_t>(raw), mean_m, spread_m, test);
  };
  // Invariant: every raw in [1, lo] passes, every raw in [hi, 65535] fails. The test is
  // monotone in raw, so the answer is lo once hi = lo + 1.
  uint32_t lo = 0;
  uint32_t hi = kRawValues;
  // The closed form lands within a unit or two of the boundary: probe there first, so that the
  // bisection below usually has nothing left to do. A NaN estimate just starts at 1.
  const double estimate = std::ceil(estimated_boundary_m(mean_m, spread_m, test) / test.depth_scale_m) - 1.0;
  const uint32_t guess = estimate >= 1.0 ? static_cast<uint32_t>(std::min(estimate, 65535.0)) : 1U;
  if (nearer(guess)) {
    lo = guess;
    if (guess + 1 < hi) (nearer(guess + 1) ? lo : hi) = guess + 1;
  } else {
    hi = guess;
    if (guess - 1 > lo) (nearer(guess - 1) ? lo : hi) = guess - 1;
  }
  while (hi - lo > 1) {
    const uint32_t mid = lo + (hi - lo) / 2;
    (nearer(mid) ? lo : hi) = mid;
  }
  return static_cast<uint16_t>(lo);
}

void build_nearer_table(const BackgroundModel& background, const NearerTest& test, uint8_t unknown_state,
                        uint16_t* count, uint8_t* unknown) {
  // A threshold exists only because the test is monotone in raw: z and the margin both grow.
  assert(test.depth_scale_m > 0.0F && test.k_sigma >= 0.0F && test.k_model >= 0.0F);
  const size_t n = background.mean_m.size();
  for (size_t i = 0; i < n; ++i) {
    const float mean_m = background.mean_m[i];
    const bool known = mean_m > 0.0F;  // false for NaN too, as before
    count[i] = known ? nearer_raw_count(mean_m, background.spread_m[i], test) : 0;
    unknown[i] = known ? 0 : unknown_state;
  }
}

void build_jump_limits(float depth_scale_m, float jump_per_z2, int32_t* limit) {
  const float jump_min_raw = kJumpMinM / depth_scale_m;
  const float jump_per_raw2 = jump_per_z2 * depth_scale_m;
  for (uint32_t r = 0; r < kRawValues; ++r) {
    const float far = static_cast<float>(r);
    // Steps are at most 65535, so any limit above 65536 acts like 65536; capping also keeps
    // the conversion to int defined for an extreme noise model (a NaN limit becomes 65536 too).
    const float exact = std::max(jump_min_raw, jump_per_raw2 * far * far);
    const float raw_limit = exact < 65536.0F ? exact : 65536.0F;
    const int whole = static_cast<int>(raw_limit);
    limit[r] = whole + (static_cast<float>(whole) < raw_limit ? 1 : 0);
  }
}

}  // namespace hrcsense::segmentation_detail
