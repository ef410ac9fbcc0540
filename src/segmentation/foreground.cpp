// SPDX-License-Identifier: Apache-2.0
// hrcsense — foreground extraction: background subtraction, speckle removal by physical size,
// deprojection into camera- and base-frame point clouds.

#include "hrcsense/camera.hpp"
#include "hrcsense/segmentation.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>

namespace hrcsense {
namespace {

// Mask states while a frame is processed; only kNone and kForeground survive extract().
// The values are bit-distinct so that a scan can test 8 pixels at once for one state.
constexpr uint8_t kNone = 0;
constexpr uint8_t kForeground = 1;  // final: kept after speckle removal
constexpr uint8_t kCandidate = 2;   // passed the background test, not yet flood-filled
constexpr uint8_t kVisited = 3;     // in the blob being flood-filled
constexpr uint8_t kUnknown = 4;     // valid depth where the background was never valid

// Neighbouring foreground pixels belong to one object unless their depths jump by more than
// max(kJumpMinM, kJumpSigmas · σ_model(z)) at the farther of the two depths.
constexpr float kJumpMinM = 0.05F;
constexpr float kJumpSigmas = 4.0F;

/// σ_model(z) / z² for the frame's camera, metres⁻¹; 0 when the baseline is unknown.
float sigma_per_z2(const Frame& frame, float subpixel_rms_px) {
  if (frame.stereo_baseline_mm <= 0.0F || frame.intrinsics.fx <= 0.0F) return 0.0F;
  return static_cast<float>(
      stereo_depth_sigma_m(1.0, frame.intrinsics.fx, frame.stereo_baseline_mm, subpixel_rms_px));
}

/// Whether any of the 8 mask bytes starting at `i` has a bit of `bits` set.
bool any_bits8(const uint8_t* mask, size_t i, uint64_t bits) {
  uint64_t word;
  std::memcpy(&word, mask + i, sizeof word);
  return (word & bits) != 0;
}

constexpr uint64_t kEveryByte = 0x0101010101010101ULL;

/// Calls `visit(i)` for every pixel whose mask has a bit of `state_bits` set, in raster order.
/// Skips 8 pixels at a time, since foreground is sparse.
template <typename Visit>
void for_each_marked(const uint8_t* mask, size_t n, uint8_t state_bits, Visit visit) {
  const uint64_t bits = kEveryByte * state_bits;
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    if (!any_bits8(mask, i, bits)) continue;
    for (size_t j = i; j < i + 8; ++j) {
      if ((mask[j] & state_bits) != 0) visit(j);
    }
  }
  for (; i < n; ++i) {
    if ((mask[i] & state_bits) != 0) visit(i);
  }
}

/// The background test for every pixel: kCandidate, kUnknown or kNone. Branch-free so that
/// it vectorises.
void classify(const DepthImage& depth, const BackgroundModel& background, const ForegroundParams& params,
              float sigma_z2, uint8_t* mask) {
  const size_t n = depth.pixels.size();
  const uint16_t* raw = depth.pixels.data();
  const float* mean_m = background.mean_m.data();
  const float* spread_m = background.spread_m.data();
  const float scale_m = depth.depth_scale_m;
  const float k_sigma = params.k_sigma;
  const float k_model = params.k_sigma * sigma_z2;
  const float min_margin_m = params.min_margin_m;
  for (size_t i = 0; i < n; ++i) {
    const float z = static_cast<float>(raw[i]) * scale_m;
    const float m = mean_m[i];
    const float a = k_sigma * spread_m[i];
    const float b = k_model * z * z;
    const float ab = a > b ? a : b;
    const float margin = ab > min_margin_m ? ab : min_margin_m;
    // Bitwise & instead of && keeps the loop free of branches.
    const unsigned valid = raw[i] != 0;
    const unsigned known = m > 0.0F;
    const unsigned nearer = z < m - margin;
    mask[i] = static_cast<uint8_t>((valid & known & nearer) * kCandidate | (valid & (known ^ 1U)) * kUnknown);
  }
}

/// How pixels become rays: the pinhole tables when the intrinsics have no distortion to undo.
struct Rays {
  const Intrinsics* intrinsics;
  bool pinhole;
  const float* x;  ///< (u − ppx) / fx per column, computed in float as the SDK does
  const float* y;  ///< (v − ppy) / fy per row
};

/// The camera-frame point of pixel (u, v) at depth z_m; false if it cannot be deprojected.
bool camera_point(const Rays& rays, int u, int v, float z_m, Eigen::Vector3f& p_camera) {
  if (rays.pinhole) {
    p_camera = {z_m * rays.x[u], z_m * rays.y[v], z_m};
    return true;
  }
  const auto p = deproject(*rays.intrinsics, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), z_m);
  if (p) p_camera = *p;
  return p.has_value();
}

