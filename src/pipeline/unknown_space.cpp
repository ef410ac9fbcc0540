// SPDX-License-Identifier: Apache-2.0
// hrcsense — unknown space near the robot (unknown_space.hpp).
//
// Speed (issue A4): most of a frame is measured background or needs no more than counting, so
// runs of 64 pixels are first tested for measured background as a whole, the rest classified
// 16 at a time into bit masks (unknown_space_blocks.hpp), and only the foreground, reliable
// gaps and (where a gap follows) the envelope are visited. The envelope buffer is read only
// inside the self-filter's rectangle (RobotPixels' bounds), the one place it can be nonzero,
// and the background's reliability as one bit per pixel (ReliableBackground), prepared once
// per background: read as floats, it cost two cache misses at every block with a gap.
// Most unknown rays pass far from the robot, so a block's rays are tested together, then one
// by one, against spheres around the whole robot and around each capsule (four capsules at a
// time, unknown_space_spheres.hpp), and the exact segment-to-capsule distance is computed only
// where a sphere comes nearer than the smallest distance found so far. The distance reported
// is the same, bit for bit: what is skipped cannot be smaller than what was found, and the
// minimum does not depend on the order.

#include "hrcsense/unknown_space.hpp"

#include "unknown_space_blocks.hpp"
#include "unknown_space_spheres.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace hrcsense {
namespace {

// A sphere skips a ray only when it stays this much farther than the smallest distance found:
// far above the float rounding of both the bound and the exact path (~1e-6 m at cell scale),
// so a skipped capsule could never have given a smaller distance.
constexpr float kSkipMargin_m = 1e-3F;
// Capsules with a sphere of their own; a larger robot is bounded by its enclosing sphere only
// and measured exactly against every capsule (no allocation on the hot path).
constexpr size_t kMaxBoundedCapsules = unknown_space_detail::kMaxSpheres;

// Squared distance between segments [p0, p1] and [q0, q1]: the closest pair's parameters
// clamped to [0, 1] (the usual two-step clamp), in double so that nearly parallel segments
// stay exact enough.
double segment_segment_distance_sq(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                                   const Eigen::Vector3d& q1) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 1e-18 && e <= 1e-18) return r.squaredNorm();
  if (a <= 1e-18) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 1e-18) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-18 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p0 + s * d1) - (q0 + t * d2)).squaredNorm();
}

// The distance from segment [a, b] to one capsule's surface, as segment_capsule_distance takes
// its minimum: every path computes it with this one function.
double capsule_surface_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Capsule& capsule) {
  const double d = std::sqrt(segment_segment_distance_sq(a, b, capsule.a.cast<double>(), capsule.b.cast<double>()));
  return std::max(0.0, d - capsule.radius_m);
}

// A sphere enclosing a capsule (or the whole robot), its centre relative to the camera's
// centre in the base frame.
struct Sphere {
  Eigen::Vector3f centre_from_camera = Eigen::Vector3f::Zero();
  float radius_m = 0.0F;
};

// What the per-ray test needs, gathered once per frame. A ray's segment is
// camera + z·direction for z in [z0, z1], with direction = linear·((u − ppx)/fx, (v − ppy)/fy, 1)
// in the base frame: the same points ray_segment computes.
struct RayBounds {
  Eigen::Vector3f camera_base = Eigen::Vector3f::Zero();
  Eigen::Matrix3f linear = Eigen::Matrix3f::Identity();
  float ppx = 0.0F, ppy = 0.0F, inv_fx = 1.0F, inv_fy = 1.0F;
  float column_x_norm = 1.0F;  ///< |linear·(1, 0, 0)|: how far rays part per unit of x
  Sphere robot;
  unknown_space_detail::SphereLanes capsules;  ///< sphere c around capsule c
  bool per_capsule = false;                    ///< capsules holds one sphere per capsule of the robot
};

