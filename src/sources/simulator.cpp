// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulated depth camera: ray casting, stereo disparity noise, ground truth.

#include "hrcsense/proximity.hpp"
#include "hrcsense/sim.hpp"
#include "sim_geometry.hpp"
#include "sim_noise.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hrcsense {
namespace {

using sim_detail::kNoHit;
using sim_detail::mix64;

constexpr uint64_t kGolden = 0x9E3779B97F4A7C15ULL;

bool exists_at(const SceneObject& object, int64_t index) {
  return object.first_frame <= index && (object.last_frame == -1 || index <= object.last_frame);
}

/// Linear interpolation between waypoints (sorted by t_s), held at both ends.
Eigen::Vector3f path_offset(const std::vector<Waypoint>& path, double t_s) {
  if (path.empty()) return Eigen::Vector3f::Zero();
  if (t_s <= path.front().t_s) return path.front().offset_m;
  for (size_t k = 1; k < path.size(); ++k) {
    if (t_s < path[k].t_s) {
      const Waypoint& w0 = path[k - 1];
      const Waypoint& w1 = path[k];
      const auto f = static_cast<float>((t_s - w0.t_s) / (w1.t_s - w0.t_s));
      return w0.offset_m + f * (w1.offset_m - w0.offset_m);
    }
  }
  return path.back().offset_m;
}

Shape translated(Shape s, const Eigen::Vector3f& offset_m) {
  s.point += offset_m;
  s.min += offset_m;
  s.max += offset_m;
  s.a += offset_m;
  s.b += offset_m;
  return s;
}

/// Rigid transform in float for the per-pixel work.
struct PoseF {
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();
  Eigen::Vector3f t = Eigen::Vector3f::Zero();
  Eigen::Vector3f apply(const Eigen::Vector3f& p) const { return R * p + t; }
};

/// A half-open pixel rectangle [u0, u1) × [v0, v1).
struct PixelRect {
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
};

/// Pixels whose rays may hit `s` (base frame): the projection of its bounding box's corners,
/// padded by a pixel. Perspective maps the convex hull of corners in front of the camera to
/// the hull of their images, so this is conservative; planes and shapes reaching behind the
/// camera get the whole image.
PixelRect screen_bounds(const Shape& s, const Intrinsics& in, const PoseF& T_camera_base) {
  const PixelRect full{0, 0, in.width, in.height};
  Eigen::Vector3f lo;
  Eigen::Vector3f hi;
  switch (s.type) {
    case Shape::Type::plane:
      return full;
    case Shape::Type::box:
      lo = s.min;
      hi = s.max;
      break;
    case Shape::Type::sphere:
      lo = s.point.array() - s.radius_m;
      hi = s.point.array() + s.radius_m;
      break;
    case Shape::Type::capsule:
      lo = s.a.cwiseMin(s.b).array() - s.radius_m;
      hi = s.a.cwiseMax(s.b).array() + s.radius_m;
      break;
  }
  float u_min = kNoHit, v_min = kNoHit, u_max = -kNoHit, v_max = -kNoHit;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3f p_base((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                                 (corner & 4) ? hi.z() : lo.z());
    const Eigen::Vector3f p_camera = T_camera_base.apply(p_base);
    const std::optional<Eigen::Vector2f> uv = project(in, p_camera);
    if (p_camera.z() < 1e-4F || !uv) return full;
    u_min = std::min(u_min, uv->x());
    u_max = std::max(u_max, uv->x());
    v_min = std::min(v_min, uv->y());
    v_max = std::max(v_max, uv->y());
  }
  const auto clamp_to = [](float value, int limit) {
    return static_cast<int>(std::clamp(value, 0.0F, static_cast<float>(limit)));
  };
  return {clamp_to(std::floor(u_min) - 1.0F, in.width), clamp_to(std::floor(v_min) - 1.0F, in.height),
          clamp_to(std::ceil(u_max) + 2.0F, in.width), clamp_to(std::ceil(v_max) + 2.0F, in.height)};
}

/// Per-pixel rays, from deproject() at unit depth, recomputed only when the size changes.
void ensure_rays(SimScratch& scratch, const Intrinsics& in) {
  if (scratch.width == in.width && scratch.height == in.height) return;
  const size_t n = static_cast<size_t>(in.width) * in.height;
  scratch.ray_x.resize(n);
  scratch.ray_y.resize(n);
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const size_t i = static_cast<size_t>(v) * in.width + u;
      const Eigen::Vector3f ray = deproject(in, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), 1.0F)
                                      .value_or(Eigen::Vector3f(0.0F, 0.0F, 1.0F));
      scratch.ray_x[i] = ray.x();
      scratch.ray_y[i] = ray.y();
    }
  }
  scratch.points_base.reserve(n);
  scratch.points_camera.reserve(n);
  scratch.width = in.width;
  scratch.height = in.height;
}