/// Connection rule of the flood fill: neighbours join when their depths differ by less than
/// the jump limit max(kJumpMinM, kJumpSigmas · σ_model(z)) at the farther of the two depths.
struct Connectivity {
  float jump_min_raw;   ///< kJumpMinM in raw units
  float jump_per_raw2;  ///< the σ term in raw units per raw unit²
  /// The jump limit at raw depth r, rounded up: for integer steps d, d < limit ⇔ d < ceil(limit).
  int limit_raw(int r) const {
    const float far = static_cast<float>(r);
    const float limit = std::max(jump_min_raw, jump_per_raw2 * far * far);
    const int whole = static_cast<int>(limit);  // std::ceil is a library call without SSE4.1
    return whole + (static_cast<float>(whole) < limit ? 1 : 0);
  }
};

/// Flood-fills the blob of candidates around `seed` (packed) into queue[0, returned count) and
/// adds its raw depths to `raw_sum`. Entries pack a pixel as v << 16 | u, so that bounds need
/// no division. `queue` must have room for every pixel.
size_t fill_blob(const DepthImage& depth, const Connectivity& link, int32_t seed, uint8_t* mask,
                 int32_t* queue, uint64_t& raw_sum) {
  const int width = depth.width;
  const int height = depth.height;
  const uint16_t* raw = depth.pixels.data();
  size_t tail = 0;
  queue[tail++] = seed;
  mask[static_cast<size_t>(seed >> 16) * width + (seed & 0xFFFF)] = kVisited;
  // A queue that keeps its popped entries: afterwards it lists the whole blob.
  for (size_t head = 0; head < tail; ++head) {
    const int32_t packed = queue[head];
    const int u = packed & 0xFFFF;
    const int v = packed >> 16;
    const int r = raw[static_cast<size_t>(v) * width + u];
    raw_sum += static_cast<uint64_t>(r);
    // The limit at r covers every neighbour not farther than r; only a neighbour both farther
    // and beyond that limit needs its own (larger) limit.
    const int limit = link.limit_raw(r);
    const int u0 = u > 0 ? u - 1 : 0;
    const int u1 = u + 1 < width ? u + 1 : u;
    const int v0 = v > 0 ? v - 1 : 0;
    const int v1 = v + 1 < height ? v + 1 : v;
    for (int nv = v0; nv <= v1; ++nv) {
      const size_t row = static_cast<size_t>(nv) * width;
      for (int nu = u0; nu <= u1; ++nu) {
        if (mask[row + nu] != kCandidate) continue;
        const int rn = raw[row + nu];
        const int step = rn > r ? rn - r : r - rn;
        if (step >= limit && (rn < r || step >= link.limit_raw(rn))) continue;
        mask[row + nu] = kVisited;
        queue[tail++] = nv << 16 | nu;
      }
    }
  }
  return tail;
}

/// Removes blobs smaller than `min_object_mm` and marks the rest kForeground. A blob's size is
/// the side of a square of the same pixel area at the blob's mean depth:
/// sqrt(pixel count) · mean_z / fx, in millimetres. Returns the number of kept pixels.
size_t remove_speckles(const Frame& frame, float jump_per_z2, float min_object_mm, uint8_t* mask,
                       std::vector<int32_t>& queue) {
  const DepthImage& depth = frame.depth;
  const int width = depth.width;
  const float scale_m = depth.depth_scale_m;
  const Connectivity link{kJumpMinM / scale_m, jump_per_z2 * scale_m};
  const double mm_per_raw_px = 1000.0 * scale_m / frame.intrinsics.fx;
  size_t kept = 0;
  for_each_marked(mask, depth.pixels.size(), kCandidate, [&](size_t i) {
    const int32_t seed = static_cast<int32_t>(i / static_cast<size_t>(width)) << 16 |
                         static_cast<int32_t>(i % static_cast<size_t>(width));
    uint64_t raw_sum = 0;
    const size_t count = fill_blob(depth, link, seed, mask, queue.data(), raw_sum);
    // sqrt(count) · (raw_sum / count) · scale / fx, in mm.
    const double size_mm = static_cast<double>(raw_sum) / std::sqrt(static_cast<double>(count)) * mm_per_raw_px;
    const bool keep = size_mm >= min_object_mm;
    const uint8_t state = keep ? kForeground : kNone;
    for (size_t j = 0; j < count; ++j) {
      mask[static_cast<size_t>(queue[j] >> 16) * width + (queue[j] & 0xFFFF)] = state;
    }
    if (keep) kept += count;
  });
  return kept;
}

