// SPDX-License-Identifier: Apache-2.0
// hrcsense — foreground extraction: background subtraction, speckle removal by physical size
// (a blob's equivalent disc diameter at its depth), deprojection into camera- and base-frame
// point clouds.

#include "foreground_tables.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/segmentation.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>

namespace hrcsense {
namespace {

using segmentation_detail::kJumpMinM;
using segmentation_detail::kJumpSigmas;

// Mask states while a frame is processed; only kNone and kForeground survive extract().
// Each state is its own bit, so that a scan can test many pixels at once for one state.
constexpr uint8_t kNone = 0;
constexpr uint8_t kForeground = 1;  // final: kept after speckle removal
constexpr uint8_t kCandidate = 2;   // passed the background test, not yet flood-filled
constexpr uint8_t kUnknown = 4;     // valid depth where the background was never valid
constexpr uint8_t kVisited = 8;     // in the blob being flood-filled

constexpr uint64_t kEveryByte = 0x0101010101010101ULL;

/// Whether any of the 16 mask bytes starting at `i` has a bit of `bits` (repeated per byte) set.
bool any_bits16(const uint8_t* mask, size_t i, uint64_t bits) {
  uint64_t word[2];
  std::memcpy(word, mask + i, sizeof word);
  return ((word[0] | word[1]) & bits) != 0;
}

/// Calls `visit(i)` for every pixel in [begin, end) whose mask has a bit of `state_bits` set,
/// in raster order. Skips 16 pixels at a time, since foreground is sparse.
template <typename Visit>
void for_each_marked(const uint8_t* mask, size_t begin, size_t end, uint8_t state_bits, Visit& visit) {
  const uint64_t bits = kEveryByte * state_bits;
  size_t i = begin;
  for (; i + 16 <= end; i += 16) {
    if (!any_bits16(mask, i, bits)) continue;
    for (size_t j = i; j < i + 16; ++j) {
      if ((mask[j] & state_bits) != 0) visit(j);
    }
  }
  for (; i < end; ++i) {
    if ((mask[i] & state_bits) != 0) visit(i);
  }
}

/// for_each_marked over the rows [v_begin, v_end) whose `row_states` have a bit of `state_bits`.
template <typename Visit>
void for_each_marked_in_rows(const uint8_t* mask, const uint8_t* row_states, size_t width, size_t v_begin,
                             size_t v_end, uint8_t state_bits, Visit visit) {
  for (size_t v = v_begin; v < v_end; ++v) {
    if ((row_states[v] & state_bits) != 0) for_each_marked(mask, v * width, (v + 1) * width, state_bits, visit);
  }
}

/// The background test for every pixel, one 16-bit comparison each: kCandidate where the raw
/// depth is valid and below the pixel's threshold, kUnknown where it is valid and the
/// background unknown, else kNone. Also ORs each row's states into `row_states`, so that the
/// scans after it skip empty rows. Branch-free so that it vectorises.
void classify(const DepthImage& depth, const uint16_t* nearer_count, const uint8_t* unknown, uint8_t* mask,
              uint8_t* row_states) {
  const size_t width = static_cast<size_t>(depth.width);
  for (size_t v = 0; v < static_cast<size_t>(depth.height); ++v) {
    // Row pointers that do not alias, so that the loop needs no run-time overlap checks.
    const uint16_t* __restrict raw = depth.pixels.data() + v * width;
    const uint16_t* __restrict count = nearer_count + v * width;
    const uint8_t* __restrict unknown_row = unknown + v * width;
    uint8_t* __restrict out = mask + v * width;
    unsigned states = 0;
    for (size_t u = 0; u < width; ++u) {
      // raw − 1 wraps 0 ("no data") to 65535, which no count exceeds.
      const uint8_t candidate = static_cast<uint16_t>(raw[u] - 1U) < count[u] ? kCandidate : kNone;
      const uint8_t valid = raw[u] != 0 ? 0xFF : 0x00;  // a mask, not a branch around a load
      const uint8_t state = static_cast<uint8_t>(candidate | (unknown_row[u] & valid));
      out[u] = state;
      states |= state;
    }
    row_states[v] = static_cast<uint8_t>(states);
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

/// Queues neighbour `ni` (packed `packed_n`) of a pixel at raw depth r, whose jump limit is
/// limit_r, if it is an unvisited candidate within the jump limit at the farther of the two
/// depths (foreground_tables.hpp).
inline void join(const uint16_t* raw, uint8_t* mask, int32_t* queue, const int32_t* limit, size_t ni,
                 int32_t packed_n, int r, int limit_r, size_t& tail) {
  if (mask[ni] != kCandidate) return;
  const int rn = raw[ni];
  const int step = rn > r ? rn - r : r - rn;
  // The limit at r covers every neighbour not farther than r; only a neighbour both farther
  // and beyond that limit needs its own (larger) limit.
  if (step >= limit_r && (rn < r || step >= limit[rn])) return;
  mask[ni] = kVisited;
  queue[tail++] = packed_n;
}

/// The blob a flood fill found: queue[0, count) lists its pixels.
struct Blob {
  size_t count = 0;
  uint64_t raw_sum = 0;  ///< sum of its raw depths
  int v_max = 0;         ///< its lowest row
};

/// Flood-fills the blob of candidates around `seed` (packed v << 16 | u) into `queue`, which
/// must have room for every pixel. `limit` is the jump limit per raw depth.
Blob fill_blob(const DepthImage& depth, const int32_t* limit, int32_t seed, uint8_t* mask, int32_t* queue) {
  // Locals rather than members or references: every byte store into the mask may alias
  // anything for the compiler, which would otherwise reload them per pixel.
  const uint16_t* raw = depth.pixels.data();
  const int width = depth.width;
  const int height = depth.height;
  const size_t w = static_cast<size_t>(width);
  constexpr int32_t kRow = 1 << 16;  // one row down, packed
  size_t tail = 0;
  queue[tail++] = seed;
  mask[static_cast<size_t>(seed >> 16) * w + static_cast<size_t>(seed & 0xFFFF)] = kVisited;
  // A queue that keeps its popped entries: afterwards it lists the whole blob.
  for (size_t head = 0; head < tail; ++head) {
    const int32_t packed = queue[head];
    const int u = packed & 0xFFFF;
    const int v = packed >> 16;
    const size_t i = static_cast<size_t>(v) * w + static_cast<size_t>(u);
    const int r = raw[i];
    const int limit_r = limit[r];
    if (u > 0 && u + 1 < width && v > 0 && v + 1 < height) {
      // Inside the image (nearly every pixel): fixed offsets, no bounds.
      join(raw, mask, queue, limit, i - w - 1, packed - kRow - 1, r, limit_r, tail);
      join(raw, mask, queue, limit, i - w, packed - kRow, r, limit_r, tail);
      join(raw, mask, queue, limit, i - w + 1, packed - kRow + 1, r, limit_r, tail);
      join(raw, mask, queue, limit, i - 1, packed - 1, r, limit_r, tail);
      join(raw, mask, queue, limit, i + 1, packed + 1, r, limit_r, tail);
      join(raw, mask, queue, limit, i + w - 1, packed + kRow - 1, r, limit_r, tail);
      join(raw, mask, queue, limit, i + w, packed + kRow, r, limit_r, tail);
      join(raw, mask, queue, limit, i + w + 1, packed + kRow + 1, r, limit_r, tail);
      continue;
    }
    for (int nv = v > 0 ? v - 1 : 0; nv <= (v + 1 < height ? v + 1 : v); ++nv) {
      for (int nu = u > 0 ? u - 1 : 0; nu <= (u + 1 < width ? u + 1 : u); ++nu) {
        join(raw, mask, queue, limit, static_cast<size_t>(nv) * w + static_cast<size_t>(nu), nv << 16 | nu, r,
             limit_r, tail);
      }
    }
  }
  // Sums in a pass of their own: inside the fill they would be two more live registers.
  Blob blob{tail, 0, seed >> 16};
  for (size_t j = 0; j < tail; ++j) {
    const int v = queue[j] >> 16;
    blob.raw_sum += raw[static_cast<size_t>(v) * w + static_cast<size_t>(queue[j] & 0xFFFF)];
    blob.v_max = v > blob.v_max ? v : blob.v_max;
  }
  return blob;
}

/// Which pixels are left after speckle removal.
struct Kept {
  size_t count = 0;  ///< kForeground pixels
  size_t v_begin = 0, v_end = 0;  ///< they lie in rows [v_begin, v_end)
};

/// Removes blobs smaller than `min_object_mm` and marks the rest kForeground. A blob's size is
/// the diameter of a disc of the same pixel area at the blob's mean depth:
/// 2 · sqrt(pixel count / π) · mean_z / fx, in millimetres. A disc, not a square, because the
/// detection capability d (`safety.detection_mm`) is the diameter of a test piece (a sphere or
/// rod, ISO 13855): a square of side d has 4/π times a d-disc's area, so a 40 mm ball measured
/// as a square came out 35 mm and was removed at min_object_mm 40.
Kept remove_speckles(const Frame& frame, const int32_t* jump_limit_raw, float min_object_mm,
                     const uint8_t* row_states, uint8_t* mask, int32_t* queue) {
  const DepthImage& depth = frame.depth;
  const size_t width = static_cast<size_t>(depth.width);
  // 2 / sqrt(π) folded into the per-raw-unit factor: one multiplication per blob.
  const double mm_per_raw_px = 2.0 / std::sqrt(kPi) * 1000.0 * depth.depth_scale_m / frame.intrinsics.fx;
  Kept kept;
  for_each_marked_in_rows(mask, row_states, width, 0, static_cast<size_t>(depth.height), kCandidate, [&](size_t i) {
    const int v = static_cast<int>(i / width);
    const Blob blob = fill_blob(depth, jump_limit_raw, v << 16 | static_cast<int32_t>(i % width), mask, queue);
    // 2 · sqrt(count / π) · (raw_sum / count) · scale / fx = raw_sum / sqrt(count) · mm_per_raw_px, in mm.
    const double size_mm =
        static_cast<double>(blob.raw_sum) / std::sqrt(static_cast<double>(blob.count)) * mm_per_raw_px;
    const bool keep = size_mm >= min_object_mm;
    const uint8_t state = keep ? kForeground : kNone;
    for (size_t j = 0; j < blob.count; ++j) {
      mask[static_cast<size_t>(queue[j] >> 16) * width + static_cast<size_t>(queue[j] & 0xFFFF)] = state;
    }
    if (!keep) return;
    // Seeds come in raster order, so the first kept seed's row is the first kept row.
    if (kept.count == 0) kept.v_begin = static_cast<size_t>(v);
    kept.v_end = std::max(kept.v_end, static_cast<size_t>(blob.v_max) + 1);
    kept.count += blob.count;
  });
  return kept;
}

/// Deprojects every kForeground pixel into `cloud` (camera frame), in raster order. Pixels that
/// cannot be deprojected (a distortion model the SDK cannot invert) leave the mask.
void deproject_mask(const DepthImage& depth, const Rays& rays, const Kept& kept, uint8_t* mask, PointCloud& cloud) {
  // Resizing within the reserved capacity does not allocate; shrinking writes nothing.
  cloud.x.resize(kept.count);
  cloud.y.resize(kept.count);
  cloud.z.resize(kept.count);
  cloud.pixel.resize(kept.count);
  float* x = cloud.x.data();
  float* y = cloud.y.data();
  float* z = cloud.z.data();
  uint32_t* pixel = cloud.pixel.data();
  const uint16_t* raw = depth.pixels.data();
  const float scale_m = depth.depth_scale_m;
  const size_t width = static_cast<size_t>(depth.width);
  size_t count = 0;
  auto visit = [&](size_t i) {
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
  };
  for_each_marked(mask, kept.v_begin * width, kept.v_end * width, kForeground, visit);
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

/// Where the background is unknown (kUnknown), only the configured workspace says whether a
/// pixel matters: kCandidate inside `workspace_base`, else kNone. Rows that had unknown pixels
/// may now hold candidates, and their `row_states` say so.
void keep_unknown_in_workspace(const DepthImage& depth, const Rays& rays, const Eigen::Matrix3f& R,
                               const Eigen::Vector3f& t, const AlignedBox& workspace_base, uint8_t* mask,
                               uint8_t* row_states) {
  const size_t width = static_cast<size_t>(depth.width);
  const size_t height = static_cast<size_t>(depth.height);
  for_each_marked_in_rows(mask, row_states, width, 0, height, kUnknown, [&](size_t i) {
    const int u = static_cast<int>(i % width);
    const int v = static_cast<int>(i / width);
    Eigen::Vector3f p_camera;
    const bool ok = camera_point(rays, u, v, static_cast<float>(depth.pixels[i]) * depth.depth_scale_m, p_camera);
    mask[i] = ok && workspace_base.contains(R * p_camera + t) ? kCandidate : kNone;
  });
  for (size_t v = 0; v < height; ++v) {
    if ((row_states[v] & kUnknown) != 0) row_states[v] |= kCandidate;
  }
}

constexpr uint8_t kArmMix = 16;  // a candidate found to be a mix of the arm and what lies behind it

/// A candidate inside the robot's silhouette but beyond its padded far side (`raw` over
/// robot.to_raw) is the filters' mix of the arm and the surface behind it when, within
/// robot.smear_px, there is both a pixel of the arm nearer than it and a pixel that is not
/// foreground: the background farther than it, or no depth. Decimation's median of four and the
/// spatial filter's smoothing put such depths along the arm's rim, between its two sides, where
/// no surface is. Something real behind the arm has candidates of its own depth around it, not
/// only the arm and the background, and stays (docs/ROBOT.md, "Self-filter", step 4).
bool arm_mix(const DepthImage& depth, const RobotPixels& robot, const uint8_t* mask, size_t i) {
  const int width = depth.width;
  const int u = static_cast<int>(i % static_cast<size_t>(width));
  const int v = static_cast<int>(i / static_cast<size_t>(width));
  const uint16_t raw = depth.pixels[i];
  bool arm_nearer = false, background_farther = false;
  for (int vv = std::max(0, v - robot.smear_px); vv <= std::min(depth.height - 1, v + robot.smear_px); ++vv) {
    for (int uu = std::max(0, u - robot.smear_px); uu <= std::min(width - 1, u + robot.smear_px); ++uu) {
      const size_t j = static_cast<size_t>(vv) * static_cast<size_t>(width) + static_cast<size_t>(uu);
      const uint16_t other = depth.pixels[j];
      if (other != 0 && robot.contains(j, other)) {
        arm_nearer = arm_nearer || other < raw;
      } else if ((mask[j] & (kCandidate | kArmMix)) == 0) {
        // The background, or a hole: beside an edge the sensor and the filters lose depth
        // where the two sides disagree, and the mix came from the far side all the same.
        background_farther = background_farther || other == 0 || other > raw;
      }
    }
  }
  return arm_nearer && background_farther;
}

/// Clears the candidates that are the robot's own pixels (SelfFilter::robot_pixels()), and the
/// mixes of the arm and its background at its rim (arm_mix); returns how many. Done before
/// speckle removal, so that the fringe the self-filter leaves around the arm is judged by its
/// own size, not as part of the arm's blob.
size_t remove_robot_pixels(const DepthImage& depth, const RobotPixels& robot, const uint8_t* row_states,
                           uint8_t* mask) {
  size_t removed = 0;
  const size_t width = static_cast<size_t>(depth.width);
  const size_t height = static_cast<size_t>(depth.height);
  for_each_marked_in_rows(mask, row_states, width, 0, height, kCandidate, [&](size_t i) {
    if (robot.contains(i, depth.pixels[i])) {
      mask[i] = kNone;
      ++removed;
    }
  });
  if (robot.smear_px <= 0) return removed;
  // Mixes are marked first and cleared after, so that one mix never makes its neighbour look
  // like the background behind it.
  for_each_marked_in_rows(mask, row_states, width, 0, height, kCandidate, [&](size_t i) {
    if (robot.from_raw[i] != 0 && depth.pixels[i] > robot.to_raw[i] && arm_mix(depth, robot, mask, i)) {
      mask[i] = kArmMix;
      ++removed;
    }
  });
  auto clear = [&](size_t i) { mask[i] = kNone; };
  for (size_t v = 0; v < height; ++v) {
    if ((row_states[v] & kCandidate) != 0) for_each_marked(mask, v * width, (v + 1) * width, kArmMix, clear);
  }
  return removed;
}

}  // namespace

void ForegroundExtractor::set_background(const BackgroundModel& background, float fx_px, float stereo_baseline_mm,
                                         float depth_scale_m) {
  namespace detail = segmentation_detail;
  const size_t n = static_cast<size_t>(background.width) * static_cast<size_t>(background.height);
  assert(background.mean_m.size() == n && background.spread_m.size() == n);
  const float sigma_z2 = detail::sigma_per_z2(fx_px, stereo_baseline_mm, params.subpixel_rms_px);
  const detail::NearerTest test{depth_scale_m, params.k_sigma, params.k_sigma * sigma_z2, params.min_margin_m};
  nearer_count_.resize(n);
  unknown_.resize(n);
  detail::build_nearer_table(background, test, kUnknown, nearer_count_.data(), unknown_.data());
  jump_limit_raw_.resize(65536);
  detail::build_jump_limits(depth_scale_m, kJumpSigmas * sigma_z2, jump_limit_raw_.data());
  width_ = background.width;
  height_ = background.height;
  fx_px_ = fx_px;
  stereo_baseline_mm_ = stereo_baseline_mm;
  depth_scale_m_ = depth_scale_m;
  prepared_params_ = params;
  prepared_ = true;
}

bool ForegroundExtractor::prepared_for(const Frame& frame) const {
  // Only the parameters the tables depend on; the others are read per frame.
  return prepared_ && frame.depth.width == width_ && frame.depth.height == height_ &&
         frame.depth.pixels.size() == nearer_count_.size() && frame.intrinsics.fx == fx_px_ &&
         frame.stereo_baseline_mm == stereo_baseline_mm_ && frame.depth.depth_scale_m == depth_scale_m_ &&
         params.k_sigma == prepared_params_.k_sigma && params.min_margin_m == prepared_params_.min_margin_m &&
         params.subpixel_rms_px == prepared_params_.subpixel_rms_px;
}

bool ForegroundExtractor::extract(const Frame& frame, const Pose& T_base_camera, Foreground& out,
                                  const RobotPixels* robot) {
  out.self_filtered_pixels = 0;
  if (!prepared_for(frame)) {
    out.mask.clear();
    out.points_camera.clear();
    out.points_base.clear();
    return false;
  }
  const DepthImage& depth = frame.depth;
  const Intrinsics& intr = frame.intrinsics;
  const size_t width = static_cast<size_t>(depth.width);
  const size_t height = static_cast<size_t>(depth.height);
  const size_t n = width * height;
  assert(depth.width < 65536 && depth.height < 32768);  // the flood fill packs v << 16 | u
  // Allocates only for the first frame of a size; afterwards these keep their capacity.
  out.mask.resize(n);
  out.points_camera.reserve(n);
  out.points_base.reserve(n);
  stack_.resize(n);
  row_states_.resize(height);
  ray_x_.resize(width);
  ray_y_.resize(height);
  for (size_t u = 0; u < width; ++u) ray_x_[u] = (static_cast<float>(u) - intr.ppx) / intr.fx;
  for (size_t v = 0; v < height; ++v) ray_y_[v] = (static_cast<float>(v) - intr.ppy) / intr.fy;
  const Rays rays{&intr, is_pinhole(intr), ray_x_.data(), ray_y_.data()};

  const Eigen::Matrix3f R = T_base_camera.linear().cast<float>();
  const Eigen::Vector3f t = T_base_camera.translation().cast<float>();
  uint8_t* mask = out.mask.data();
  classify(depth, nearer_count_.data(), unknown_.data(), mask, row_states_.data());
  keep_unknown_in_workspace(depth, rays, R, t, params.workspace_base, mask, row_states_.data());
  if (robot != nullptr) out.self_filtered_pixels = remove_robot_pixels(depth, *robot, row_states_.data(), mask);

  const Kept kept = remove_speckles(frame, jump_limit_raw_.data(), params.min_object_mm, row_states_.data(), mask,
                                    stack_.data());
  deproject_mask(depth, rays, kept, mask, out.points_camera);
  transform_points(R, t, out.points_camera, out.points_base);
  return true;
}

}  // namespace hrcsense