RayBounds make_ray_bounds(const Intrinsics& intrinsics, const Pose& T_base_camera, const RobotModel& robot) {
  RayBounds bounds;
  bounds.camera_base = T_base_camera.translation().cast<float>();
  bounds.linear = T_base_camera.linear().cast<float>();
  bounds.ppx = intrinsics.ppx;
  bounds.ppy = intrinsics.ppy;
  bounds.inv_fx = 1.0F / intrinsics.fx;
  bounds.inv_fy = 1.0F / intrinsics.fy;
  bounds.column_x_norm = bounds.linear.col(0).norm();
  Eigen::Vector3f lo = robot.capsules.front().a, hi = lo;
  for (const Capsule& c : robot.capsules) {
    lo = lo.cwiseMin(c.a).cwiseMin(c.b);
    hi = hi.cwiseMax(c.a).cwiseMax(c.b);
  }
  const Eigen::Vector3f centre = 0.5F * (lo + hi);
  float radius_m = 0.0F;
  for (const Capsule& c : robot.capsules) {
    radius_m = std::max(radius_m, std::max((c.a - centre).norm(), (c.b - centre).norm()) + c.radius_m);
  }
  bounds.robot = {centre - bounds.camera_base, radius_m};
  bounds.per_capsule = robot.capsules.size() <= kMaxBoundedCapsules;
  for (size_t i = 0; bounds.per_capsule && i < robot.capsules.size(); ++i) {
    const Capsule& c = robot.capsules[i];
    const Eigen::Vector3f centre_from_camera = 0.5F * (c.a + c.b) - bounds.camera_base;
    bounds.capsules.x[i] = centre_from_camera.x();
    bounds.capsules.y[i] = centre_from_camera.y();
    bounds.capsules.z[i] = centre_from_camera.z();
    bounds.capsules.radius_m[i] = 0.5F * (c.b - c.a).norm() + c.radius_m;
    bounds.capsules.count = static_cast<int>(i) + 1;
  }
  return bounds;
}

// True when the ray's segment stays farther than reach_m from the sphere's surface: its point
// nearest the centre (the projection, clamped to [z0, z1]) is. NaN anywhere never skips.
bool beyond(const Eigen::Vector3f& direction, float inv_direction_sq, float z0_m, float z1_m, const Sphere& sphere,
            float reach_m) {
  const Eigen::Vector3f& w = sphere.centre_from_camera;
  const float z = std::clamp(w.dot(direction) * inv_direction_sq, z0_m, z1_m);
  const float limit_m = sphere.radius_m + reach_m;
  return (w - z * direction).squaredNorm() > limit_m * limit_m;
}

// One frame's inputs to the pixel loop.
struct PixelScan {
  unknown_space_detail::BlockInputs blocks;
  unknown_space_detail::BlockInputs blocks_without_envelope;  ///< the same, envelope_from_raw null
  // Where the envelope can be (RobotPixels' bounds): columns [u0, u1), rows [v0, v1).
  int envelope_u0 = 0, envelope_u1 = 0, envelope_v0 = 0, envelope_v1 = 0;
  const DepthImage* depth = nullptr;
  const uint8_t* no_depth_frames = nullptr;  ///< null: every gap counts at once
  double fx_b = 0.0;                         ///< px·m: shadow width = fx·B·(1/z_fg − 1/z_bg)
  UnknownSpaceParams params;
  // For measure_ray.
  const Intrinsics* intrinsics = nullptr;
  const Pose* T_base_camera = nullptr;
  const RobotModel* robot = nullptr;
  RayBounds bounds;
};

constexpr float kNoRay = std::numeric_limits<float>::quiet_NaN();

// The nearest envelope pixel to the right in the row being scanned (right to left).
struct Envelope {
  int u = -1;
  float z_m = 0.0F;
};

// One unknown ray of a block's row: pixel column u, from depth z0 to z1 (m). Left
// uninitialised in a RayGroup: only rays [0, count) are written and read, and zeroing 16 of
// them for every visited block cost as much as the visit.
struct Ray {
  int u;
  float z0_m;
  float z1_m;
};

struct RayGroup {
  std::array<Ray, unknown_space_detail::kBlockPx> rays;
  int count = 0;
};

// The base-frame direction of the ray through (u, v): its points are camera + z·direction.
Eigen::Vector3f ray_direction(const RayBounds& b, float u, int v) {
  const float x = (u - b.ppx) * b.inv_fx;
  const float y = (static_cast<float>(v) - b.ppy) * b.inv_fy;
  return b.linear * Eigen::Vector3f(x, y, 1.0F);
}

