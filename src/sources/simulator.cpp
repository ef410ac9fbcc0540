// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulated depth camera: ray casting, the D435 sensor model, ground truth.

#include "hrcsense/proximity.hpp"
#include "hrcsense/sim.hpp"
#include "sim_geometry.hpp"
#include "sim_noise.hpp"
#include "sim_sensor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hrcsense {
namespace {

using sim_detail::kNoHit;

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
  scratch.shape_ids.reserve(total);
  scratch.shapes_base.clear();
  scratch.shape_labels.clear();
  scratch.shape_ids.clear();
  // Per object id (0: nothing hit): its label and its material bits. Same size every frame.
  scratch.label_of_id.assign(sim.scene.objects.size() + 1, kStaticLabel);
  scratch.material_of_id.assign(sim.scene.objects.size() + 1, 0);
  const double t_s = static_cast<double>(index) / sim.params.fps;
  uint16_t next_label = 1;
  for (size_t k = 0; k < sim.scene.objects.size(); ++k) {
    const SceneObject& object = sim.scene.objects[k];
    const uint16_t label = object.is_static ? kStaticLabel : next_label++;
    const auto id = static_cast<uint16_t>(k + 1);
    scratch.label_of_id[id] = label;
    const Material& m = object.material;
    scratch.material_of_id[id] = static_cast<uint8_t>((m.dark ? sim_detail::kDarkBit : 0) |
                                                      (m.shiny ? sim_detail::kShinyBit : 0) |
                                                      (m.low_texture ? sim_detail::kLowTextureBit : 0));
    if (!exists_at(object, index)) continue;
    const Eigen::Vector3f offset_m = path_offset(object.path, t_s);
    for (const Shape& shape : object.shapes) {
      scratch.shapes_base.push_back(translated(shape, offset_m));
      scratch.shape_labels.push_back(label);
      scratch.shape_ids.push_back(id);
    }
  }
}

/// Z-buffers one shape over its pixel rectangle: keeps the nearest depth and its object id.
/// `d` is the pixel's ray in whichever frame `hit` expects; t is Z either way.
template <typename Hit>
void cast(const PixelRect& r, const SimScratch& scratch, const Eigen::Matrix3f& R, uint16_t id, Hit hit,
          float* z_m, uint16_t* ids) {
  const int width = scratch.width;
  for (int v = r.v0; v < r.v1; ++v) {
    for (int u = r.u0; u < r.u1; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const Eigen::Vector3f d = R.col(0) * scratch.ray_x[i] + R.col(1) * scratch.ray_y[i] + R.col(2);
      const float t = hit(d);
      if (t < z_m[i]) {
        z_m[i] = t;
        ids[i] = id;
      }
    }
  }
}

/// Planes cover the whole image, so they get a flat loop on the camera-frame normal.
void cast_plane(const Shape& plane_camera, const SimScratch& scratch, uint16_t id, float* z_m, uint16_t* ids) {
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
    ids[i] = nearer ? id : ids[i];
  }
}

/// Renders every placed shape into the z-buffer `z_m` (+inf where nothing is hit) and the
/// object ids `ids` (0 where nothing is hit).
void cast_all(const SimScratch& scratch, const Intrinsics& in, const PoseF& T_base_camera, float* z_m,
              uint16_t* ids) {
  PoseF T_camera_base;
  T_camera_base.R = T_base_camera.R.transpose();
  T_camera_base.t = -(T_camera_base.R * T_base_camera.t);
  const Eigen::Matrix3f I = Eigen::Matrix3f::Identity();
  const Eigen::Vector3f origin_base = T_base_camera.t;
  for (size_t k = 0; k < scratch.shapes_base.size(); ++k) {
    const Shape& s = scratch.shapes_base[k];
    const uint16_t id = scratch.shape_ids[k];
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
        cast_plane(c, scratch, id, z_m, ids);
        break;
      case Shape::Type::box:
        cast(r, scratch, T_base_camera.R, id,
             [&](const Eigen::Vector3f& d) { return sim_detail::hit_box(s, origin_base, d); }, z_m, ids);
        break;
      case Shape::Type::sphere:
        cast(r, scratch, I, id,
             [&](const Eigen::Vector3f& d) { return sim_detail::hit_sphere(c.point, c.radius_m, zero, d); }, z_m,
             ids);
        break;
      case Shape::Type::capsule:
        cast(r, scratch, I, id, [&](const Eigen::Vector3f& d) { return sim_detail::hit_capsule(c, zero, d); },
             z_m, ids);
        break;
    }
  }
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
  truth.labels.resize(n);
  scratch.object_ids.assign(n, 0);

  cast_all(scratch, in, T_base_camera_f, truth.depth_m.data(), scratch.object_ids.data());
  sim_detail::write_sensor_depth(params, in.fx, index, truth.depth_m.data(), scratch, out.depth);
  for (size_t i = 0; i < n; ++i) {
    truth.labels[i] = scratch.label_of_id[scratch.object_ids[i]];
    truth.depth_m[i] = truth.depth_m[i] < kNoHit ? truth.depth_m[i] : 0.0F;
  }
  fill_truth_contacts(*this, T_base_camera_f, truth);
}

}  // namespace hrcsense

namespace hrcsense {

double sim_fill_rate(const Simulator& sim, int64_t first, int64_t count) {
  Frame frame;
  size_t valid = 0;
  size_t total = 0;
  for (int64_t i = first; i < first + std::max<int64_t>(count, 1); ++i) {
    sim.render(i, frame);
    for (const uint16_t raw : frame.depth.pixels) valid += raw != 0 ? 1U : 0U;
    total += frame.depth.pixels.size();
  }
  return total == 0 ? 0.0 : static_cast<double>(valid) / static_cast<double>(total);
}

}  // namespace hrcsense
