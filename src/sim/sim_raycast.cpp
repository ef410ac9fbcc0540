// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator's ray caster: planes by their envelope along each row (or in one
// branch-free pass over the image for distorted cameras), every other shape only over the
// pixels its projected bounding box can cover.

#include "sim_raycast.hpp"

#include "hrcsense/camera.hpp"
#include "sim_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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

/// A box for a pinhole camera: hit_box over the pixel rectangle, written branch-free along each
/// row so that it vectorises. The ray of pixel u is d = R·(x_u, y, 1), summed in the same order
/// as in cast(), so that the depths are the same to the bit.
void cast_box_pinhole(const PixelRect& r, const SimRays& rays, const Eigen::Matrix3f& R, const Eigen::Vector3f& o,
                      const Shape& box, uint16_t id, float* z_m, uint16_t* ids) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const int width = rays.intrinsics.width;
  const float* rx = rays.x.data();  // the same in every row
  // The slabs relative to the camera centre, as hit_box computes them.
  const float lx = box.min.x() - o.x(), ly = box.min.y() - o.y(), lz = box.min.z() - o.z();
  const float hx = box.max.x() - o.x(), hy = box.max.y() - o.y(), hz = box.max.z() - o.z();
  const float c0x = R(0, 0), c0y = R(1, 0), c0z = R(2, 0);
  const int box_id = id;
  for (int v = r.v0; v < r.v1; ++v) {
    const size_t row = static_cast<size_t>(v) * width;
    const float y = rays.y[row];
    const float c1x = R(0, 1) * y, c1y = R(1, 1) * y, c1z = R(2, 1) * y;
    const float c2x = R(0, 2), c2y = R(1, 2), c2z = R(2, 2);
    float* z_row = z_m + row;
    uint16_t* id_row = ids + row;
    for (int u = r.u0; u < r.u1; ++u) {
      const float x = rx[u];
      const float ix = 1.0F / (c0x * x + c1x + c2x);
      const float iy = 1.0F / (c0y * x + c1y + c2y);
      const float iz = 1.0F / (c0z * x + c1z + c2z);
      const float ax = lx * ix, bx = hx * ix;
      const float ay = ly * iy, by = hy * iy;
      const float az = lz * iz, bz = hz * iz;
      // hit_box's swap, min and max, as selects in the same order (NaN behaves the same).
      const float near_x = ax > bx ? bx : ax, far_x = ax > bx ? ax : bx;
      const float near_y = ay > by ? by : ay, far_y = ay > by ? ay : by;
      const float near_z = az > bz ? bz : az, far_z = az > bz ? az : bz;
      float t_near = near_x > -kInf ? near_x : -kInf;
      t_near = near_y > t_near ? near_y : t_near;
      t_near = near_z > t_near ? near_z : t_near;
      float t_far = far_x < kInf ? far_x : kInf;
      t_far = far_y < t_far ? far_y : t_far;
      t_far = far_z < t_far ? far_z : t_far;
      const float t = t_near > 0.0F ? t_near : t_far;
      const int take = (t_near <= t_far) & (t_far > 0.0F) & (t < z_row[u]);
      z_row[u] = take ? t : z_row[u];
      id_row[u] = static_cast<uint16_t>((box_id & -take) | (id_row[u] & ~-take));
    }
  }
}

/// A plane in the camera frame as inverse depth per ray: 1/Z = n·(x/z, y/z, 1) / (n·p).
struct PlaneW {
  float wx, wy, wz;  ///< n / (n·p)
  uint16_t id;
};

/// Any camera: planes cast together, row by row (so that the row of the buffers stays in the
/// L1 cache), kept as inverse depth in `w_best` (to be 0: nothing in front) while the planes
/// are cast: the nearest plane is the one with the largest positive 1/Z, so no division is
/// needed until the end. Branch-free so that it vectorises.
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

/// Fills pixels [u0, u1) of a row with plane `p` (nullptr: nothing), Z = 1 / (1/Z); where
/// rounding leaves 1/Z ≤ 0 beside the plane's horizon, nothing as cast_planes_w would have it.
void fill_plane_span(const PlaneW* p, const float* rx, float y, size_t u0, size_t u1, float* z_row,
                     uint16_t* id_row) {
  if (p == nullptr) {
    std::fill(z_row + u0, z_row + u1, kNoHit);
    std::fill(id_row + u0, id_row + u1, uint16_t{0});
    return;
  }
  // Copies, so that the stores below cannot alias them and the loop vectorises.
  const float wx = p->wx;
  const float wy = p->wy * y;
  const float wz = p->wz;
  const int id = p->id;
  for (size_t u = u0; u < u1; ++u) {
    const float w = wx * rx[u] + wy + wz;
    z_row[u] = 1.0F / std::max(0.0F, w);  // +inf where w ≤ 0
    id_row[u] = static_cast<uint16_t>(id & -static_cast<int>(w > 0.0F));
  }
}

