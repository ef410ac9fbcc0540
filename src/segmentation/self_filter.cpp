// SPDX-License-Identifier: Apache-2.0
// hrcsense — the self-filter: the robot's padded capsules ray-cast into the depth image's
// geometry, the silhouette dilated, and per pixel the raw depth from which on a pixel is the
// robot's.

#include "hrcsense/self_filter.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
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
  const float da = x * c.a.x() + y * c.a.y() + c.a.z();
  const float db = x * c.b.x() + y * c.b.y() + c.b.z();
  const float dba = db - da;
  // Cylinder about the axis: t² (|ba|² dd − dba²) + 2 t (dba a·ba − |ba|² da) + cylinder_c = 0.
  const float quad = std::max(c.ba_ba * dd - dba * dba, 1e-12F);
  const float half = dba * c.a_ba - c.ba_ba * da;
  const float disc = half * half - quad * c.cylinder_c;
  const float root = std::sqrt(std::max(disc, 0.0F));
  const float t_in = (-half - root) / quad;
  const float t_out = (-half + root) / quad;
  const float along_in = t_in * dba - c.a_ba;  // (hit − a) · (b − a)
  const float along_out = t_out * dba - c.a_ba;
  const bool in_hit = disc >= 0.0F && along_in > 0.0F && along_in < c.ba_ba && t_in > 0.0F;
  const bool out_hit = disc >= 0.0F && along_out > 0.0F && along_out < c.ba_ba && t_out > 0.0F;
  // End spheres: t² dd − 2 t (d·centre) + |centre|² − r² = 0.
  const float disc_a = da * da - dd * c.a_c;
  const float root_a = std::sqrt(std::max(disc_a, 0.0F));
  const float disc_b = db * db - dd * c.b_c;
  const float root_b = std::sqrt(std::max(disc_b, 0.0F));
  const bool a_hit = disc_a >= 0.0F && da + root_a > 0.0F;
  const bool b_hit = disc_b >= 0.0F && db + root_b > 0.0F;
  float entry = in_hit ? t_in : kInf;
  entry = a_hit ? std::min(entry, (da - root_a) / dd) : entry;
  entry = b_hit ? std::min(entry, (db - root_b) / dd) : entry;
  float exit = out_hit ? t_out : 0.0F;
  exit = a_hit ? std::max(exit, (da + root_a) / dd) : exit;
  exit = b_hit ? std::max(exit, (db + root_b) / dd) : exit;
  return {entry, exit};
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

void SelfFilter::render(const Frame& frame, const Pose& T_base_camera, const SelfFilterNoise& noise) {
  prepare(frame);
  clear(dirty_);
  dirty_ = Rect{};
  silhouette_pixels_ = 0;
  if (pose_count_ == 0 || width_ == 0 || height_ == 0) return;

  const Intrinsics& intr = frame.intrinsics;
  const Eigen::Matrix3f R = T_base_camera.linear().transpose().cast<float>();  // camera ← base
  const Eigen::Vector3f t = -(R * T_base_camera.translation().cast<float>());
  const size_t w = static_cast<size_t>(width_);
  Rect drawn{width_, height_, 0, 0};  // the union of the capsules' boxes

  for (int p = 0; p < pose_count_; ++p) {
    for (const Capsule& capsule : ring_[static_cast<size_t>(p)].capsules) {
      const Eigen::Vector3f a = R * capsule.a + t;
      const Eigen::Vector3f b = R * capsule.b + t;
      const float r = capsule.radius_m;
      // The image box of the capsule's bounding box (the capsule is convex and inside it, so
      // its silhouette is inside the projected corners' box); the whole image when a corner is
      // at or behind the camera, or when the distortion makes the pinhole box unreliable.
      Rect box{0, 0, width_, height_};
      const Eigen::Vector3f lo = a.cwiseMin(b).array() - r;
      const Eigen::Vector3f hi = a.cwiseMax(b).array() + r;
      if (hi.z() <= 0.0F) continue;  // entirely behind the camera
      if (pinhole_ && lo.z() > 1e-3F) {
        float u_min = kInf, u_max = -kInf, v_min = kInf, v_max = -kInf;
        for (int corner = 0; corner < 8; ++corner) {
          const float x = (corner & 1) != 0 ? hi.x() : lo.x();
          const float y = (corner & 2) != 0 ? hi.y() : lo.y();
          const float z = (corner & 4) != 0 ? hi.z() : lo.z();
          const float u = intr.fx * x / z + intr.ppx;
          const float v = intr.fy * y / z + intr.ppy;
          u_min = std::min(u_min, u), u_max = std::max(u_max, u);
          v_min = std::min(v_min, v), v_max = std::max(v_max, v);
        }
        // One pixel of slack each side for the float rounding of the projection.
        box.u0 = static_cast<int>(std::clamp(std::floor(u_min) - 1.0F, 0.0F, static_cast<float>(width_)));
        box.u1 = static_cast<int>(std::clamp(std::ceil(u_max) + 2.0F, 0.0F, static_cast<float>(width_)));
        box.v0 = static_cast<int>(std::clamp(std::floor(v_min) - 1.0F, 0.0F, static_cast<float>(height_)));
        box.v1 = static_cast<int>(std::clamp(std::ceil(v_max) + 2.0F, 0.0F, static_cast<float>(height_)));
      }
      if (box.empty()) continue;
      const CapsuleRayTerms terms = ray_terms(a, b, r);
      for (int v = box.v0; v < box.v1; ++v) {
        float* __restrict entry = entry_m_.data() + static_cast<size_t>(v) * w;
        float* __restrict exit = exit_m_.data() + static_cast<size_t>(v) * w;
        const float* __restrict xs = ray_x_.data() + (pinhole_ ? 0 : static_cast<size_t>(v) * w);
        const float* __restrict ys = pinhole_ ? nullptr : ray_y_.data() + static_cast<size_t>(v) * w;
        const float y_row = pinhole_ ? ray_y_[static_cast<size_t>(v)] : 0.0F;
        for (int u = box.u0; u < box.u1; ++u) {
          // NaN rays (a distortion without inverse) compare false: no hit.
          const RayInterval in = capsule_interval(xs[u], ys != nullptr ? ys[u] : y_row, terms);
          entry[u] = in.entry < entry[u] ? in.entry : entry[u];
          exit[u] = in.exit > exit[u] ? in.exit : exit[u];
        }
      }
      drawn.u0 = std::min(drawn.u0, box.u0), drawn.u1 = std::max(drawn.u1, box.u1);
      drawn.v0 = std::min(drawn.v0, box.v0), drawn.v1 = std::max(drawn.v1, box.v1);
    }
  }
  if (drawn.empty()) return;
  const int k = std::max(params.dilate_px, 0);
  const Rect grown{std::max(drawn.u0 - k, 0), std::max(drawn.v0 - k, 0), std::min(drawn.u1 + k, width_),
                   std::min(drawn.v1 + k, height_)};
  dilate(grown);
  dirty_ = grown;

  // The margin at depth z never undercuts the foreground test there: max(margin_m,
  // min_margin_m, k_sigma · σ(z)), σ(z) = z² · subpixel / (fx · baseline) (no stereo term
  // without a baseline).
  const float floor_m = std::max(params.margin_m, noise.min_margin_m);
  const float sigma_per_z2 =
      frame.stereo_baseline_mm > 0.0F && intr.fx > 0.0F
          ? static_cast<float>(stereo_depth_sigma_m(1.0, intr.fx, frame.stereo_baseline_mm, noise.subpixel_rms_px))
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
  silhouette_pixels_ = silhouette;
}

}  // namespace hrcsense
