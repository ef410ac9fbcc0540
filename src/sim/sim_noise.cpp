// SPDX-License-Identifier: Apache-2.0
// hrcsense — ziggurat tables and the rare slow path of the simulator's Gaussian draws.

#include "sim_noise.hpp"

#include <vector>

namespace hrcsense::sim_detail {

const NormalStream::Tables& NormalStream::tables() {
  // Built once (thread-safe static initialisation, no heap). 128 layers of equal area
  // v = 9.91256303526217e-3 under exp(-x²/2), the last one the tail beyond kR.
  static const Tables kTables = [] {
    Tables t;
    constexpr double kArea = 9.91256303526217e-3;
    constexpr double kScale = 2147483648.0;  // 2^31: |value| range of a signed 32-bit draw
    double d = kR;
    double prev = d;
    const double q = kArea / std::exp(-0.5 * d * d);
    t.k[0] = static_cast<uint32_t>((d / q) * kScale);
    t.k[1] = 0;
    t.w[0] = q / kScale;
    t.w[127] = d / kScale;
    t.f[0] = 1.0;
    t.f[127] = std::exp(-0.5 * d * d);
    for (int i = 126; i >= 1; --i) {
      d = std::sqrt(-2.0 * std::log(kArea / d + std::exp(-0.5 * d * d)));
      t.k[i + 1] = static_cast<uint32_t>((d / prev) * kScale);
      prev = d;
      t.f[i] = std::exp(-0.5 * d * d);
      t.w[i] = d / kScale;
    }
    return t;
  }();
  return kTables;
}

float NormalStream::slow(int32_t value, unsigned layer) {
  const Tables& t = tables();
  for (;;) {
    const double x = value * t.w[layer];
    if (layer == 0) {
      // The tail beyond kR, by Marsaglia's exponential rejection.
      double tx = 0.0;
      double ty = 0.0;
      do {
        tx = -std::log(uniform()) / kR;
        ty = -std::log(uniform());
      } while (ty + ty < tx * tx);
      return static_cast<float>(value > 0 ? kR + tx : -kR - tx);
    }
    // The wedge between the rectangle and the curve: accept under the density.
    if (t.f[layer] + uniform() * (t.f[layer - 1] - t.f[layer]) < std::exp(-0.5 * x * x)) {
      return static_cast<float>(x);
    }
    const uint64_t bits = next_bits();
    value = static_cast<int32_t>(static_cast<uint32_t>(bits));
    layer = static_cast<unsigned>((bits >> 32) & 127U);
    if (static_cast<uint32_t>(std::abs(static_cast<int64_t>(value))) < t.k[layer]) {
      return static_cast<float>(value * t.w[layer]);
    }
  }
}

namespace {

constexpr size_t kTableSize = size_t{1} << 18;

const std::vector<float>& normal_table() {
  static const std::vector<float> kTable = [] {
    std::vector<float> t(kTableSize);
    NormalStream normal(0x6A09E667F3BCC908ULL);  // any fixed seed
    double sum = 0.0;
    for (float& x : t) {
      x = normal.next();
      sum += x;
    }
    const double mean = sum / static_cast<double>(kTableSize);
    double sq = 0.0;
    for (const float x : t) sq += (x - mean) * (x - mean);
    const double scale = 1.0 / std::sqrt(sq / static_cast<double>(kTableSize));
    for (float& x : t) x = static_cast<float>((x - mean) * scale);
    return t;
  }();
  return kTable;
}

}  // namespace

void fill_normal_rows(uint64_t frame_seed, int width, int height, float* out) {
  const std::vector<float>& table = normal_table();
  const size_t w = static_cast<size_t>(width);
  // Rows wider than the table (none of the D435's) wrap around it.
  const size_t span = w < kTableSize ? kTableSize - w + 1 : 1;
  for (int v = 0; v < height; ++v) {
    const uint64_t h = mix64(frame_seed + static_cast<uint64_t>(v + 1) * 0x9E3779B97F4A7C15ULL);
    const size_t offset = static_cast<size_t>(h >> 40) % span;
    const float sign = (h & 1U) != 0 ? -1.0F : 1.0F;
    float* row = out + static_cast<size_t>(v) * w;
    if (offset + w <= kTableSize) {
      const float* window = table.data() + offset;
      for (size_t u = 0; u < w; ++u) row[u] = sign * window[u];
    } else {
      for (size_t u = 0; u < w; ++u) row[u] = sign * table[(offset + u) % kTableSize];
    }
  }
}

}  // namespace hrcsense::sim_detail