/// A pinhole camera: along a row y is fixed and x grows with u, so each plane's 1/Z is a line
/// in x, and the nearest plane (the largest 1/Z) is their upper envelope: a few spans per row,
/// found from the lines' crossings, each filled with one plane and one division per pixel.
/// "Nothing" is the line 1/Z = 0, ahead of every plane on ties as in cast_planes_w. Near a
/// crossing the two planes' depths agree to rounding, so either is right.
void cast_planes_pinhole(const PlaneW* planes, size_t count, const SimRays& rays, float* z_m, uint16_t* ids) {
  const size_t width = static_cast<size_t>(rays.intrinsics.width);
  const size_t height = static_cast<size_t>(rays.intrinsics.height);
  const float* rx = rays.x.data();  // the same in every row
  for (size_t v = 0; v < height; ++v) {
    const size_t row = v * width;
    const float y = rays.y[row];
    // Line k (k = 0: nothing, k ≥ 1: planes[k − 1]): 1/Z = slope[k]·x + offset[k].
    const auto slope = [&](size_t k) { return k == 0 ? 0.0 : static_cast<double>(planes[k - 1].wx); };
    const auto offset = [&](size_t k) {
      return k == 0 ? 0.0 : static_cast<double>(planes[k - 1].wy) * y + planes[k - 1].wz;
    };
    // The winner at the row's first pixel, then from crossing to crossing: only a steeper
    // line can overtake the current one as x grows, so this ends after at most count steps.
    size_t current = 0;
    const double x0 = rx[0];
    for (size_t k = 1; k <= count; ++k) {
      if (slope(k) * x0 + offset(k) > slope(current) * x0 + offset(current)) current = k;
    }
    size_t u = 0;
    while (u < width) {
      size_t next = 0;
      double next_x = std::numeric_limits<double>::infinity();
      for (size_t k = 1; k <= count + 1; ++k) {
        const size_t line = k % (count + 1);  // planes, then nothing
        const double rise = slope(line) - slope(current);
        if (!(rise > 0.0)) continue;
        const double x = (offset(current) - offset(line)) / rise;
        if (x < next_x || (x == next_x && slope(line) > slope(next))) {
          next_x = x;
          next = line;
        }
      }
      // The current line wins up to the last pixel at or before the crossing.
      const size_t end = next_x == std::numeric_limits<double>::infinity()
                             ? width
                             : static_cast<size_t>(std::upper_bound(rx + u, rx + width, next_x,
                                                                    [](double a, float b) { return a < b; }) -
                                                   rx);
      fill_plane_span(current == 0 ? nullptr : &planes[current - 1], rx, y, u, end, z_m + row, ids + row);
      u = end;
      current = next;
    }
  }
}

/// Ray from the camera centre against a capsule (camera frame). Exact like hit_capsule, with
/// two shortcuts: the capsule lies inside the infinite cylinder around its axis, so a ray that
/// misses the cylinder misses it; and when the ray enters the cylinder in front of the camera
/// beside the segment, that entry is on the capsule and nothing of it can be nearer.
struct CapsuleHit {
  Shape c;  ///< the capsule in the camera frame
  // What does not depend on the ray, computed once per capsule rather than per pixel.
  Eigen::Vector3f ba = c.b - c.a;
  Eigen::Vector3f oa = -c.a;
  float baba = ba.dot(ba);
  float baoa = ba.dot(oa);
  float cc = baba * oa.dot(oa) - baoa * baoa - c.radius_m * c.radius_m * baba;

