// SPDX-License-Identifier: Apache-2.0
// Plain, obviously correct scalar references of the spatial and temporal filters, written
// from specs/depth-filters.md §5–§6 line by line, for checking faster versions bit for bit.
#pragma once

#include "hrcsense/filters.hpp"

#include <algorithm>
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


// §3: keep raw when min <= raw · units <= max, in float32.
inline DepthImage threshold(const ThresholdParams& q, DepthImage img) {
  for (uint16_t& raw : img.pixels) {
    const float z = float(raw) * img.depth_scale_m;
    if (!(z >= q.min_m && z <= q.max_m)) raw = 0;
  }
  return img;
}

// §2: disparity = F / raw for raw != 0.
inline DisparityImage to_disparity(const DepthImage& in, float factor) {
  DisparityImage out;
  out.resize(in.width, in.height);
  for (size_t i = 0; i < in.pixels.size(); ++i) out.pixels[i] = in.pixels[i] != 0 ? factor / float(in.pixels[i]) : 0.0F;
  return out;
}

// §2: raw = F / d + 0.5 truncated, for normal d; through a 32-bit integer as the SDK's x86 build
// (whose conversion gives INT32_MIN out of range).
inline DepthImage to_depth(const DisparityImage& in, float factor) {
  DepthImage out;
  out.resize(in.width, in.height);
  for (size_t i = 0; i < in.pixels.size(); ++i) {
    if (!std::isnormal(in.pixels[i])) continue;
    const float x = factor / in.pixels[i] + 0.5F;
    const int32_t truncated = (x > -2147483648.0F && x < 2147483648.0F) ? int32_t(x) : INT32_MIN;
    out.pixels[i] = uint16_t(uint32_t(truncated));
  }
  return out;
}

// §4: lower median (s 2–3) or truncated mean (otherwise) of each block's non-zero values,
// padded to multiples of 4.
inline DepthImage decimate(int s, const DepthImage& in) {
  DepthImage out;
  const int rw = in.width / s, rh = in.height / s;
  out.resize((rw + 3) / 4 * 4, (rh + 3) / 4 * 4);
  for (int j = 0; j < rh; ++j) {
    for (int i = 0; i < rw; ++i) {
      std::vector<uint16_t> values;
      for (int y = j * s; y < j * s + s; ++y)
        for (int x = i * s; x < i * s + s; ++x)
          if (in.pixels[size_t(y) * in.width + x] != 0) values.push_back(in.pixels[size_t(y) * in.width + x]);
      uint16_t result = 0;
      if (!values.empty()) {
        std::sort(values.begin(), values.end());
        uint32_t sum = 0;
        for (const uint16_t v : values) sum += v;
        result = (s == 2 || s == 3) ? values[(values.size() - 1) / 2] : uint16_t(sum / values.size());
      }
      out.pixels[size_t(j) * out.width + i] = result;
    }
  }
  return out;
}

// §7, in place in raster order: mode 0 copies the left pixel; 1 takes the largest of up-left,
// up, left, down-left, down; 2 the smallest non-empty one, starting from up even when empty.
template <typename Image>
Image fill_holes(int mode, Image img) {
  using T = typename decltype(img.pixels)::value_type;
  const auto empty = [](T x) {
    if constexpr (std::is_same_v<T, float>) return plus_zero(x);
    else return x == 0;
  };
  const int w = img.width, h = img.height;
  auto at = [&](int u, int v) -> T& { return img.pixels[size_t(v) * w + u]; };
  for (int v = 0; v < h; ++v) {
    for (int u = 1; u < w; ++u) {
      if (!empty(at(u, v))) continue;
      if (mode == 0) {
        at(u, v) = at(u - 1, v);
      } else if (v >= 1 && v + 1 < h) {
        T best = at(u, v - 1);
        for (const T x : {at(u - 1, v - 1), at(u - 1, v), at(u - 1, v + 1), at(u, v + 1)}) {
          if (mode == 1 ? x > best : (!empty(x) && x < best)) best = x;
        }
        at(u, v) = best;
      }
    }
  }
  return img;
}

}  // namespace hrcsense::reference
