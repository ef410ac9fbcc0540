// SPDX-License-Identifier: Apache-2.0
// hrcsense filters — the SDK's edge-preserving spatial filter (spec §5). The depth (uint16)
// and disparity (float) domains are two different algorithms in the SDK; both are copied.
#include "hrcsense/filters.hpp"

#include <cstdlib>
#include <cstring>

namespace hrcsense {
namespace {

// ---- disparity (float) path, spec §5a ----

// The SDK's validity test reads the float's bits as an int: only positive values count.
bool valid_disparity(float value) {
  int32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits > 0;
}

bool empty_disparity(float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits == 0;  // only +0.0 is a hole; -0.0 is not
}

// One directional scan over n values `stride` apart. The edge test compares the unsmoothed
// neighbours, the blend uses the smoothed state; p[0] is never written.
void scan_disparity(float* p, ptrdiff_t stride, int n, float alpha, float delta) {
  if (n < 2) return;
  const float one_minus_alpha = 1.0F - alpha;
  float state = p[0];
  float previous = p[0];
  bool chain = valid_disparity(p[0]);
  for (int k = 1; k < n; ++k) {
    float* pixel = p + k * stride;
    const float current = *pixel;
    const bool valid = valid_disparity(current);
    if (!chain) {
      if (valid) state = current;  // a new chain starts, the pixel is kept
      chain = valid;
    } else if (valid) {
      const float difference = previous - current;
      if (difference < delta && difference > -delta) {
        state = current * alpha + state * one_minus_alpha;
        *pixel = state;
      } else {
        state = current;  // an edge: restart from the unsmoothed value
      }
    } else {
      chain = false;
    }
    previous = current;
  }
}

// Fills at most radius − 1 holes from each side, once after all iterations.
void holes_fill_disparity(DisparityImage& image, int radius) {
  const int w = image.width;
  for (int v = 0; v < image.height; ++v) {
    float* row = image.pixels.data() + static_cast<size_t>(v) * w;
    int fill = 0;
    for (int u = 1; u < w; ++u) {
      if (!empty_disparity(row[u])) {
        fill = 0;
      } else if (++fill < radius) {
        row[u] = row[u - 1];
      }
    }
    fill = 0;
    for (int u = w - 1; u >= 1; --u) {
      if (!empty_disparity(row[u])) {
        fill = 0;
      } else if (++fill < radius) {
        // The SDK takes the next row's first pixel as the right neighbour of the last column;
        // the goldens need that copied (spatial_disp_*_h*). On the last row it reads past the
        // buffer's end; there we use 0, i.e. no neighbour.
        row[u] = u + 1 < w ? row[u + 1] : (v + 1 < image.height ? row[w] : 0.0F);
      }
    }
  }
}

// ---- depth (uint16) path, spec §5b ----

uint16_t blend(uint16_t current, uint16_t neighbour, float alpha, float one_minus_alpha) {
  const float filtered = static_cast<float>(current) * alpha + static_cast<float>(neighbour) * one_minus_alpha;
  return static_cast<uint16_t>(filtered + 0.5F);
}

// Left→right then right→left over one row, comparing with the already filtered neighbour
// and filling holes in place when radius > 0.
void horizontal_depth(uint16_t* row, int w, float alpha, int delta, int radius) {
  const float one_minus_alpha = 1.0F - alpha;
  int fill = 0;
  uint16_t left = row[0];
  for (int u = 1; u < w - 1; ++u) {  // the last column is not visited in this direction
    uint16_t current = row[u];
    if (left >= 1) {
      if (current >= 1) {
        fill = 0;
        const int difference = std::abs(static_cast<int>(current) - static_cast<int>(left));
        if (difference >= 1 && difference <= delta) row[u] = current = blend(current, left, alpha, one_minus_alpha);
      } else if (radius > 0 && ++fill < radius) {
        row[u] = current = left;
      }
    }
    left = current;
  }
  fill = 0;
  uint16_t right = row[w - 1];
  for (int u = w - 2; u >= 0; --u) {
    uint16_t current = row[u];
    if (right >= 1) {
      if (current > 1) {  // SDK quirk: a raw 1 counts as a hole in this direction
        fill = 0;
        const int difference = std::abs(static_cast<int>(right) - static_cast<int>(current));
        if (difference <= delta) row[u] = current = blend(current, right, alpha, one_minus_alpha);
      } else if (radius > 0 && ++fill < radius) {
        row[u] = current = right;
      }
    }
    right = current;
  }
}

// Top→bottom (no validity check, as the SDK) then bottom→top (both valid); row-major loops.
void vertical_depth(DepthImage& image, float alpha, int delta) {
  const float one_minus_alpha = 1.0F - alpha;
  const int w = image.width;
  uint16_t* pixels = image.pixels.data();
  for (int v = 1; v < image.height; ++v) {
    const uint16_t* up = pixels + static_cast<size_t>(v - 1) * w;
    uint16_t* row = pixels + static_cast<size_t>(v) * w;
    for (int u = 0; u < w; ++u) {
      if (std::abs(static_cast<int>(up[u]) - static_cast<int>(row[u])) < delta) {
        row[u] = blend(row[u], up[u], alpha, one_minus_alpha);
      }
    }
  }
  for (int v = image.height - 2; v >= 0; --v) {
    const uint16_t* down = pixels + static_cast<size_t>(v + 1) * w;
    uint16_t* row = pixels + static_cast<size_t>(v) * w;
    for (int u = 0; u < w; ++u) {
      if (row[u] >= 1 && down[u] >= 1 && std::abs(static_cast<int>(row[u]) - static_cast<int>(down[u])) < delta) {
        row[u] = blend(row[u], down[u], alpha, one_minus_alpha);
      }
    }
  }
}

}  // namespace

int spatial_holes_radius(int holes_fill) {
  if (holes_fill <= 0) return 0;
  if (holes_fill >= 5) return 255;
  return 1 << holes_fill;
}

void spatial_filter(const SpatialParams& params, DepthImage& depth) {
  if (depth.width < 2 || depth.height < 1) return;
  const int radius = spatial_holes_radius(params.holes_fill);
  for (int i = 0; i < params.magnitude; ++i) {
    for (int v = 0; v < depth.height; ++v) {
      horizontal_depth(depth.pixels.data() + static_cast<size_t>(v) * depth.width, depth.width, params.alpha,
                       params.delta, radius);
    }
    vertical_depth(depth, params.alpha, params.delta);
  }
}

void spatial_filter(const SpatialParams& params, DisparityImage& disparity) {
  const int w = disparity.width;
  const int h = disparity.height;
  if (w < 1 || h < 1) return;
  const float delta = static_cast<float>(params.delta);
  for (int i = 0; i < params.magnitude; ++i) {
    for (int v = 0; v < h; ++v) {
      float* row = disparity.pixels.data() + static_cast<size_t>(v) * w;
      scan_disparity(row, 1, w, params.alpha, delta);
      scan_disparity(row + w - 1, -1, w, params.alpha, delta);
    }
    for (int u = 0; u < w; ++u) {
      float* column = disparity.pixels.data() + u;
      scan_disparity(column, w, h, params.alpha, delta);
      scan_disparity(column + static_cast<ptrdiff_t>(h - 1) * w, -static_cast<ptrdiff_t>(w), h, params.alpha, delta);
    }
  }
  const int radius = spatial_holes_radius(params.holes_fill);
  if (radius > 0) holes_fill_disparity(disparity, radius);
}

}  // namespace hrcsense
