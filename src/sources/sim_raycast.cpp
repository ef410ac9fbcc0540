// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator's ray caster: planes in one branch-free pass over the image, every
// other shape only over the pixels its projected bounding box can cover.

#include "sim_raycast.hpp"

#include "hrcsense/camera.hpp"
#include "sim_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace hrcsense::sim_detail {
namespace {

/// A half-open pixel rectangle [u0, u1) × [v0, v1).
struct PixelRect {
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
};

/// Pixels whose rays may hit `s` (base frame): the projection of its bounding box's corners,
/// padded by a pixel. Perspective maps the convex hull of corners in front of the camera to
/// the hull of their images, so this is conservative; shapes reaching behind the camera get
/// the whole image.
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

/// Z-buffers one shape over its pixel rectangle: keeps the nearest depth and its object id.
/// `d` is the pixel's ray in whichever frame `hit` expects; t is Z either way.
template <typename Hit>
void cast(const PixelRect& r, const SimRays& rays, const Eigen::Matrix3f& R, uint16_t id, Hit hit, float* z_m,
          uint16_t* ids) {
  const int width = rays.intrinsics.width;
  for (int v = r.v0; v < r.v1; ++v) {
    for (int u = r.u0; u < r.u1; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const Eigen::Vector3f d = R.col(0) * rays.x[i] + R.col(1) * rays.y[i] + R.col(2);
      const float t = hit(d);
      if (t < z_m[i]) {
        z_m[i] = t;
        ids[i] = id;
      }
    }
  }
}

/// A plane in the camera frame as inverse depth per ray: 1/Z = n·(x/z, y/z, 1) / (n·p).
struct PlaneW {
  float wx, wy, wz;  ///< n / (n·p)
  uint16_t id;
};

/// Planes cast together, row by row (so that the row of the buffers stays in the L1 cache),
/// kept as inverse depth in `w_best` (0: nothing in front) while the planes are cast: the
/// nearest plane is the one with the largest positive 1/Z, so no division is needed until the
/// end. Branch-free so that it vectorises.
void cast_planes_w(const PlaneW* planes, size_t count, const SimRays& rays, float* w_best, uint16_t* ids) {
  const size_t width = static_cast<size_t>(rays.intrinsics.width);
  const size_t height = static_cast<size_t>(rays.intrinsics.height);
  for (size_t v = 0; v < height; ++v) {
    const size_t row = v * width;
    const float* rx = rays.x.data() + row;
    const float* ry = rays.y.data() + row;
    float* w_row = w_best + row;
    uint16_t* id_row = ids + row;
    for (size_t k = 0; k < count; ++k) {
      const PlaneW p = planes[k];
      for (size_t u = 0; u < width; ++u) {
        // Selects by max and masks: GCC turns `x = c ? y : x` into a conditional store, which
        // does not vectorise.
        const float w = p.wx * rx[u] + p.wy * ry[u] + p.wz;
        const float w_had = w_row[u];
        const auto mask = static_cast<uint16_t>(-static_cast<int>(w > w_had));
        w_row[u] = std::max(w_had, w);
        id_row[u] = static_cast<uint16_t>((p.id & mask) | (id_row[u] & ~mask));
      }
    }
  }
}

/// Ray from the camera centre against a capsule (camera frame). Exact like hit_capsule, with
/// two shortcuts: the capsule lies inside the infinite cylinder around its axis, so a ray that
/// misses the cylinder misses it; and when the ray enters the cylinder in front of the camera
/// beside the segment, that entry is on the capsule and nothing of it can be nearer.
inline float hit_capsule_fast(const Shape& c, const Eigen::Vector3f& ba, float baba, const Eigen::Vector3f& d) {
  if (baba > 0.0F) {
    const Eigen::Vector3f oa = -c.a;
    const float bad = ba.dot(d);
    const float baoa = ba.dot(oa);
    const float a = baba * d.dot(d) - bad * bad;
    const float half_b = baba * d.dot(oa) - baoa * bad;
    const float cc = baba * oa.dot(oa) - baoa * baoa - c.radius_m * c.radius_m * baba;
    const float h = half_b * half_b - a * cc;
    if (!(h >= 0.0F)) return kNoHit;
    if (a > 0.0F) {
      const float t0 = (-half_b - std::sqrt(h)) / a;
      const float foot = baoa + t0 * bad;
      if (t0 > 0.0F && foot >= 0.0F && foot <= baba) return t0;
    }
  }
  return hit_capsule(c, Eigen::Vector3f::Zero(), d);
}

/// Z-buffers a shape cast in the camera frame: the ray of pixel i is (x_i, y_i, 1).
template <typename Hit>
void cast_camera(const PixelRect& r, const SimRays& rays, uint16_t id, Hit hit, float* z_m, uint16_t* ids) {
  const int width = rays.intrinsics.width;
  for (int v = r.v0; v < r.v1; ++v) {
    for (int u = r.u0; u < r.u1; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const float t = hit(Eigen::Vector3f(rays.x[i], rays.y[i], 1.0F));
      if (t < z_m[i]) {
        z_m[i] = t;
        ids[i] = id;
      }
    }
  }
}

}  // namespace