/// Deprojects every kForeground pixel into `cloud` (camera frame), in raster order. Pixels that
/// cannot be deprojected (a distortion model the SDK cannot invert) leave the mask.
void deproject_mask(const DepthImage& depth, const Rays& rays, size_t kept, uint8_t* mask, PointCloud& cloud) {
  // Resizing within the reserved capacity does not allocate; shrinking writes nothing.
  cloud.x.resize(kept);
  cloud.y.resize(kept);
  cloud.z.resize(kept);
  cloud.pixel.resize(kept);
  float* x = cloud.x.data();
  float* y = cloud.y.data();
  float* z = cloud.z.data();
  uint32_t* pixel = cloud.pixel.data();
  const uint16_t* raw = depth.pixels.data();
  const float scale_m = depth.depth_scale_m;
  const size_t width = static_cast<size_t>(depth.width);
  size_t count = 0;
  for_each_marked(mask, depth.pixels.size(), kForeground, [&](size_t i) {
    const int u = static_cast<int>(i % width);
    const int v = static_cast<int>(i / width);
    Eigen::Vector3f p;
    if (!camera_point(rays, u, v, static_cast<float>(raw[i]) * scale_m, p)) {
      mask[i] = kNone;
      return;
    }
    x[count] = p.x();
    y[count] = p.y();
    z[count] = p.z();
    pixel[count] = static_cast<uint32_t>(i);
    ++count;
  });
  cloud.x.resize(count);
  cloud.y.resize(count);
  cloud.z.resize(count);
  cloud.pixel.resize(count);
}

/// points_base = R · points_camera + t, point by point (float).
void transform_points(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, const PointCloud& in, PointCloud& out) {
  const size_t n = in.size();
  out.x.resize(n);
  out.y.resize(n);
  out.z.resize(n);
  out.pixel.assign(in.pixel.begin(), in.pixel.end());
  const float* __restrict xc = in.x.data();
  // Local copies: the stores below could alias R and t for all the compiler knows.
  const float r00 = R(0, 0), r01 = R(0, 1), r02 = R(0, 2), tx = t.x();
  const float r10 = R(1, 0), r11 = R(1, 1), r12 = R(1, 2), ty = t.y();
  const float r20 = R(2, 0), r21 = R(2, 1), r22 = R(2, 2), tz = t.z();
  const float* __restrict yc = in.y.data();
  const float* __restrict zc = in.z.data();
  float* __restrict xb = out.x.data();
  float* __restrict yb = out.y.data();
  float* __restrict zb = out.z.data();
  for (size_t i = 0; i < n; ++i) {
    xb[i] = r00 * xc[i] + r01 * yc[i] + r02 * zc[i] + tx;
    yb[i] = r10 * xc[i] + r11 * yc[i] + r12 * zc[i] + ty;
    zb[i] = r20 * xc[i] + r21 * yc[i] + r22 * zc[i] + tz;
  }
}

}  // namespace

void ForegroundExtractor::extract(const Frame& frame, const BackgroundModel& background,
                                  const Pose& T_base_camera, Foreground& out) {
  const DepthImage& depth = frame.depth;
  const Intrinsics& intr = frame.intrinsics;
  const size_t width = static_cast<size_t>(depth.width);
  const size_t n = width * static_cast<size_t>(depth.height);
  assert(background.mean_m.size() == n && background.spread_m.size() == n && depth.pixels.size() == n);
  assert(depth.width < 65536 && depth.height < 32768);  // the flood fill packs v << 16 | u
  // Allocates only for the first frame of a size; afterwards these keep their capacity.
  out.mask.resize(n);
  out.points_camera.reserve(n);
  out.points_base.reserve(n);
  stack_.resize(n);
  ray_x_.resize(static_cast<size_t>(depth.width));
  ray_y_.resize(static_cast<size_t>(depth.height));
  for (int u = 0; u < depth.width; ++u) ray_x_[static_cast<size_t>(u)] = (static_cast<float>(u) - intr.ppx) / intr.fx;
  for (int v = 0; v < depth.height; ++v) ray_y_[static_cast<size_t>(v)] = (static_cast<float>(v) - intr.ppy) / intr.fy;
  const Rays rays{&intr, is_pinhole(intr), ray_x_.data(), ray_y_.data()};

  const float sigma_z2 = sigma_per_z2(frame, params.subpixel_rms_px);
  const Eigen::Matrix3f R = T_base_camera.linear().cast<float>();
  const Eigen::Vector3f t = T_base_camera.translation().cast<float>();
  uint8_t* mask = out.mask.data();
  classify(depth, background, params, sigma_z2, mask);

  // Where the background is unknown, only the configured workspace says whether it matters.
  for_each_marked(mask, n, kUnknown, [&](size_t i) {
    const int u = static_cast<int>(i % width);
    const int v = static_cast<int>(i / width);
    Eigen::Vector3f p_camera;
    const bool ok = camera_point(rays, u, v, static_cast<float>(depth.pixels[i]) * depth.depth_scale_m, p_camera);
    mask[i] = ok && params.workspace_base.contains(R * p_camera + t) ? kCandidate : kNone;
  });

  const size_t kept = remove_speckles(frame, kJumpSigmas * sigma_z2, params.min_object_mm, mask, stack_);
  deproject_mask(depth, rays, kept, mask, out.points_camera);
  transform_points(R, t, out.points_camera, out.points_base);
}

}  // namespace hrcsense
