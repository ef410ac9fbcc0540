// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator's random numbers: a seekable 64-bit stream and fast Gaussian draws.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>

namespace hrcsense::sim_detail {

/// SplitMix64's output function: a strong 64-bit mixer. Used to derive a frame's seed from
/// (seed, frame index) and, over a Weyl counter, as the generator itself, so that any frame's
/// stream can be started directly (frames render alone, in any order).
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// Standard normal variates by the ziggurat method (Marsaglia & Tsang 2000, 128 layers):
/// about 98.8 % of draws cost one table look-up and a compare, which is what lets a full
/// 848x480 frame get per-pixel noise at a few hundred frames per second. Deterministic:
/// the same seed gives the same sequence on every run.
class NormalStream {
 public:
  explicit NormalStream(uint64_t seed) : state_(seed) {}

  /// The next N(0, 1) variate.
  float next() {
    const uint64_t bits = next_bits();
    const auto value = static_cast<int32_t>(static_cast<uint32_t>(bits));  // signed 32-bit
    const auto layer = static_cast<unsigned>((bits >> 32) & 127U);
    const Tables& t = tables();
    // Inside the layer's rectangle under the curve: accept at once.
    if (static_cast<uint32_t>(std::abs(static_cast<int64_t>(value))) < t.k[layer]) {
      return static_cast<float>(value * t.w[layer]);
    }
    return slow(value, layer);
  }

 private:
  struct Tables {
    std::array<uint32_t, 128> k{};  ///< acceptance thresholds on |value|
    std::array<double, 128> w{};    ///< value → x scale per layer
    std::array<double, 128> f{};    ///< density exp(-x²/2) at each layer's edge
  };
  static constexpr double kR = 3.442619855899;  ///< start of the tail layer

  uint64_t next_bits() {
    state_ += 0x9E3779B97F4A7C15ULL;
    return mix64(state_);
  }
  double uniform() { return (static_cast<double>(next_bits() >> 11) + 0.5) * 0x1.0p-53; }

  static const Tables& tables();
  float slow(int32_t value, unsigned layer);

  uint64_t state_;
};

/// Fills a width × height image with N(0, 1) draws for the frame whose seed is `frame_seed`.
/// Each row is a window of a fixed table of 2^18 ziggurat draws (normalised to mean 0, σ 1),
/// at an offset and with a sign drawn per row and frame, so a frame costs a copy instead of a
/// draw per pixel. Neighbouring pixels get independent table entries and a pixel gets an
/// independent entry each frame (unless two frames pick the same offset, 1 in 2^18); what
/// is given up is that, within a frame, two rows may share a stretch of values, shifted.
void fill_normal_rows(uint64_t frame_seed, int width, int height, float* out);

}  // namespace hrcsense::sim_detail
