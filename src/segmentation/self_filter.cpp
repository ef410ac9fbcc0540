// SPDX-License-Identifier: Apache-2.0
// hrcsense — the self-filter: the robot's padded capsules ray-cast into the depth image's
// geometry, the silhouette dilated, and per pixel the raw depth from which on a pixel is the
// robot's.

#include "hrcsense/self_filter.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/segmentation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace hrcsense {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// One capsule in the camera frame, with what every pixel's ray test shares precomputed.
/// A pixel's ray is d = (x, y, 1), so that the ray parameter t of a hit is its depth z.
struct CapsuleRayTerms {
  Eigen::Vector3f a, b;  ///< end points, camera frame
  float ba_ba = 0.0F;    ///< |b − a|²
  float a_ba = 0.0F;     ///< a · (b − a)
  float cylinder_c = 0.0F;  ///< |b − a|² (|a|² − r²) − (a · (b − a))²
  float a_c = 0.0F;      ///< |a|² − r²
  float b_c = 0.0F;      ///< |b|² − r²
};

CapsuleRayTerms ray_terms(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float r) {
  CapsuleRayTerms c;
  c.a = a;
  c.b = b;
  const Eigen::Vector3f ba = b - a;
  c.ba_ba = ba.squaredNorm();
  c.a_ba = a.dot(ba);
  c.a_c = a.squaredNorm() - r * r;
  c.b_c = b.squaredNorm() - r * r;
  c.cylinder_c = c.ba_ba * c.a_c - c.a_ba * c.a_ba;
  return c;
}

/// Where the ray (x, y, 1) is inside the capsule: depths [entry, exit], entry = +inf on a miss.
struct RayInterval {
  float entry;
  float exit;
};

/// The capsule is the union of the finite cylinder and the two end spheres, which overlap, so
/// along a ray it is one interval: from the nearest of their entries to the farthest of their
/// exits (the cylinder's only where the hit lies between the ends). Branch-free, so that a row
/// of pixels vectorises.
inline RayInterval capsule_interval(float x, float y, const CapsuleRayTerms& c) {
  const float dd = x * x + y * y + 1.0F;
  const float inv_dd = 1.0F / dd;
  const float da = x * c.a.x() + y * c.a.y() + c.a.z();
  const float db = x * c.b.x() + y * c.b.y() + c.b.z();
  const float dba = db - da;
  // Cylinder about the axis: t² (|ba|² dd − dba²) + 2 t (dba a·ba − |ba|² da) + cylinder_c = 0.
  const float quad = std::max(c.ba_ba * dd - dba * dba, 1e-12F);
  const float inv_quad = 1.0F / quad;
  const float half = dba * c.a_ba - c.ba_ba * da;
  const float disc = half * half - quad * c.cylinder_c;
  const float root = std::sqrt(std::max(disc, 0.0F));
  const float t_in = (-half - root) * inv_quad;
  const float t_out = (-half + root) * inv_quad;
  const float along_in = t_in * dba - c.a_ba;  // (hit − a) · (b − a)
  const float along_out = t_out * dba - c.a_ba;
  // Non-short-circuit &: no branches, so that the loop over a row vectorises.
  const bool cylinder = disc >= 0.0F;
  const bool in_hit = cylinder & (along_in > 0.0F) & (along_in < c.ba_ba) & (t_in > 0.0F);
  const bool out_hit = cylinder & (along_out > 0.0F) & (along_out < c.ba_ba) & (t_out > 0.0F);
  // End spheres: t² dd − 2 t (d·centre) + |centre|² − r² = 0.
  const float disc_a = da * da - dd * c.a_c;
  const float root_a = std::sqrt(std::max(disc_a, 0.0F));
  const float disc_b = db * db - dd * c.b_c;
  const float root_b = std::sqrt(std::max(disc_b, 0.0F));
  const bool a_hit = (disc_a >= 0.0F) & (da + root_a > 0.0F);
  const bool b_hit = (disc_b >= 0.0F) & (db + root_b > 0.0F);
  const float entry_a = a_hit ? (da - root_a) * inv_dd : kInf;
  const float entry_b = b_hit ? (db - root_b) * inv_dd : kInf;
  const float exit_a = a_hit ? (da + root_a) * inv_dd : 0.0F;
  const float exit_b = b_hit ? (db + root_b) * inv_dd : 0.0F;
  const float entry_cyl = in_hit ? t_in : kInf;
  const float exit_cyl = out_hit ? t_out : 0.0F;
  return {std::min(entry_cyl, std::min(entry_a, entry_b)), std::max(exit_cyl, std::max(exit_a, exit_b))};
}