unknown_space_detail::RaySpan ray_span(const Eigen::Vector3f& direction, float z0_m, float z1_m) {
  unknown_space_detail::RaySpan span;
  span.dx = direction.x();
  span.dy = direction.y();
  span.dz = direction.z();
  span.inv_direction_sq = 1.0F / direction.squaredNorm();
  span.z0_m = z0_m;
  span.z1_m = z1_m;
  return span;
}

// Lowers best_m to the ray's distance to the capsules in `near` (bit c: capsule c), measuring
// exactly (ray_segment, segment-to-capsule in double) those its own bound does not skip. A
// skipped capsule is farther than best_m, so leaving it out of the minimum cannot change
// min(best_m, the ray's distance to every capsule).
void measure_ray(const PixelScan& scan, int v, const Ray& ray, uint32_t near, float& best_m) {
  const RayBounds& b = scan.bounds;
  const float reach_m = best_m + kSkipMargin_m;  // infinite until a ray was measured: no skips
  const unknown_space_detail::RaySpan span = ray_span(ray_direction(b, static_cast<float>(ray.u), v), ray.z0_m, ray.z1_m);
  uint32_t measured = unknown_space_detail::spheres_within(b.capsules, span, reach_m, near);
  if (measured == 0) return;
  const RaySegment s = ray_segment(*scan.intrinsics, *scan.T_base_camera, ray.u, v, ray.z0_m, ray.z1_m);
  const Eigen::Vector3d from = s.from_base.cast<double>(), to = s.to_base.cast<double>();
  double ray_best = std::numeric_limits<double>::infinity();
  for (; measured != 0; measured &= measured - 1) {
    ray_best = std::min(ray_best, capsule_surface_distance(from, to, scan.robot->capsules[__builtin_ctz(measured)]));
  }
  best_m = std::min(best_m, static_cast<float>(ray_best));
}

// The rays of one block (at least one), tested together first: each lies within slack_m of
// the group's middle ray at the same depth, so a sphere farther than reach + slack from the
// middle ray over all their depths is farther than reach from every one of them.
void measure_rays(const PixelScan& scan, int v, const RayGroup& group, float& best_m) {
  const RayBounds& b = scan.bounds;
  int u_min = group.rays[0].u, u_max = u_min;
  float z0_m = group.rays[0].z0_m, z1_m = group.rays[0].z1_m;
  for (int r = 1; r < group.count; ++r) {
    u_min = std::min(u_min, group.rays[r].u);
    u_max = std::max(u_max, group.rays[r].u);
    z0_m = std::min(z0_m, group.rays[r].z0_m);
    z1_m = std::max(z1_m, group.rays[r].z1_m);
  }
  const Eigen::Vector3f middle = ray_direction(b, 0.5F * static_cast<float>(u_min + u_max), v);
  const float inv_middle_sq = 1.0F / middle.squaredNorm();
  const float slack_m = std::max(std::fabs(z0_m), std::fabs(z1_m)) * 0.5F * static_cast<float>(u_max - u_min) *
                        std::fabs(b.inv_fx) * b.column_x_norm;
  const float reach_m = best_m + kSkipMargin_m + slack_m;
  if (beyond(middle, inv_middle_sq, z0_m, z1_m, b.robot, reach_m)) return;
  if (!b.per_capsule) {  // too many capsules for spheres of their own: measure every one
    for (int r = 0; r < group.count; ++r) {
      const Ray& ray = group.rays[r];
      const RaySegment s = ray_segment(*scan.intrinsics, *scan.T_base_camera, ray.u, v, ray.z0_m, ray.z1_m);
      best_m = std::min(best_m, segment_capsule_distance(s.from_base, s.to_base, *scan.robot));
    }
    return;
  }
  const uint32_t near = unknown_space_detail::spheres_within(b.capsules, ray_span(middle, z0_m, z1_m), reach_m,
                                                             unknown_space_detail::sphere_bits(b.capsules.count));
  for (int r = 0; near != 0 && r < group.count; ++r) measure_ray(scan, v, group.rays[r], near, best_m);
}