  float operator()(const Eigen::Vector3f& d) const {
    if (baba > 0.0F) {
      const float bad = ba.dot(d);
      const float a = baba * d.dot(d) - bad * bad;
      const float half_b = baba * d.dot(oa) - baoa * bad;
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
};

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

/// A plane as seen from the camera: w = n_camera / (n_camera · p_camera), so that the inverse
/// depth along the ray (x, y, 1) is w · (x, y, 1). False for a shape that is no plane and for a
/// plane through the camera centre (seen edge-on, never hit).
bool plane_w(const Shape& s, uint16_t id, const PoseF& T_camera_base, PlaneW& out) {
  if (s.type != Shape::Type::plane) return false;
  const Eigen::Vector3f n_camera = T_camera_base.R * s.normal;
  const float num = n_camera.dot(T_camera_base.apply(s.point));
  if (num == 0.0F) return false;
  const Eigen::Vector3f w = n_camera / num;
  out = {w.x(), w.y(), w.z(), id};
  return true;
}

/// Casts every plane of the scene; planes come first, since they initialise every pixel of
/// both buffers (kNoHit and id 0 where no plane is in front).
void cast_all_planes(const std::vector<Shape>& shapes_base, const std::vector<uint16_t>& shape_ids,
                     const SimRays& rays, const PoseF& T_camera_base, bool pinhole, float* z_m, uint16_t* ids) {
  // Fixed-size batches, so that casting does not allocate.
  std::array<PlaneW, 16> batch{};
  size_t count = 0;
  size_t total = 0;
  for (size_t k = 0; k < shapes_base.size(); ++k) {
    PlaneW p{};
    if (!plane_w(shapes_base[k], shape_ids[k], T_camera_base, p)) continue;
    if (count < batch.size()) batch[count++] = p;
    ++total;
  }
  if (pinhole && total <= batch.size()) {
    cast_planes_pinhole(batch.data(), count, rays, z_m, ids);
    return;
  }
  const size_t n = rays.x.size();
  std::fill(z_m, z_m + n, 0.0F);  // inverse depth meanwhile
  std::fill(ids, ids + n, uint16_t{0});
  count = 0;
  for (size_t k = 0; k < shapes_base.size(); ++k) {
    if (!plane_w(shapes_base[k], shape_ids[k], T_camera_base, batch[count])) continue;
    if (++count == batch.size()) {
      cast_planes_w(batch.data(), count, rays, z_m, ids);
      count = 0;
    }
  }
  if (count > 0) cast_planes_w(batch.data(), count, rays, z_m, ids);
  for (size_t i = 0; i < n; ++i) {
    // 1 / +0 = +inf = kNoHit where no plane is in front (w = 0). max rather than a select,
    // which GCC would keep as a branch; this loop should vectorise.
    z_m[i] = 1.0F / std::max(0.0F, z_m[i]);
  }
}

/// Z-buffers one shape other than a plane over the pixels its bounding box may cover. Boxes
/// are axis-aligned in the base frame, so they are cast there; the rest in the camera frame,
/// where every ray starts at the origin.
void cast_solid(const Shape& s, uint16_t id, const SimRays& rays, const PoseF& T_base_camera,
                const PoseF& T_camera_base, bool pinhole, float* z_m, uint16_t* ids) {
  const PixelRect r = screen_bounds(s, rays.intrinsics, T_camera_base);
  if (r.u0 >= r.u1 || r.v0 >= r.v1) return;
  const Eigen::Vector3f origin_base = T_base_camera.t;
  const Eigen::Vector3f zero = Eigen::Vector3f::Zero();
  Shape c = s;
  c.point = T_camera_base.apply(s.point);
  c.a = T_camera_base.apply(s.a);
  c.b = T_camera_base.apply(s.b);
  switch (s.type) {
    case Shape::Type::plane:
      break;
    case Shape::Type::box:
      if (pinhole) {
        cast_box_pinhole(r, rays, T_base_camera.R, origin_base, s, id, z_m, ids);
      } else {
        cast(r, rays, T_base_camera.R, id, [&](const Eigen::Vector3f& d) { return hit_box(s, origin_base, d); }, z_m,
             ids);
      }
      break;
    case Shape::Type::sphere:
      cast_camera(r, rays, id, [&](const Eigen::Vector3f& d) { return hit_sphere(c.point, c.radius_m, zero, d); },
                  z_m, ids);
      break;
    case Shape::Type::capsule:
      cast_camera(r, rays, id, CapsuleHit{c}, z_m, ids);
      break;
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
  // The row paths need x to grow along a row, as it does for every real camera (fx > 0).
  const bool pinhole = is_pinhole(in) && in.fx > 0.0F;
  cast_all_planes(shapes_base, shape_ids, rays, T_camera_base, pinhole, z_m, ids);
  for (size_t k = 0; k < shapes_base.size(); ++k) {
    if (shapes_base[k].type == Shape::Type::plane) continue;
    cast_solid(shapes_base[k], shape_ids[k], rays, T_base_camera, T_camera_base, pinhole, z_m, ids);
  }
}

}  // namespace hrcsense::sim_detail