/// A convex polygon in the image (pixels), for the rows a capsule can cover.
struct ImageHull {
  bool valid = false;
  int count = 0;
  std::array<Eigen::Vector2f, 8> points;  ///< counter-clockwise
  float v_min = 0.0F, v_max = 0.0F;

  /// The hull's [lo, hi] on the row at height v; false when the row misses it.
  bool row_span(float v, float& lo, float& hi) const {
    if (v < v_min || v > v_max) return false;
    lo = std::numeric_limits<float>::infinity();
    hi = -lo;
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector2f& p = points[static_cast<size_t>(i)];
      const Eigen::Vector2f& q = points[static_cast<size_t>((i + 1) % count)];
      if ((p.y() - v) * (q.y() - v) > 0.0F) continue;  // the edge lies above or below the row
      if (p.y() == q.y()) {  // an edge along the row: both its ends
        lo = std::min({lo, p.x(), q.x()});
        hi = std::max({hi, p.x(), q.x()});
        continue;
      }
      const float u = p.x() + (v - p.y()) * (q.x() - p.x()) / (q.y() - p.y());
      lo = std::min(lo, u);
      hi = std::max(hi, u);
    }
    return lo <= hi;
  }
};

float cross(const Eigen::Vector2f& o, const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

/// The image hull of the capsule a–b of radius r (camera frame): the convex hull of the corners
/// of its two end spheres' projected bounding boxes. Invalid when a box reaches within 1 mm of
/// the camera plane or behind it.
ImageHull capsule_hull(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float r, const Intrinsics& intr) {
  ImageHull hull;
  std::array<Eigen::Vector2f, 8> corners;
  int n = 0;
  for (const Eigen::Vector3f& c : {a, b}) {
    if (c.z() - r <= 1e-3F) return hull;
    float u_min = std::numeric_limits<float>::infinity(), u_max = -u_min, v_min = u_min, v_max = -u_min;
    for (int corner = 0; corner < 8; ++corner) {
      const float x = c.x() + ((corner & 1) != 0 ? r : -r);
      const float y = c.y() + ((corner & 2) != 0 ? r : -r);
      const float z = c.z() + ((corner & 4) != 0 ? r : -r);
      const float u = intr.fx * x / z + intr.ppx;
      const float v = intr.fy * y / z + intr.ppy;
      u_min = std::min(u_min, u), u_max = std::max(u_max, u);
      v_min = std::min(v_min, v), v_max = std::max(v_max, v);
    }
    corners[static_cast<size_t>(n++)] = {u_min, v_min};
    corners[static_cast<size_t>(n++)] = {u_max, v_min};
    corners[static_cast<size_t>(n++)] = {u_max, v_max};
    corners[static_cast<size_t>(n++)] = {u_min, v_max};
  }
  // Andrew's monotone chain over the 8 corners.
  std::sort(corners.begin(), corners.end(), [](const Eigen::Vector2f& p, const Eigen::Vector2f& q) {
    return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
  });
  std::array<Eigen::Vector2f, 16> chain;
  int k = 0;
  for (int i = 0; i < 8; ++i) {  // lower hull
    while (k >= 2 && cross(chain[static_cast<size_t>(k - 2)], chain[static_cast<size_t>(k - 1)], corners[static_cast<size_t>(i)]) <= 0.0F) --k;
    chain[static_cast<size_t>(k++)] = corners[static_cast<size_t>(i)];
  }
  for (int i = 6, lower = k + 1; i >= 0; --i) {  // upper hull
    while (k >= lower && cross(chain[static_cast<size_t>(k - 2)], chain[static_cast<size_t>(k - 1)], corners[static_cast<size_t>(i)]) <= 0.0F) --k;
    chain[static_cast<size_t>(k++)] = corners[static_cast<size_t>(i)];
  }
  hull.count = std::min(k - 1, 8);  // the last point repeats the first
  hull.v_min = std::numeric_limits<float>::infinity();
  hull.v_max = -hull.v_min;
  for (int i = 0; i < hull.count; ++i) {
    hull.points[static_cast<size_t>(i)] = chain[static_cast<size_t>(i)];
    hull.v_min = std::min(hull.v_min, chain[static_cast<size_t>(i)].y());
    hull.v_max = std::max(hull.v_max, chain[static_cast<size_t>(i)].y());
  }
  hull.valid = hull.count >= 3;
  return hull;
}

bool same_intrinsics(const Intrinsics& x, const Intrinsics& y) {
  return x.width == y.width && x.height == y.height && x.fx == y.fx && x.fy == y.fy && x.ppx == y.ppx &&
         x.ppy == y.ppy && x.model == y.model && x.coeffs == y.coeffs;
}

}  // namespace