void ensure_rays(SimRays& rays, const Intrinsics& in) {
  const Intrinsics& had = rays.intrinsics;
  if (had.width == in.width && had.height == in.height && had.fx == in.fx && had.fy == in.fy &&
      had.ppx == in.ppx && had.ppy == in.ppy && had.model == in.model && had.coeffs == in.coeffs) {
    return;
  }
  const size_t n = static_cast<size_t>(in.width) * in.height;
  rays.x.resize(n);
  rays.y.resize(n);
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const size_t i = static_cast<size_t>(v) * in.width + u;
      const Eigen::Vector3f ray = deproject(in, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), 1.0F)
                                      .value_or(Eigen::Vector3f(0.0F, 0.0F, 1.0F));
      rays.x[i] = ray.x();
      rays.y[i] = ray.y();
    }
  }
  rays.intrinsics = in;
}

void cast_shapes(const std::vector<Shape>& shapes_base, const std::vector<uint16_t>& shape_ids, const SimRays& rays,
                 const PoseF& T_base_camera, float* z_m, uint16_t* ids) {
  const PoseF T_camera_base = T_base_camera.inverse();
  const Intrinsics& in = rays.intrinsics;
  // Planes first, into the empty buffers, with z_m holding inverse depth meanwhile; in
  // batches of a fixed size, so that casting does not allocate.
  const size_t n = rays.x.size();
  std::array<PlaneW, 8> batch{};
  size_t count = 0;
  bool any_plane = false;
  for (size_t k = 0; k < shapes_base.size(); ++k) {
    const Shape& s = shapes_base[k];
    if (s.type != Shape::Type::plane) continue;
    const Eigen::Vector3f n_camera = T_camera_base.R * s.normal;
    const float num = n_camera.dot(T_camera_base.apply(s.point));
    if (num == 0.0F) continue;  // through the camera centre: seen edge-on, never hit
    const Eigen::Vector3f w = n_camera / num;
    if (!any_plane) std::fill(z_m, z_m + n, 0.0F);
    any_plane = true;
    batch[count++] = {w.x(), w.y(), w.z(), shape_ids[k]};
    if (count == batch.size()) {
      cast_planes_w(batch.data(), count, rays, z_m, ids);
      count = 0;
    }
  }
  if (count > 0) cast_planes_w(batch.data(), count, rays, z_m, ids);
  if (any_plane) {
    for (size_t i = 0; i < n; ++i) {
      // 1 / +0 = +inf = kNoHit where no plane is in front (w = 0). max rather than a select,
      // which GCC would keep as a branch; this loop should vectorise.
      z_m[i] = 1.0F / std::max(0.0F, z_m[i]);
    }
  }

  const Eigen::Vector3f origin_base = T_base_camera.t;
  const Eigen::Vector3f zero = Eigen::Vector3f::Zero();
  for (size_t k = 0; k < shapes_base.size(); ++k) {
    const Shape& s = shapes_base[k];
    if (s.type == Shape::Type::plane) continue;
    const uint16_t id = shape_ids[k];
    const PixelRect r = screen_bounds(s, in, T_camera_base);
    if (r.u0 >= r.u1 || r.v0 >= r.v1) continue;
    // Boxes are axis-aligned in the base frame, so they are cast there; the rest in the camera
    // frame, where every ray starts at the origin.
    Shape c = s;
    c.point = T_camera_base.apply(s.point);
    c.a = T_camera_base.apply(s.a);
    c.b = T_camera_base.apply(s.b);
    switch (s.type) {
      case Shape::Type::plane:
        break;
      case Shape::Type::box:
        cast(r, rays, T_base_camera.R, id, [&](const Eigen::Vector3f& d) { return hit_box(s, origin_base, d); }, z_m,
             ids);
        break;
      case Shape::Type::sphere:
        cast_camera(r, rays, id, [&](const Eigen::Vector3f& d) { return hit_sphere(c.point, c.radius_m, zero, d); },
                    z_m, ids);
        break;
      case Shape::Type::capsule: {
        const Eigen::Vector3f ba = c.b - c.a;
        const float baba = ba.dot(ba);
        cast_camera(r, rays, id, [&](const Eigen::Vector3f& d) { return hit_capsule_fast(c, ba, baba, d); }, z_m, ids);
        break;
      }
    }
  }
}

}  // namespace hrcsense::sim_detail
