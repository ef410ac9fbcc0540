// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's temporal filter (spec §6): smoothing across frames and hole
// filling from a rotating 8-frame validity history, with the SDK's persistence rules.
#include "hrcsense/filters.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <type_traits>

namespace hrcsense {
namespace {

// Window N (frames before the current one) and minimum count M of each persistence mode.
constexpr int kWindow[9] = {0, 8, 3, 4, 8, 2, 5, 8, 0};
constexpr int kMinValid[9] = {0, 8, 2, 2, 2, 1, 1, 1, 0};

// Bit k of lut[history] says whether a hole may be filled at phase k: bit k of the history
// is the pixel's validity in the last frame of phase k, so the N frames before a frame of
// phase k are the bits k-1, ..., k-N (mod 8).
std::array<uint8_t, 256> persistence_lut(int persistence) {
  std::array<uint8_t, 256> lut{};
  for (int history = 0; history < 256; ++history) {
    for (int phase = 0; phase < 8; ++phase) {
      bool fill = persistence == 8;
      if (persistence >= 1 && persistence <= 7) {
        int count = 0;
        for (int back = 1; back <= kWindow[persistence]; ++back) count += (history >> ((phase - back + 8) % 8)) & 1;
        fill = count >= kMinValid[persistence];
      }
      if (fill) lut[static_cast<size_t>(history)] |= static_cast<uint8_t>(1U << phase);
    }
  }
  return lut;
}

bool same(const TemporalParams& a, const TemporalParams& b) {
  return a.alpha == b.alpha && a.delta == b.delta && a.persistence == b.persistence;
}

// |a - b| as the SDK computes it: through int for uint16, in float for float.
inline uint16_t abs_difference(uint16_t a, uint16_t b) {
  return static_cast<uint16_t>(std::abs(static_cast<int>(a) - static_cast<int>(b)));
}
inline float abs_difference(float a, float b) { return std::fabs(a - b); }

}  // namespace

void TemporalFilter::reset() { has_state_ = false; }

template <typename T>
void TemporalFilter::apply_to(T* pixels, int width, int height, bool disparity) {
  const size_t n = static_cast<size_t>(width) * height;
  std::vector<T>* last_storage = nullptr;
  if constexpr (std::is_same_v<T, float>) {
    last_storage = &last_disparity_;
  } else {
    last_storage = &last_depth_;
  }
  std::vector<T>& last_vector = *last_storage;
  if (!has_state_ || width != width_ || height != height_ || disparity != disparity_ || !same(params, state_params_)) {
    last_vector.assign(n, T{0});  // reuses the capacity of the previous stream
    history_.assign(n, 0);
    fill_lut_ = persistence_lut(params.persistence);
    state_params_ = params;
    width_ = width;
    height_ = height;
    disparity_ = disparity;
    phase_ = 0;
    has_state_ = true;
  }
  const T delta = static_cast<T>(params.delta);
  const float alpha = params.alpha;
  const float one_minus_alpha = 1.0F - alpha;
  const auto mask = static_cast<uint8_t>(1U << phase_);
  T* last = last_vector.data();
  uint8_t* history = history_.data();
  for (size_t i = 0; i < n; ++i) {
    const T current = pixels[i];
    const T previous = last[i];
    if (current != T{0}) {
      if (previous != T{0} && abs_difference(current, previous) < delta) {
        history[i] |= mask;
        // Truncated for uint16 (no +0.5, unlike the spatial filter), as the SDK.
        const T result = static_cast<T>(alpha * static_cast<float>(current) + one_minus_alpha * static_cast<float>(previous));
        pixels[i] = result;
        last[i] = result;
      } else {
        last[i] = current;  // first sample or a jump: start over, forgetting older frames
        history[i] = mask;
      }
    } else {
      // A filled hole keeps `last` unchanged.
      if (previous != T{0} && (fill_lut_[history[i]] & mask) != 0) pixels[i] = previous;
      history[i] = static_cast<uint8_t>(history[i] & ~mask);
    }
  }
  phase_ = (phase_ + 1) % 8;
}

void TemporalFilter::apply(DepthImage& depth) { apply_to(depth.pixels.data(), depth.width, depth.height, false); }

void TemporalFilter::apply(DisparityImage& disparity) {
  apply_to(disparity.pixels.data(), disparity.width, disparity.height, true);
}

}  // namespace hrcsense