// Set bits; without a POPCNT instruction in the baseline x86-64 target __builtin_popcount is
// a library call, and a loop per bit cost as much again on the shiny table, whose blocks are
// mostly never-valid pixels. Sums of bit pairs, then nibbles, then the bytes by a multiply.
size_t count_bits(uint32_t bits) {
  bits = bits - ((bits >> 1) & 0x55555555U);
  bits = (bits & 0x33333333U) + ((bits >> 2) & 0x33333333U);
  bits = (bits + (bits >> 4)) & 0x0F0F0F0FU;
  return (bits * 0x01010101U) >> 24;
}

// A pixel without depth now over a reliable background (column u): the robot's stereo shadow,
// a dropout or unknown, counted in `out`; the depth (m) its unknown ray starts at, or kNoRay.
float gap_ray_start(const PixelScan& scan, size_t i, int u, const Envelope& envelope, UnknownSpace& out) {
  const float bg = scan.blocks.background_m[i];
  // The robot's stereo shadow lies immediately left of its envelope (docs/SAFETY.md).
  if (envelope.u >= 0 && envelope.z_m > 0.0F && bg > envelope.z_m) {
    const double shadow_px = scan.fx_b * (1.0 / envelope.z_m - 1.0 / bg);
    if (envelope.u - u <= static_cast<int>(std::ceil(shadow_px)) + 1) {
      ++out.robot_shadow_pixels;
      return kNoRay;
    }
  }
  // A pixel that only just lost its depth is most likely the sensor's random dropout (a far
  // wall loses 1-4 % of its pixels each frame); what stays without depth is unknown.
  if (scan.no_depth_frames != nullptr && scan.no_depth_frames[i] < scan.params.min_no_depth_frames) {
    ++out.dropout_pixels;
    return kNoRay;
  }
  ++out.no_depth_pixels;
  return scan.params.near_m;
}

void set_envelope(const PixelScan& scan, size_t i, int u, Envelope& envelope) {
  envelope.u = u;
  envelope.z_m = static_cast<float>(scan.blocks.envelope_from_raw[i]) * scan.depth->depth_scale_m;
}

// The block of pixels from column first_u: counts its kinds and measures its unknown rays,
// visiting the pixels that need it from right to left (the shadow lies left of the envelope).
// No depth where the background was not reliable was unknown when the cell was taught (a
// far wall, a shiny table): it is only counted.
void visit_block(const PixelScan& scan, const unknown_space_detail::BlockKinds& kinds, size_t row_start, int first_u,
                 int v, Envelope& envelope, UnknownSpace& out, float& best_m) {
  out.never_valid_pixels += count_bits(kinds.never_valid);
  out.hidden_pixels += count_bits(kinds.hidden);
  // The envelope matters to the gaps left of it only: without one in the block, its leftmost
  // envelope pixel is all that the blocks to the left need.
  uint32_t todo = kinds.hidden | kinds.gap | (kinds.gap != 0 ? kinds.envelope : 0U);
  RayGroup group;
  while (todo != 0) {
    const int k = 31 - __builtin_clz(todo);  // the rightmost pixel left to visit
    const uint32_t bit = 1U << k;
    todo &= ~bit;
    const int u = first_u + k;
    const size_t i = row_start + static_cast<size_t>(u);
    if ((kinds.envelope & bit) != 0) {  // the arm and its edges
      set_envelope(scan, i, u, envelope);
      continue;
    }
    const float z0_m = (kinds.hidden & bit) != 0 ? static_cast<float>(scan.blocks.raw[i]) * scan.depth->depth_scale_m
                                                 : gap_ray_start(scan, i, u, envelope, out);
    if (std::isnan(z0_m)) continue;  // no ray
    const float bg = scan.blocks.background_m[i];
    if (!(bg > z0_m)) continue;  // nothing hidden behind it
    group.rays[static_cast<size_t>(group.count++)] = Ray{u, z0_m, bg};
  }
  if (kinds.envelope != 0 && kinds.gap == 0) {
    const int u = first_u + __builtin_ctz(kinds.envelope);
    set_envelope(scan, row_start + static_cast<size_t>(u), u, envelope);
  }
  if (group.count != 0) measure_rays(scan, v, group, best_m);
}