/// The shapes that exist in frame `index`, moved along their paths, with their labels.
void place_shapes(const Simulator& sim, int64_t index, SimScratch& scratch) {
  size_t total = 0;
  for (const SceneObject& object : sim.scene.objects) total += object.shapes.size();
  scratch.shapes_base.reserve(total);  // the first frame sizes for all, so later ones never grow
  scratch.shape_labels.reserve(total);
  scratch.shapes_base.clear();
  scratch.shape_labels.clear();
  const double t_s = static_cast<double>(index) / sim.params.fps;
  uint16_t next_label = 1;
  for (const SceneObject& object : sim.scene.objects) {
    const uint16_t label = object.is_static ? kStaticLabel : next_label++;
    if (!exists_at(object, index)) continue;
    const Eigen::Vector3f offset_m = path_offset(object.path, t_s);
    for (const Shape& shape : object.shapes) {
      scratch.shapes_base.push_back(translated(shape, offset_m));
      scratch.shape_labels.push_back(label);
    }
  }
}

/// Z-buffers one shape over its pixel rectangle: keeps the nearest depth and its label.
/// `d` is the pixel's ray in whichever frame `hit` expects; t is Z either way.
template <typename Hit>
void cast(const PixelRect& r, const SimScratch& scratch, const Eigen::Matrix3f& R, uint16_t label, Hit hit,
          float* z_m, uint16_t* labels) {
  const int width = scratch.width;
  for (int v = r.v0; v < r.v1; ++v) {
    for (int u = r.u0; u < r.u1; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const Eigen::Vector3f d = R.col(0) * scratch.ray_x[i] + R.col(1) * scratch.ray_y[i] + R.col(2);
      const float t = hit(d);
      if (t < z_m[i]) {
        z_m[i] = t;
        labels[i] = label;
      }
    }
  }
}

/// Planes cover the whole image, so they get a flat loop on the camera-frame normal.
void cast_plane(const Shape& plane_camera, const SimScratch& scratch, uint16_t label, float* z_m,
                uint16_t* labels) {
  const float nx = plane_camera.normal.x(), ny = plane_camera.normal.y(), nz = plane_camera.normal.z();
  const float num = plane_camera.normal.dot(plane_camera.point);
  const size_t n = scratch.ray_x.size();
  const float* rx = scratch.ray_x.data();
  const float* ry = scratch.ray_y.data();
  // Unconditional selects instead of a branch, so that the compiler can vectorise the loop.
  for (size_t i = 0; i < n; ++i) {
    const float t = num / (nx * rx[i] + ny * ry[i] + nz);
    const bool nearer = t > 0.0F && t < z_m[i];
    z_m[i] = nearer ? t : z_m[i];
    labels[i] = nearer ? label : labels[i];
  }
}

/// Renders every placed shape into the z-buffer `z_m` (+inf where nothing is hit).
void cast_all(const SimScratch& scratch, const Intrinsics& in, const PoseF& T_base_camera, float* z_m,
              uint16_t* labels) {
  PoseF T_camera_base;
  T_camera_base.R = T_base_camera.R.transpose();
  T_camera_base.t = -(T_camera_base.R * T_base_camera.t);
  const Eigen::Matrix3f I = Eigen::Matrix3f::Identity();
  const Eigen::Vector3f origin_base = T_base_camera.t;
  for (size_t k = 0; k < scratch.shapes_base.size(); ++k) {
    const Shape& s = scratch.shapes_base[k];
    const uint16_t label = scratch.shape_labels[k];
    const PixelRect r = screen_bounds(s, in, T_camera_base);
    if (r.u0 >= r.u1 || r.v0 >= r.v1) continue;
    // Boxes are axis-aligned in the base frame, so they are cast there; the rest in the camera
    // frame, where every ray starts at the origin.
    Shape c = s;
    c.point = T_camera_base.apply(s.point);
    c.normal = T_camera_base.R * s.normal;
    c.a = T_camera_base.apply(s.a);
    c.b = T_camera_base.apply(s.b);
    const Eigen::Vector3f zero = Eigen::Vector3f::Zero();
    switch (s.type) {
      case Shape::Type::plane:
        cast_plane(c, scratch, label, z_m, labels);
        break;
      case Shape::Type::box:
        cast(r, scratch, T_base_camera.R, label,
             [&](const Eigen::Vector3f& d) { return sim_detail::hit_box(s, origin_base, d); }, z_m, labels);
        break;
      case Shape::Type::sphere:
        cast(r, scratch, I, label,
             [&](const Eigen::Vector3f& d) { return sim_detail::hit_sphere(c.point, c.radius_m, zero, d); }, z_m,
             labels);
        break;
      case Shape::Type::capsule:
        cast(r, scratch, I, label, [&](const Eigen::Vector3f& d) { return sim_detail::hit_capsule(c, zero, d); },
             z_m, labels);
        break;
    }
  }
}