void SelfFilter::add_pose(const RobotModel& robot_base) {
  const int memory = std::max(params.memory_frames, 1);
  if (static_cast<int>(ring_.size()) != memory) {
    ring_.assign(static_cast<size_t>(memory), RobotModel{});
    ring_next_ = 0;
    pose_count_ = 0;
  }
  // assign() into a slot that held a pose of the same arm reuses its buffer.
  ring_[static_cast<size_t>(ring_next_)].capsules.assign(robot_base.capsules.begin(), robot_base.capsules.end());
  ring_next_ = (ring_next_ + 1) % memory;
  pose_count_ = std::min(pose_count_ + 1, memory);
}

void SelfFilter::clear_poses() {
  ring_next_ = 0;
  pose_count_ = 0;
}

void SelfFilter::prepare(const Frame& frame) {
  const int width = frame.depth.width;
  const int height = frame.depth.height;
  if (width != width_ || height != height_) {
    width_ = width;
    height_ = height;
    const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
    entry_m_.assign(n, kInf);
    exit_m_.assign(n, 0.0F);
    scratch_m_.assign(n, kInf);
    from_raw_.assign(n, 0);
    to_raw_.assign(n, 0);
    dirty_ = Rect{};
    rays_for_ = Intrinsics{};  // the ray tables are per size too
  }
  const Intrinsics& intr = frame.intrinsics;
  if (same_intrinsics(intr, rays_for_) && !ray_x_.empty()) return;
  rays_for_ = intr;
  pinhole_ = is_pinhole(intr);
  if (pinhole_) {
    // The pinhole ray of pixel (u, v) is ((u − ppx) / fx, (v − ppy) / fy, 1), as deproject() has it.
    ray_x_.resize(static_cast<size_t>(width));
    ray_y_.resize(static_cast<size_t>(height));
    for (int u = 0; u < width; ++u) ray_x_[static_cast<size_t>(u)] = (static_cast<float>(u) - intr.ppx) / intr.fx;
    for (int v = 0; v < height; ++v) ray_y_[static_cast<size_t>(v)] = (static_cast<float>(v) - intr.ppy) / intr.fy;
    return;
  }
  // With a distortion to undo, one ray per pixel; NaN where the model cannot be inverted (no hit).
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  ray_x_.resize(n);
  ray_y_.resize(n);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u);
      const auto p = deproject(intr, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), 1.0F);
      ray_x_[i] = p ? p->x() / p->z() : std::numeric_limits<float>::quiet_NaN();
      ray_y_[i] = p ? p->y() / p->z() : std::numeric_limits<float>::quiet_NaN();
    }
  }
}

void SelfFilter::clear(const Rect& rect) {
  for (int v = rect.v0; v < rect.v1; ++v) {
    const size_t begin = static_cast<size_t>(v) * static_cast<size_t>(width_) + static_cast<size_t>(rect.u0);
    const size_t count = static_cast<size_t>(rect.u1 - rect.u0);
    std::fill_n(entry_m_.data() + begin, count, kInf);
    std::fill_n(exit_m_.data() + begin, count, 0.0F);
    std::fill_n(from_raw_.data() + begin, count, uint16_t{0});
    std::fill_n(to_raw_.data() + begin, count, uint16_t{0});
  }
}