// The row's inputs for pixels [first, first + count): without the envelope where they lie
// outside its columns [u0, u1) (RobotPixels: nothing of the robot there), so that most of the
// envelope buffer is never read.
const unknown_space_detail::BlockInputs& inputs_for(const PixelScan& scan, const unknown_space_detail::BlockInputs& row,
                                                    int first, int count) {
  const bool outside = first >= scan.envelope_u1 || first + count <= scan.envelope_u0;
  return outside ? scan.blocks_without_envelope : row;
}

// The block of pixels from column first, if it has any pixel to visit.
void scan_block(const PixelScan& scan, const unknown_space_detail::BlockInputs& row, size_t row_start, int first, int v,
                Envelope& envelope, UnknownSpace& out, float& best_m) {
  const unknown_space_detail::BlockBits bits = unknown_space_detail::block_bits(
      inputs_for(scan, row, first, unknown_space_detail::kBlockPx), row_start + static_cast<size_t>(first));
  if ((bits.no_depth | bits.envelope | bits.foreground) == 0) return;  // measured background only
  visit_block(scan, unknown_space_detail::kinds_of(bits), row_start, first, v, envelope, out, best_m);
}

// Right to left: runs of kSpanBlocks blocks from the row's end (a quiet run skipped at once),
// the whole blocks left over, then the columns left over at the row's start.
void scan_row(const PixelScan& scan, int v, UnknownSpace& out, float& best_m) {
  using unknown_space_detail::kBlockPx;
  constexpr int kSpanPx = unknown_space_detail::kSpanBlocks * kBlockPx;
  const int width = scan.depth->width;
  const size_t row_start = static_cast<size_t>(v) * static_cast<size_t>(width);
  const bool envelope_row = v >= scan.envelope_v0 && v < scan.envelope_v1;
  const unknown_space_detail::BlockInputs& row = envelope_row ? scan.blocks : scan.blocks_without_envelope;
  Envelope envelope;
  int end = width;  // columns [0, end) are left
  for (; end >= kSpanPx; end -= kSpanPx) {
    const int span_first = end - kSpanPx;
    if (unknown_space_detail::span_quiet(inputs_for(scan, row, span_first, kSpanPx),
                                         row_start + static_cast<size_t>(span_first))) {
      continue;
    }
    for (int first = end - kBlockPx; first >= span_first; first -= kBlockPx) {
      scan_block(scan, row, row_start, first, v, envelope, out, best_m);
    }
  }
  for (; end >= kBlockPx; end -= kBlockPx) scan_block(scan, row, row_start, end - kBlockPx, v, envelope, out, best_m);
  if (end <= 0) return;
  const unknown_space_detail::BlockBits bits =
      unknown_space_detail::block_bits_head(inputs_for(scan, row, 0, std::min(width, kBlockPx)), row_start, end, width);
  visit_block(scan, unknown_space_detail::kinds_of(bits), row_start, 0, v, envelope, out, best_m);
}

}  // namespace

RaySegment ray_segment(const Intrinsics& in, const Pose& T_base_camera, int u, int v, float z0_m, float z1_m) {
  const double x = (static_cast<double>(u) - in.ppx) / in.fx;
  const double y = (static_cast<double>(v) - in.ppy) / in.fy;
  const Eigen::Vector3d ray(x, y, 1.0);
  RaySegment segment;
  segment.from_base = (T_base_camera * (ray * z0_m)).cast<float>();
  segment.to_base = (T_base_camera * (ray * z1_m)).cast<float>();
  return segment;
}

float segment_capsule_distance(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, const RobotModel& robot) {
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d a = p0.cast<double>(), b = p1.cast<double>();
  for (const Capsule& capsule : robot.capsules) best = std::min(best, capsule_surface_distance(a, b, capsule));
  return static_cast<float>(best);
}

