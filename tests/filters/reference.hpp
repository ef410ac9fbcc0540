// SPDX-License-Identifier: Apache-2.0
// Plain, obviously correct scalar references of the spatial and temporal filters, written
// from specs/depth-filters.md §5–§6 line by line, for checking faster versions bit for bit.
#pragma once

#include "hrcsense/filters.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace hrcsense::reference {

inline bool positive(float v) {
  int32_t bits;
  std::memcpy(&bits, &v, 4);
  return bits > 0;
}
inline bool plus_zero(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  return bits == 0;
}

// §5a: one scan over the values at `index[0..n-1]`.
inline void scan(std::vector<float>& p, const std::vector<size_t>& index, float alpha, float delta) {
  float state = p[index[0]];
  float prev_raw = p[index[0]];
  bool prev_valid = positive(prev_raw);
  for (size_t k = 1; k < index.size(); ++k) {
    const float cur_raw = p[index[k]];
    if (!prev_valid) {
      if (positive(cur_raw)) state = cur_raw;
    } else if (positive(cur_raw)) {
      if (std::fabs(prev_raw - cur_raw) < delta) {
        state = alpha * cur_raw + (1.0F - alpha) * state;
        p[index[k]] = state;
      } else {
        state = cur_raw;
      }
    }
    prev_valid = positive(cur_raw);
    prev_raw = cur_raw;
  }
}

inline void spatial_disparity(const SpatialParams& q, DisparityImage& img) {
  const size_t w = img.width, h = img.height;
  std::vector<size_t> index;
  for (int it = 0; it < q.magnitude; ++it) {
    for (size_t v = 0; v < h; ++v) {
      index.clear();
      for (size_t u = 0; u < w; ++u) index.push_back(v * w + u);
      scan(img.pixels, index, q.alpha, float(q.delta));
      std::vector<size_t> back(index.rbegin(), index.rend());
      scan(img.pixels, back, q.alpha, float(q.delta));
    }
    for (size_t u = 0; u < w; ++u) {
      index.clear();
      for (size_t v = 0; v < h; ++v) index.push_back(v * w + u);
      scan(img.pixels, index, q.alpha, float(q.delta));
      std::vector<size_t> back(index.rbegin(), index.rend());
      scan(img.pixels, back, q.alpha, float(q.delta));
    }
  }
  const int r = q.holes_fill == 0 ? 0 : (q.holes_fill == 5 ? 255 : 1 << q.holes_fill);
  if (r == 0) return;
  for (size_t v = 0; v < h; ++v) {
    int c = 0;
    for (size_t u = 1; u < w; ++u) {
      float& x = img.pixels[v * w + u];
      if (!plus_zero(x)) c = 0;
      else if (++c < r) x = img.pixels[v * w + u - 1];
    }
    c = 0;
    for (size_t u = w - 1; u >= 1; --u) {
      float& x = img.pixels[v * w + u];
      // the flat buffer's next element: the next row's first pixel, 0 past the end
      const float right = v * w + u + 1 < w * h ? img.pixels[v * w + u + 1] : 0.0F;
      if (!plus_zero(x)) c = 0;
      else if (++c < r) x = right;
    }
  }
}

inline uint16_t round_blend(int cur, int other, float alpha) {
  return uint16_t(float(cur) * alpha + float(other) * (1.0F - alpha) + 0.5F);
}

// §5b, literally.
inline void spatial_depth(const SpatialParams& q, DepthImage& img) {
  const int w = img.width, h = img.height;
  const int r = q.holes_fill == 0 ? 0 : (q.holes_fill == 5 ? 255 : 1 << q.holes_fill);
  auto at = [&](int u, int v) -> uint16_t& { return img.pixels[size_t(v) * w + u]; };
  for (int it = 0; it < q.magnitude; ++it) {
    for (int v = 0; v < h; ++v) {
      int c = 0;
      for (int u = 1; u <= w - 2; ++u) {
        const int left = at(u - 1, v), cur = at(u, v);
        if (left >= 1 && cur >= 1) {
          c = 0;
          const int d = std::abs(cur - left);
          if (d >= 1 && d <= q.delta) at(u, v) = round_blend(cur, left, q.alpha);
        } else if (left >= 1 && cur == 0 && r > 0) {
          if (++c < r) at(u, v) = uint16_t(left);
        }
      }
      c = 0;
      for (int u = w - 2; u >= 0; --u) {
        const int right = at(u + 1, v), cur = at(u, v);
        if (right >= 1 && cur > 1) {
          c = 0;
          if (std::abs(right - cur) <= q.delta) at(u, v) = round_blend(cur, right, q.alpha);
        } else if (right >= 1 && cur <= 1 && r > 0) {
          if (++c < r) at(u, v) = uint16_t(right);
        }
      }
    }
    for (int v = 1; v < h; ++v)
      for (int u = 0; u < w; ++u)
        if (std::abs(int(at(u, v - 1)) - int(at(u, v))) < q.delta) at(u, v) = round_blend(at(u, v), at(u, v - 1), q.alpha);
    for (int v = h - 2; v >= 0; --v)
      for (int u = 0; u < w; ++u)
        if (at(u, v) >= 1 && at(u, v + 1) >= 1 && std::abs(int(at(u, v)) - int(at(u, v + 1))) < q.delta)
          at(u, v) = round_blend(at(u, v), at(u, v + 1), q.alpha);
  }
}

// §6 with a shift register (bit 0 = previous frame) instead of the SDK's rotating history.
template <typename T>
struct Temporal {
  TemporalParams q;
  std::vector<T> last;
  std::vector<uint8_t> recent;  // bit b: valid and agreeing b+1 frames ago

  bool fill(uint8_t bits) const {
    static const int N[9] = {0, 8, 3, 4, 8, 2, 5, 8, 0}, M[9] = {0, 8, 2, 2, 2, 1, 1, 1, 0};
    if (q.persistence == 8) return true;
    int count = 0;
    for (int b = 0; b < N[q.persistence]; ++b) count += (bits >> b) & 1;
    return q.persistence != 0 && count >= M[q.persistence];
  }

  void apply(std::vector<T>& frame) {
    if (last.size() != frame.size()) {
      last.assign(frame.size(), T(0));
      recent.assign(frame.size(), 0);
    }
    for (size_t i = 0; i < frame.size(); ++i) {
      const T cur = frame[i];
      if (cur != T(0)) {
        double diff = 0.0;
        if constexpr (std::is_same_v<T, float>) {
          diff = double(std::fabs(cur - last[i]));  // in float, as the spec's float path
        } else {
          diff = std::abs(int(cur) - int(last[i]));
        }
        if (last[i] != T(0) && diff < double(q.delta)) {
          const T v = T(q.alpha * float(cur) + (1.0F - q.alpha) * float(last[i]));
          frame[i] = last[i] = v;
          recent[i] = uint8_t(recent[i] << 1 | 1);
        } else {
          last[i] = cur;
          recent[i] = 1;  // only this frame counts
        }
      } else {
        if (last[i] != T(0) && fill(recent[i])) frame[i] = last[i];
        recent[i] = uint8_t(recent[i] << 1);
      }
    }
  }
};

}  // namespace hrcsense::reference
