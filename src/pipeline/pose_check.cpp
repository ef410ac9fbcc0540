// SPDX-License-Identifier: Apache-2.0
// hrcsense — the per-frame camera pose check: the arm's visual shapes against its measured depth.

#include "hrcsense/pose_check.hpp"

#include <algorithm>
#include <cmath>

namespace hrcsense {
namespace {

// Shapes nearer the camera than this (m) are not projected: no camera mount puts the arm there.
constexpr float kMinShapeDepthM = 0.1F;

// The entry depth of the ray t·ray into the sphere of radius r about c (t is depth: ray.z = 1).
bool ray_sphere_depth(const Eigen::Vector3f& ray, const Eigen::Vector3f& c, float r, float& t) {
  const float rr = ray.squaredNorm();
  const float rc = ray.dot(c);
  const float h = rc * rc - rr * (c.squaredNorm() - r * r);
  if (h < 0.0F) return false;
  t = (rc - std::sqrt(h)) / rr;
  return t > 0.0F;
}

// The ray's least distance to the point c, squared.
float ray_point_distance2(const Eigen::Vector3f& ray, const Eigen::Vector3f& c) {
  const float rc = ray.dot(c);
  return std::max(0.0F, c.squaredNorm() - rc * rc / ray.squaredNorm());
}

// The pixels the capsule's projection may cover: its end points projected, grown by the radius
// seen at the nearer end. Empty (u1 < u0) when an end lies too near or behind the camera.
void project_bounds(const Intrinsics& in, ShapeInCamera& s) {
  const float z_near = std::min(s.a_camera.z(), s.b_camera.z());
  s.u0 = 0;
  s.u1 = -1;
  if (!(z_near - s.radius_m > kMinShapeDepthM)) return;
  const float grow_u = s.radius_m * in.fx / (z_near - s.radius_m) + 1.0F;
  const float grow_v = s.radius_m * in.fy / (z_near - s.radius_m) + 1.0F;
  const float ua = in.fx * s.a_camera.x() / s.a_camera.z() + in.ppx;
  const float va = in.fy * s.a_camera.y() / s.a_camera.z() + in.ppy;
  const float ub = in.fx * s.b_camera.x() / s.b_camera.z() + in.ppx;
  const float vb = in.fy * s.b_camera.y() / s.b_camera.z() + in.ppy;
  s.u0 = std::max(0, static_cast<int>(std::floor(std::min(ua, ub) - grow_u)));
  s.u1 = std::min(in.width - 1, static_cast<int>(std::ceil(std::max(ua, ub) + grow_u)));
  s.v0 = std::max(0, static_cast<int>(std::floor(std::min(va, vb) - grow_v)));
  s.v1 = std::min(in.height - 1, static_cast<int>(std::ceil(std::max(va, vb) + grow_v)));
}

int round_up_to(int value, int step) { return (value + step - 1) / step * step; }

// The mean valid depth (m) in the square of half-size `half_px` about (u, v), 0 when fewer than
// half of its pixels are valid: the single pixel's stereo noise averaged down without reaching
// across the arm's edge.
float patch_mean_m(const DepthImage& depth, int u, int v, int half_px, int& valid_pixels) {
  const int u0 = std::max(0, u - half_px);
  const int u1 = std::min(depth.width - 1, u + half_px);
  const int v0 = std::max(0, v - half_px);
  const int v1 = std::min(depth.height - 1, v + half_px);
  uint32_t sum = 0;
  int valid = 0;
  for (int y = v0; y <= v1; ++y) {
    const uint16_t* row = depth.pixels.data() + static_cast<size_t>(y) * static_cast<size_t>(depth.width);
    for (int x = u0; x <= u1; ++x) {
      sum += row[x];
      valid += row[x] != 0 ? 1 : 0;
    }
  }
  const int pixels = (u1 - u0 + 1) * (v1 - v0 + 1);
  valid_pixels = valid;
  if (2 * valid < pixels || valid == 0) return 0.0F;
  return static_cast<float>(sum) / static_cast<float>(valid) * depth.depth_scale_m;
}

}  // namespace

// The cylinder: with w = t·ray − a and e = b − a, the squared distance of the ray's point to the
// axis line times |e|² is A t² + 2 B t + C; it equals r² |e|² at the entry. An entry beyond
// either end of the segment enters through that end's cap instead (the capsule is convex).
bool ray_capsule_depth(const Eigen::Vector3f& ray, const Eigen::Vector3f& a, const Eigen::Vector3f& b, float r,
                       CapsuleHit& hit) {
  const Eigen::Vector3f e = b - a;
  const float ee = e.squaredNorm();
  const float re = ray.dot(e);
  const float ae = a.dot(e);
  const float A = ray.squaredNorm() * ee - re * re;
  const float B = re * ae - ray.dot(a) * ee;
  const float C = a.squaredNorm() * ee - ae * ae;
  if (ee > 1e-12F && A > 1e-9F * ee) {
    const float h = B * B - A * (C - r * r * ee);
    if (h < 0.0F) return false;  // misses the infinite cylinder, so the capsule too
    const float t = (-B - std::sqrt(h)) / A;
    const float along = t * re - ae;  // (w · e) at the entry: 0 at a, |e|² at b
    if (along >= 0.0F && along <= ee) {
      if (!(t > 0.0F)) return false;
      hit.depth_m = t;
      hit.axis_share = std::sqrt(std::max(0.0F, (C - B * B / A) / ee)) / r;
      return true;
    }
    const Eigen::Vector3f& end = along < 0.0F ? a : b;
    float t_cap = 0.0F;
    if (!ray_sphere_depth(ray, end, r, t_cap)) return false;
    hit.depth_m = t_cap;
    hit.axis_share = std::sqrt(ray_point_distance2(ray, end)) / r;
    return true;
  }
  // A point (a = b) or a ray along the axis: the nearer of the two end spheres.
  float ta = 0.0F;
  float tb = 0.0F;
  const bool hit_a = ray_sphere_depth(ray, a, r, ta);
  const bool hit_b = ray_sphere_depth(ray, b, r, tb);
  if (!hit_a && !hit_b) return false;
  const bool use_a = hit_a && (!hit_b || ta <= tb);
  hit.depth_m = use_a ? ta : tb;
  hit.axis_share = std::sqrt(ray_point_distance2(ray, use_a ? a : b)) / r;
  return true;
}

void shapes_in_camera(const Intrinsics& intrinsics, const Pose& T_base_camera, const RobotModel& visual_base,
                      std::vector<ShapeInCamera>& shapes) {
  const Eigen::Isometry3f T_camera_base = T_base_camera.inverse().cast<float>();
  shapes.clear();  // keeps its capacity
  for (const Capsule& c : visual_base.capsules) {
    ShapeInCamera s;
    s.a_camera = T_camera_base * c.a;
    s.b_camera = T_camera_base * c.b;
    s.radius_m = c.radius_m;
    project_bounds(intrinsics, s);
    if (s.u1 >= s.u0 && s.v1 >= s.v0) shapes.push_back(s);
  }
}

CapsuleHit nearest_shape_hit(const std::vector<ShapeInCamera>& shapes, int u, int v, const Eigen::Vector3f& ray) {
  CapsuleHit nearest;
  nearest.depth_m = 0.0F;
  for (const ShapeInCamera& s : shapes) {
    if (u < s.u0 || u > s.u1 || v < s.v0 || v > s.v1) continue;
    CapsuleHit hit;
    if (!ray_capsule_depth(ray, s.a_camera, s.b_camera, s.radius_m, hit)) continue;
    if (nearest.depth_m == 0.0F || hit.depth_m < nearest.depth_m) nearest = hit;
  }
  return nearest;
}

ShapesPixelBox shapes_pixel_box(const std::vector<ShapeInCamera>& shapes, const Intrinsics& intrinsics) {
  ShapesPixelBox box{intrinsics.width, intrinsics.height, -1, -1};
  for (const ShapeInCamera& s : shapes) {
    box.u0 = std::min(box.u0, s.u0);
    box.u1 = std::max(box.u1, s.u1);
    box.v0 = std::min(box.v0, s.v0);
    box.v1 = std::max(box.v1, s.v1);
  }
  return box;
}

PoseDisagreement pose_disagreement(const PoseCheckParams& params, const DepthImage& depth,
                                   const Intrinsics& intrinsics, const Pose& T_base_camera,
                                   const RobotModel& visual_base, std::vector<ShapeInCamera>& shapes,
                                   float stereo_baseline_m) {
  PoseDisagreement out;
  if (depth.width != intrinsics.width || depth.height != intrinsics.height || !(intrinsics.fx > 0.0F) ||
      !(intrinsics.fy > 0.0F)) {
    return out;
  }
  shapes_in_camera(intrinsics, T_base_camera, visual_base, shapes);
  const ShapesPixelBox box = shapes_pixel_box(shapes, intrinsics);
  const int u_min = box.u0, u_max = box.u1, v_min = box.v0, v_max = box.v1;
  const int step = std::max(1, params.grid_px);
  const float inv_fx = 1.0F / intrinsics.fx;
  const float inv_fy = 1.0F / intrinsics.fy;
  double sum_m = 0.0;
  double signed_m = 0.0;
  double floor_m = 0.0;
  // σ of one pixel's depth is z²·σ_d/(fx·B); E|N(0, σ)| = σ·√(2/π).
  const double noise_per_z2 = stereo_baseline_m > 0.0F && params.noise_px > 0.0F
                                  ? static_cast<double>(params.noise_px) /
                                        (static_cast<double>(intrinsics.fx) * static_cast<double>(stereo_baseline_m)) *
                                        std::sqrt(2.0 / kPi)
                                  : 0.0;
  for (int v = round_up_to(std::max(0, v_min), step); v <= v_max; v += step) {
    const uint16_t* row = depth.pixels.data() + static_cast<size_t>(v) * static_cast<size_t>(depth.width);
    for (int u = round_up_to(std::max(0, u_min), step); u <= u_max; u += step) {
      if (row[u] == 0) continue;  // no depth: nothing to compare
      const Eigen::Vector3f ray((static_cast<float>(u) - intrinsics.ppx) * inv_fx,
                                (static_cast<float>(v) - intrinsics.ppy) * inv_fy, 1.0F);
      const CapsuleHit nearest = nearest_shape_hit(shapes, u, v, ray);
      if (nearest.depth_m == 0.0F || nearest.axis_share > params.core_share) continue;
      int valid_pixels = 0;
      const float measured_m = patch_mean_m(depth, u, v, params.patch_px, valid_pixels);
      if (!(measured_m > 0.0F)) continue;
      const float diff_m = measured_m - nearest.depth_m;
      if (diff_m < -params.occlusion_m) continue;  // something in front of the arm
      sum_m += std::min(std::abs(diff_m), params.cap_m);
      signed_m += std::clamp(diff_m, -params.cap_m, params.cap_m);
      const double z = nearest.depth_m;
      floor_m += noise_per_z2 * z * z / std::sqrt(static_cast<double>(valid_pixels));
      ++out.samples;
    }
  }
  if (out.samples > 0) {
    out.mean_m = static_cast<float>(sum_m / static_cast<double>(out.samples));
    out.signed_mean_m = static_cast<float>(signed_m / static_cast<double>(out.samples));
    out.noise_floor_m = static_cast<float>(floor_m / static_cast<double>(out.samples));
  }
  return out;
}

bool PoseCheck::add(const PoseDisagreement& frame) {
  if (frame.samples < static_cast<size_t>(std::max(1, params.min_arm_pixels))) return mismatch_;
  const size_t window = static_cast<size_t>(std::max(1, params.window_frames));
  if (window_m_.size() != window) {  // the first frame, or new params: start again
    window_m_.assign(window, 0.0F);
    next_ = 0;
    filled_ = 0;
  }
  window_m_[next_] = frame.mean_m - frame.noise_floor_m;
  next_ = (next_ + 1) % window;
  filled_ = std::min(window, filled_ + 1);
  if (filled_ < window) return mismatch_;
  double sum_m = 0.0;
  float max_m = 0.0F;
  for (const float m : window_m_) {
    sum_m += m;
    max_m = std::max(max_m, m);
  }
  window_mean_m_ = static_cast<float>(sum_m / static_cast<double>(window));
  // Fires on the window's mean, clears only when every frame of the window agrees again: a
  // pose near the threshold stays a stop instead of flickering.
  if (!mismatch_) {
    mismatch_ = window_mean_m_ > params.threshold_m;
  } else {
    mismatch_ = !(max_m <= params.threshold_m);
  }
  return mismatch_;
}

void PoseCheck::reset() {
  window_m_.clear();
  next_ = 0;
  filled_ = 0;
  mismatch_ = false;
  window_mean_m_ = 0.0F;
}

}  // namespace hrcsense