void count_no_depth_frames(const DepthImage& depth, std::vector<uint8_t>& no_depth_frames) {
  if (no_depth_frames.size() != depth.pixels.size()) no_depth_frames.assign(depth.pixels.size(), 0);
  // Raw pointers and a branch-free body: through the vectors, every uint8_t store could alias
  // the vectors' own bookkeeping and the loop stayed scalar.
  const uint16_t* raw = depth.pixels.data();
  uint8_t* frames = no_depth_frames.data();
  const size_t n = depth.pixels.size();
  for (size_t i = 0; i < n; ++i) {
    const uint8_t next = static_cast<uint8_t>(frames[i] + (frames[i] < 255 ? 1 : 0));
    frames[i] = raw[i] != 0 ? 0 : next;
  }
}


ReliableBackground reliable_background(const BackgroundModel& background, float min_valid_ratio) {
  ReliableBackground out;
  out.pixels = background.mean_m.size();
  out.bits.assign((out.pixels + 7) / 8 + 2, 0);  // reliable_bits16 reads three bytes from any pixel's
  if (background.valid_ratio.size() != out.pixels) return out;
  for (size_t i = 0; i < out.pixels; ++i) {
    // Ordered compares: NaN is neither known nor reliable.
    const bool reliable = background.mean_m[i] > 0.0F && background.valid_ratio[i] >= min_valid_ratio;
    out.bits[i / 8] = static_cast<uint8_t>(out.bits[i / 8] | (reliable ? 1U << (i % 8) : 0U));
  }
  return out;
}

UnknownSpace unknown_space(const DepthImage& depth, const Intrinsics& intrinsics, const BackgroundModel& background,
                           const std::vector<uint8_t>& foreground_mask, const RobotPixels* robot_pixels,
                           const Pose& T_base_camera, const RobotModel& robot, float stereo_baseline_m,
                           const std::vector<uint8_t>& no_depth_frames, const UnknownSpaceParams& params) {
  return unknown_space(depth, intrinsics, background, reliable_background(background, params.min_valid_ratio),
                       foreground_mask, robot_pixels, T_base_camera, robot, stereo_baseline_m, no_depth_frames, params);
}

UnknownSpace unknown_space(const DepthImage& depth, const Intrinsics& intrinsics, const BackgroundModel& background,
                           const ReliableBackground& reliable, const std::vector<uint8_t>& foreground_mask,
                           const RobotPixels* robot_pixels, const Pose& T_base_camera, const RobotModel& robot,
                           float stereo_baseline_m, const std::vector<uint8_t>& no_depth_frames,
                           const UnknownSpaceParams& params) {
  UnknownSpace out;
  const size_t n = depth.pixels.size();
  if (background.mean_m.size() != n || depth.width <= 0 || robot.capsules.empty()) return out;
  PixelScan scan;
  scan.blocks.raw = depth.pixels.data();
  scan.blocks.foreground_mask = foreground_mask.size() == n ? foreground_mask.data() : nullptr;
  scan.blocks.envelope_from_raw = robot_pixels != nullptr ? robot_pixels->from_raw : nullptr;
  scan.blocks.background_m = background.mean_m.data();
  const bool reliable_fits = reliable.pixels == n && reliable.bits.size() >= (n + 7) / 8 + 2;
  scan.blocks.reliable_bits = reliable_fits ? reliable.bits.data() : nullptr;
  scan.blocks_without_envelope = scan.blocks;
  scan.blocks_without_envelope.envelope_from_raw = nullptr;
  if (robot_pixels != nullptr) {
    scan.envelope_u0 = robot_pixels->u0;
    scan.envelope_u1 = robot_pixels->u1;
    scan.envelope_v0 = robot_pixels->v0;
    scan.envelope_v1 = robot_pixels->v1;
  }
  scan.depth = &depth;
  scan.no_depth_frames = no_depth_frames.size() == n ? no_depth_frames.data() : nullptr;
  scan.fx_b = static_cast<double>(intrinsics.fx) * stereo_baseline_m;
  scan.params = params;
  scan.intrinsics = &intrinsics;
  scan.T_base_camera = &T_base_camera;
  scan.robot = &robot;
  scan.bounds = make_ray_bounds(intrinsics, T_base_camera, robot);
  float best_m = std::numeric_limits<float>::infinity();
  for (int v = 0; v < depth.height; ++v) scan_row(scan, v, out, best_m);
  if (std::isfinite(best_m)) out.distance_m = best_m;
  return out;
}

}  // namespace hrcsense