namespace {

// Square filter of radius k over `rect` of a width-w image, in two separable passes through
// `scratch`: `pick` is std::min (a pixel near the silhouette takes the nearest entry around
// it) or std::max (the farthest exit). `none` is the value outside the silhouette.
template <typename Pick>
void dilate_square(float* image, float* scratch, size_t w, int width, int k, int u0, int v0, int u1, int v1,
                   float none, Pick pick) {
  for (int v = v0; v < v1; ++v) {
    const float* in = image + static_cast<size_t>(v) * w;
    float* out = scratch + static_cast<size_t>(v) * w;
    for (int u = u0; u < u1; ++u) {
      float m = none;
      const int lo = std::max(u - k, 0);
      const int hi = std::min(u + k, width - 1);
      for (int j = lo; j <= hi; ++j) m = pick(m, in[j]);
      out[u] = m;
    }
  }
  for (int v = v0; v < v1; ++v) {
    float* out = image + static_cast<size_t>(v) * w;
    const int lo = std::max(v - k, v0);
    const int hi = std::min(v + k, v1 - 1);
    for (int u = u0; u < u1; ++u) out[u] = none;
    for (int j = lo; j <= hi; ++j) {
      const float* in = scratch + static_cast<size_t>(j) * w;
      for (int u = u0; u < u1; ++u) out[u] = pick(out[u], in[u]);
    }
  }
}

}  // namespace

// Rows outside `rect` hold no robot (the rect is the silhouette's box grown by the radius), so
// both passes stay inside it.
void SelfFilter::dilate(const Rect& rect) {
  const int k = params.dilate_px;
  if (k <= 0 || rect.empty()) return;
  const size_t w = static_cast<size_t>(width_);
  dilate_square(entry_m_.data(), scratch_m_.data(), w, width_, k, rect.u0, rect.v0, rect.u1, rect.v1, kInf,
                [](float x, float y) { return std::min(x, y); });
  dilate_square(exit_m_.data(), scratch_m_.data(), w, width_, k, rect.u0, rect.v0, rect.u1, rect.v1, 0.0F,
                [](float x, float y) { return std::max(x, y); });
}

void SelfFilter::render(const Frame& frame, const Pose& T_base_camera, const ForegroundParams& noise) {
  prepare(frame);
  clear(dirty_);
  dirty_ = Rect{};
  silhouette_pixels_ = 0;
  if (pose_count_ == 0 || width_ == 0 || height_ == 0) return;

  const Eigen::Matrix3f R = T_base_camera.linear().transpose().cast<float>();  // camera ← base
  const Eigen::Vector3f t = -(R * T_base_camera.translation().cast<float>());
  Rect drawn{width_, height_, 0, 0};  // the union of the capsules' boxes
  for (int p = 0; p < pose_count_; ++p) {
    for (const Capsule& capsule : ring_[static_cast<size_t>(p)].capsules) {
      draw_capsule(R * capsule.a + t, R * capsule.b + t, capsule.radius_m, frame.intrinsics, drawn);
    }
  }
  if (drawn.empty()) return;
  const int k = std::max(params.dilate_px, 0);
  const Rect grown{std::max(drawn.u0 - k, 0), std::max(drawn.v0 - k, 0), std::min(drawn.u1 + k, width_),
                   std::min(drawn.v1 + k, height_)};
  dilate(grown);
  dirty_ = grown;
  silhouette_pixels_ = mark_robot_depths(frame, noise, grown);
}