/// Turns the true depth into raw units: disparity noise (if enabled), then rounding to the
/// depth unit. Z' = fx·B / (fx·B/Z + σ·n) = Z / (1 + σ·n·Z/(fx·B)).
void write_depth(const SimParams& p, float fx_px, int64_t index, std::vector<float>& z_m, DepthImage& depth) {
  const auto inv_scale = static_cast<float>(1.0 / static_cast<double>(p.depth_scale_m));
  const float noise_per_m = p.disparity_noise_px / (fx_px * p.baseline_mm * 1e-3F);
  const uint64_t frame_seed = mix64(mix64(p.seed) ^ (static_cast<uint64_t>(index) * kGolden));
  const auto quantise = [&](float z, float n) -> uint16_t {
    if (!(z > 0.0F) || !(z < kNoHit)) return 0;
    float z_noisy = z;
    if (p.noise) {
      const float scale = 1.0F + noise_per_m * z * n;
      if (!(scale > 0.0F)) return 0;  // the noisy disparity d' <= 0: no match
      z_noisy = z / scale;
    }
    const float raw = z_noisy * inv_scale + 0.5F;  // round to nearest, as raw >= 0.5 here
    return raw >= 1.0F && raw < 65536.0F ? static_cast<uint16_t>(raw) : 0;
  };
  // One draw per pixel, hit or not, so that a pixel's noise does not depend on the scene.
  sim_detail::NormalStream normal(frame_seed);
  const size_t n = z_m.size();
  for (size_t i = 0; i < n; ++i) depth.pixels[i] = quantise(z_m[i], p.noise ? normal.next() : 0.0F);
  for (float& z : z_m) z = z < kNoHit ? z : 0.0F;
}

/// Closest robot contact over the analytic surfaces of the existing non-static shapes.
Contact analytic_contact(const SimScratch& scratch, const RobotModel& robot, const PoseF& T_camera_base) {
  Contact best;
  for (size_t k = 0; k < scratch.shapes_base.size(); ++k) {
    if (scratch.shape_labels[k] == kStaticLabel) continue;
    for (const Capsule& capsule : robot.capsules) {
      const sim_detail::ClosestPair pair = sim_detail::closest_shape_capsule(scratch.shapes_base[k], capsule);
      if (best.valid && !(pair.distance_m < best.distance_m)) continue;
      best.valid = true;
      best.distance_m = pair.distance_m;
      best.closest_base = pair.on_shape;
      best.closest_camera = T_camera_base.apply(pair.on_shape);
      best.closest_robot_base = pair.on_robot;
      best.robot_link = capsule.link;
    }
  }
  return best;
}

void fill_truth_contacts(const Simulator& sim, const PoseF& T_base_camera, GroundTruth& truth) {
  SimScratch& scratch = sim.scratch;
  scratch.points_base.clear();
  scratch.points_camera.clear();
  for (size_t i = 0; i < truth.labels.size(); ++i) {
    if (truth.labels[i] == kStaticLabel) continue;
    const float z = truth.depth_m[i];
    const Eigen::Vector3f p_camera(z * scratch.ray_x[i], z * scratch.ray_y[i], z);
    const Eigen::Vector3f p_base = T_base_camera.apply(p_camera);
    scratch.points_camera.push_back(p_camera.x(), p_camera.y(), p_camera.z(), static_cast<uint32_t>(i));
    scratch.points_base.push_back(p_base.x(), p_base.y(), p_base.z(), static_cast<uint32_t>(i));
  }
  // Both contacts exist only while a non-static object is in view, as a camera would see it.
  if (scratch.points_base.empty()) {
    truth.contact = Contact{};
    truth.analytic_contact = Contact{};
    return;
  }
  truth.contact = closest_contact_brute(scratch.points_base, scratch.points_camera, sim.robot);
  PoseF T_camera_base;
  T_camera_base.R = T_base_camera.R.transpose();
  T_camera_base.t = -(T_camera_base.R * T_base_camera.t);
  truth.analytic_contact = analytic_contact(scratch, sim.robot, T_camera_base);
}

}  // namespace

Intrinsics Simulator::intrinsics() const {
  const std::optional<Intrinsics> in = d435_depth_intrinsics(params.width, params.height);
  if (!in) {
    throw std::invalid_argument("simulator: the D435 has no " + std::to_string(params.width) + "x" +
                                std::to_string(params.height) + " depth mode");
  }
  return *in;
}

void Simulator::render(int64_t index, Frame& out) const {
  const Intrinsics in = intrinsics();
  ensure_rays(scratch, in);
  place_shapes(*this, index, scratch);
  PoseF T_base_camera_f;
  T_base_camera_f.R = T_base_camera.linear().cast<float>();
  T_base_camera_f.t = T_base_camera.translation().cast<float>();

  out.index = index;
  out.timestamp_ns = std::llround(static_cast<double>(index) * 1e9 / params.fps);
  out.intrinsics = in;
  out.stereo_baseline_mm = params.baseline_mm;
  out.color.reset();
  out.depth.resize(in.width, in.height);
  out.depth.depth_scale_m = params.depth_scale_m;
  if (!out.truth) out.truth.emplace();
  GroundTruth& truth = *out.truth;
  const size_t n = static_cast<size_t>(in.width) * in.height;
  truth.depth_m.assign(n, kNoHit);
  truth.labels.assign(n, kStaticLabel);

  cast_all(scratch, in, T_base_camera_f, truth.depth_m.data(), truth.labels.data());
  write_depth(params, in.fx, index, truth.depth_m, out.depth);
  fill_truth_contacts(*this, T_base_camera_f, truth);
}

}  // namespace hrcsense