void SelfFilter::draw_capsule(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float r, const Intrinsics& intr,
                              Rect& drawn) {
  // A bare segment has no surface to see; nothing behind the camera is in the image.
  if (!(r > 0.0F) || std::max(a.z(), b.z()) + r <= 0.0F) return;
  const size_t w = static_cast<size_t>(width_);
  // Which pixels of each row the capsule can cover: the row's span of the convex hull of
  // its end spheres' projected bounding boxes (the capsule is the hull of the spheres, each
  // inside its box, and projection keeps hulls). The whole image when a box reaches behind
  // the camera or a distortion makes the pinhole projection unreliable.
  const ImageHull hull = pinhole_ ? capsule_hull(a, b, r, intr) : ImageHull{};
  const CapsuleRayTerms terms = ray_terms(a, b, r);
  const int v_begin = hull.valid ? std::max(static_cast<int>(std::floor(hull.v_min)) - 1, 0) : 0;
  const int v_end = hull.valid ? std::min(static_cast<int>(std::ceil(hull.v_max)) + 2, height_) : height_;
  for (int v = v_begin; v < v_end; ++v) {
    int u0 = 0, u1 = width_;
    if (hull.valid) {
      float lo_u = 0.0F, hi_u = 0.0F;
      if (!hull.row_span(static_cast<float>(v), lo_u, hi_u)) continue;
      // One pixel of slack each side for the float rounding of the projection.
      u0 = static_cast<int>(std::clamp(std::floor(lo_u) - 1.0F, 0.0F, static_cast<float>(width_)));
      u1 = static_cast<int>(std::clamp(std::ceil(hi_u) + 2.0F, 0.0F, static_cast<float>(width_)));
      if (u0 >= u1) continue;
    }
    float* __restrict entry = entry_m_.data() + static_cast<size_t>(v) * w;
    float* __restrict exit = exit_m_.data() + static_cast<size_t>(v) * w;
    if (pinhole_) {
      const float* __restrict xs = ray_x_.data();
      const float y = ray_y_[static_cast<size_t>(v)];
      for (int u = u0; u < u1; ++u) {
        const RayInterval in = capsule_interval(xs[u], y, terms);
        entry[u] = std::min(entry[u], in.entry);
        exit[u] = std::max(exit[u], in.exit);
      }
    } else {
      const float* __restrict xs = ray_x_.data() + static_cast<size_t>(v) * w;
      const float* __restrict ys = ray_y_.data() + static_cast<size_t>(v) * w;
      for (int u = u0; u < u1; ++u) {
        // NaN rays (a distortion without inverse) compare false: no hit.
        const RayInterval in = capsule_interval(xs[u], ys[u], terms);
        entry[u] = in.entry < entry[u] ? in.entry : entry[u];
        exit[u] = in.exit > exit[u] ? in.exit : exit[u];
      }
    }
    drawn.u0 = std::min(drawn.u0, u0), drawn.u1 = std::max(drawn.u1, u1);
    drawn.v0 = std::min(drawn.v0, v), drawn.v1 = std::max(drawn.v1, v + 1);
  }
}

// The margin at depth z never undercuts the foreground test there: max(margin_m,
// min_margin_m, k_sigma · σ(z)), σ(z) = z² · subpixel / (fx · baseline) (no stereo term
// without a baseline).
size_t SelfFilter::mark_robot_depths(const Frame& frame, const ForegroundParams& noise, const Rect& grown) {
  const size_t w = static_cast<size_t>(width_);
  const float floor_m = std::max(params.margin_m, noise.min_margin_m);
  // The frame's own focal length, as the foreground test takes it (after decimation too).
  const float fx = frame.intrinsics.fx;
  const float sigma_per_z2 =
      frame.stereo_baseline_mm > 0.0F && fx > 0.0F
          ? static_cast<float>(stereo_depth_sigma_m(1.0, fx, frame.stereo_baseline_mm, noise.subpixel_rms_px))
          : 0.0F;
  const float k_sigma_per_z2 = noise.k_sigma * sigma_per_z2;
  const float units_per_m = 1.0F / frame.depth.depth_scale_m;
  size_t silhouette = 0;
  for (int v = grown.v0; v < grown.v1; ++v) {
    const size_t row = static_cast<size_t>(v) * w;
    for (int u = grown.u0; u < grown.u1; ++u) {
      const float entry = entry_m_[row + static_cast<size_t>(u)];
      if (!(entry < kInf)) continue;
      const float from_m = entry - std::max(floor_m, k_sigma_per_z2 * entry * entry);
      // Nothing beyond the padded body's far side: the arm's visible surface is at least
      // padding_m in front of it, so a pixel measured beyond is something behind the arm.
      const float to_m = exit_m_[row + static_cast<size_t>(u)];
      // Raw depths in [ceil(from / scale), floor(to / scale)] are the robot's; 0 is "no data".
      from_raw_[row + static_cast<size_t>(u)] =
          static_cast<uint16_t>(std::clamp(std::ceil(from_m * units_per_m), 1.0F, 65535.0F));
      to_raw_[row + static_cast<size_t>(u)] =
          static_cast<uint16_t>(std::clamp(std::floor(to_m * units_per_m), 1.0F, 65535.0F));
      ++silhouette;
    }
  }
  return silhouette;
}

}  // namespace hrcsense
