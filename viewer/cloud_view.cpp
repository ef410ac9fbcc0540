// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the 3D pane's pixels on the CPU (cloud_view.hpp).
#include "viewer/cloud_view.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hrcsense::view {
namespace {

constexpr float kPi = 3.14159265358979F;
constexpr float kNearPlane_m = 0.05F;  // nothing nearer to the orbit camera is drawn
constexpr float kDefaultYawOffset_rad = kPi / 4.0F;
constexpr float kDefaultPitch_rad = kPi / 6.0F;
constexpr float kDefaultMinDistance_m = 3.0F;

// Narrows the parameter range [t0, t1] of a segment to where a quantity linear along it,
// q + t·dq, is >= 0 (one side of a plane or of an image edge); false when nothing is left.
bool clip_to(float q, float dq, float& t0, float& t1) {
  if (dq == 0.0F) return q >= 0.0F;
  const float t = -q / dq;
  if (dq > 0.0F) {
    t0 = std::max(t0, t);
  } else {
    t1 = std::min(t1, t);
  }
  return t0 <= t1;
}

}  // namespace

// A segment between two orbit-camera points, cut at the near plane and then to the image
// (plus a margin for the line's width), drawn as a DDA line of 2·half_width + 1 pixels.
// The cuts keep the loop short whatever the ends' projections (a point just past the near
// plane projects thousands of pixels away).
void draw_segment(ColorImage& image, const Intrinsics& in, const Eigen::Vector3f& a_view,
                  const Eigen::Vector3f& b_view, int half_width, const Rgb& color) {
  float t0 = 0.0F;
  float t1 = 1.0F;
  if (!a_view.allFinite() || !b_view.allFinite()) return;
  if (!clip_to(a_view.z() - kNearPlane_m, b_view.z() - a_view.z(), t0, t1)) return;
  const std::optional<Eigen::Vector2f> pa = project(in, a_view + t0 * (b_view - a_view));
  const std::optional<Eigen::Vector2f> pb = project(in, a_view + t1 * (b_view - a_view));
  if (!pa || !pb) return;
  const Eigen::Vector2f from = *pa;
  const Eigen::Vector2f delta = *pb - *pa;
  const float margin = static_cast<float>(half_width) + 1.0F;
  float s0 = 0.0F;
  float s1 = 1.0F;
  if (!clip_to(from.x() + margin, delta.x(), s0, s1) ||
      !clip_to(static_cast<float>(image.width) + margin - from.x(), -delta.x(), s0, s1) ||
      !clip_to(from.y() + margin, delta.y(), s0, s1) ||
      !clip_to(static_cast<float>(image.height) + margin - from.y(), -delta.y(), s0, s1)) {
    return;
  }
  const Eigen::Vector2f start = from + s0 * delta;
  const Eigen::Vector2f span = (s1 - s0) * delta;
  const int steps = static_cast<int>(std::ceil(std::max(std::abs(span.x()), std::abs(span.y()))));
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2f p = steps == 0 ? start : start + span * (static_cast<float>(i) / static_cast<float>(steps));
    const int u = static_cast<int>(std::lround(p.x()));
    const int v = static_cast<int>(std::lround(p.y()));
    for (int dv = -half_width; dv <= half_width; ++dv) {
      for (int du = -half_width; du <= half_width; ++du) put_pixel(image, u + du, v + dv, color);
    }
  }
}

// The robot as compose_2d() draws it: brightened halfway to white, the edge exact.
void draw_robot_pixels(const std::vector<uint8_t>& robot, ColorImage& out) {
  const int w = out.width;
  const int h = out.height;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      if (!robot[i]) continue;
      const bool edge = u == 0 || v == 0 || u == w - 1 || v == h - 1 || !robot[i - 1] || !robot[i + 1] ||
                        !robot[i - w] || !robot[i + w];
      if (edge) {
        put_pixel(out, u, v, kRobotOutline);
      } else {
        for (int c = 0; c < 3; ++c) out.rgb[3 * i + c] = static_cast<uint8_t>((out.rgb[3 * i + c] + 255) / 2);
      }
    }
  }
}

namespace {

Extrinsics to_extrinsics(const Eigen::Isometry3f& T) {
  Extrinsics e;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) e.rotation[3 * j + i] = T.linear()(i, j);  // column-major, as the SDK
    e.translation_m[j] = T.translation()[j];
  }
  return e;
}

Eigen::Isometry3f depth_to_orbit(const ViewFrame& frame, const OrbitCamera& camera) {
  return (orbit_T_view_base(camera) * frame.T_camera_base.inverse()).cast<float>();
}

void draw_floor_grid(const OrbitCamera& camera, const Intrinsics& in, ColorImage& out) {
  const Eigen::Isometry3f T_view_base = orbit_T_view_base(camera).cast<float>();
  const float h = kFloorGridHalfSize_m;
  for (float c = -h; c <= h + 0.5F; c += 1.0F) {
    draw_segment(out, in, T_view_base * Eigen::Vector3f(c, -h, 0.0F), T_view_base * Eigen::Vector3f(c, h, 0.0F), 0,
                 kCloudFloorGrid);
    draw_segment(out, in, T_view_base * Eigen::Vector3f(-h, c, 0.0F), T_view_base * Eigen::Vector3f(h, c, 0.0F), 0,
                 kCloudFloorGrid);
  }
}

uint8_t grey_for(float z_view_m) {
  const float f = std::min(z_view_m / kCloudGreyFar_m, 1.0F);
  return static_cast<uint8_t>(std::lround(static_cast<float>(kCloudGreyNear) -
                                          static_cast<float>(kCloudGreyNear - kCloudGreyFar) * f));
}

// Every kCloudPixelStride-th valid depth pixel as a grey splat, z-buffered.
void draw_cloud(const ViewFrame& frame, const ViewCamera& camera, const Eigen::Isometry3f& T_view_depth,
                Cloud3dScratch& scratch, ColorImage& out) {
  const DepthImage& depth = frame.depth;
  const Intrinsics& din = frame.depth_intrinsics;
  if (depth.width <= 0 || depth.width != din.width || depth.height != din.height ||
      depth.pixels.size() != static_cast<size_t>(depth.width) * depth.height) {
    return;
  }
  const int side = kCloudPixelStride;
  const float half = 0.5F * static_cast<float>(side - 1);
  for (int v = 0; v < depth.height; v += side) {
    for (int u = 0; u < depth.width; u += side) {
      const uint16_t raw = depth.pixels[static_cast<size_t>(v) * depth.width + u];
      if (raw == 0) continue;
      const float z_m = static_cast<float>(raw) * depth.depth_scale_m;
      const std::optional<Eigen::Vector3f> p =
          deproject(din, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), z_m);
      if (!p) return;  // deproject() refuses the model: every pixel would fail
      const Eigen::Vector3f q = T_view_depth * *p;
      if (!(q.z() > kNearPlane_m)) continue;
      const std::optional<Eigen::Vector2f> px = project(camera.intrinsics, q);
      if (!px || !px->allFinite()) continue;
      const float x0 = std::round(px->x() - half);
      const float y0 = std::round(px->y() - half);
      if (x0 < -side || y0 < -side || x0 > out.width || y0 > out.height) continue;
      const int u0 = static_cast<int>(x0);
      const int v0 = static_cast<int>(y0);
      const uint8_t g = grey_for(q.z());
      for (int y = std::max(v0, 0); y < std::min(v0 + side, out.height); ++y) {
        for (int x = std::max(u0, 0); x < std::min(u0 + side, out.width); ++x) {
          const size_t i = static_cast<size_t>(y) * out.width + x;
          if (q.z() >= scratch.zbuffer[i]) continue;
          scratch.zbuffer[i] = q.z();
          out.rgb[3 * i] = out.rgb[3 * i + 1] = out.rgb[3 * i + 2] = g;
        }
      }
    }
  }
}

void draw_foreground(const ViewFrame& frame, const ViewCamera& camera, ColorImage& out) {
  const int side = kCloudForegroundSide_px;
  const float half = 0.5F * static_cast<float>(side - 1);
  for (size_t i = 0; i + 2 < frame.foreground_camera.size(); i += 3) {
    const Eigen::Vector3f p(frame.foreground_camera[i], frame.foreground_camera[i + 1], frame.foreground_camera[i + 2]);
    const std::optional<Eigen::Vector2f> px = project_to_view(camera, p);
    if (!px || !px->allFinite() || std::abs(px->x()) > 1e6F || std::abs(px->y()) > 1e6F) continue;
    const int u0 = static_cast<int>(std::lround(px->x() - half));
    const int v0 = static_cast<int>(std::lround(px->y() - half));
    for (int v = v0; v < v0 + side; ++v) {
      for (int u = u0; u < u0 + side; ++u) put_pixel(out, u, v, kCloudForeground);
    }
  }
}

void draw_robot(const ViewFrame& frame, const ViewCamera& camera, Cloud3dScratch& scratch, ColorImage& out) {
  robot_mask(frame.capsules_base, frame.T_camera_base, camera, scratch.robot);
  draw_robot_pixels(scratch.robot, out);
}

void draw_contact(const ViewFrame& frame, const ViewCamera& camera, ColorImage& out) {
  if (!frame.contact.valid) return;
  const Eigen::Vector3f contact_camera = frame.contact.closest_camera;
  const Eigen::Vector3f robot_camera = frame.T_camera_base.cast<float>() * frame.contact.closest_robot_base;
  draw_segment(out, camera.intrinsics, transform_point(camera.depth_to_view, contact_camera),
               transform_point(camera.depth_to_view, robot_camera), 1, kContactLine);
  const std::optional<Eigen::Vector2f> robot_px = project_to_view(camera, robot_camera);
  const std::optional<Eigen::Vector2f> contact_px = project_to_view(camera, contact_camera);
  if (robot_px && robot_px->allFinite()) draw_disc(out, *robot_px, kCloudMarkerRadius_px, kRobotMarker);
  if (contact_px && contact_px->allFinite()) draw_disc(out, *contact_px, kCloudMarkerRadius_px, kContactMarker);
}

}  // namespace

OrbitCamera default_orbit(const ViewFrame& frame) {
  const Pose T_base_camera = frame.T_camera_base.inverse();
  const Eigen::Vector3f camera_base = T_base_camera.translation().cast<float>();
  // A metre in front of the real camera: the middle of what it sees, also when the camera is
  // the base frame itself (T_base_camera the identity, a recording without a cell).
  const Eigen::Vector3f ahead_base = (T_base_camera * Eigen::Vector3d(0.0, 0.0, 1.0)).cast<float>();
  OrbitCamera orbit;
  orbit.target_base = ahead_base;
  // From the real camera's side, so that the pane starts out familiar, but turned: from
  // straight behind the camera the cloud would hide its own depth.
  const float camera_yaw = std::atan2(camera_base.y(), camera_base.x());
  orbit.yaw_rad = std::remainder(camera_yaw + kDefaultYawOffset_rad, 2.0F * kPi);
  orbit.pitch_rad = kDefaultPitch_rad;
  orbit.distance_m =
      std::clamp(std::max(2.0F * camera_base.norm(), kDefaultMinDistance_m), kOrbitMinDistance_m, kOrbitMaxDistance_m);
  if (!orbit.target_base.allFinite() || !std::isfinite(orbit.distance_m)) orbit = OrbitCamera{};
  return orbit;
}

void orbit_drag(OrbitCamera& camera, float dx_px, float dy_px) {
  if (!std::isfinite(dx_px) || !std::isfinite(dy_px)) return;
  camera.yaw_rad = std::remainder(camera.yaw_rad - kOrbitRadPerPx * dx_px, 2.0F * kPi);
  camera.pitch_rad = std::clamp(camera.pitch_rad + kOrbitRadPerPx * dy_px, -kOrbitMaxPitch_rad, kOrbitMaxPitch_rad);
}

void orbit_zoom(OrbitCamera& camera, float wheel_steps) {
  if (!std::isfinite(wheel_steps)) return;
  const float distance = camera.distance_m * std::pow(kOrbitZoomPerStep, wheel_steps);
  camera.distance_m = std::clamp(std::isfinite(distance) ? distance : kOrbitMaxDistance_m, kOrbitMinDistance_m,
                                 kOrbitMaxDistance_m);
}

Pose orbit_T_view_base(const OrbitCamera& camera) {
  const double yaw = camera.yaw_rad;
  const double pitch = std::clamp(static_cast<double>(camera.pitch_rad), -static_cast<double>(kOrbitMaxPitch_rad),
                                  static_cast<double>(kOrbitMaxPitch_rad));
  const Eigen::Vector3d towards_eye(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
  const Eigen::Vector3d eye = camera.target_base.cast<double>() + static_cast<double>(camera.distance_m) * towards_eye;
  // Optical axes in the base frame: z towards the target; x = z × up is horizontal and to the
  // right; y = z × x points down in the image (right-handed: x × y = z).
  const Eigen::Vector3d forward = -towards_eye;
  const Eigen::Vector3d right(-std::sin(yaw), std::cos(yaw), 0.0);
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d R_view_base;
  R_view_base.row(0) = right;
  R_view_base.row(1) = down;
  R_view_base.row(2) = forward;
  Pose T = Pose::Identity();
  T.linear() = R_view_base;
  T.translation() = -R_view_base * eye;
  return T;
}

ViewCamera orbit_view_camera(const ViewFrame& frame, const OrbitCamera& camera, int width, int height) {
  ViewCamera view;
  Intrinsics& in = view.intrinsics;
  in.width = std::max(width, 0);
  in.height = std::max(height, 0);
  const float fov = std::clamp(camera.vertical_fov_rad, 0.01F, kPi - 0.01F);
  in.fy = 0.5F * static_cast<float>(in.height) / std::tan(0.5F * fov);
  in.fx = in.fy;
  in.ppx = 0.5F * static_cast<float>(in.width - 1);
  in.ppy = 0.5F * static_cast<float>(in.height - 1);
  in.model = Distortion::none;
  view.depth_to_view = to_extrinsics(depth_to_orbit(frame, camera));
  return view;
}

size_t clear_3d_pane(int width, int height, std::vector<float>& zbuffer, ColorImage& out) {
  out.width = std::max(width, 0);
  out.height = std::max(height, 0);
  const size_t pixels = static_cast<size_t>(out.width) * out.height;
  out.rgb.resize(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) std::copy(kCloudBackdrop.begin(), kCloudBackdrop.end(), &out.rgb[3 * i]);
  zbuffer.assign(pixels, std::numeric_limits<float>::infinity());
  return pixels;
}

void compose_3d(const ViewFrame& frame, const OrbitCamera& camera, int width, int height, Cloud3dScratch& scratch,
                ColorImage& out) {
  if (clear_3d_pane(width, height, scratch.zbuffer, out) == 0) return;
  const ViewCamera view = orbit_view_camera(frame, camera, out.width, out.height);
  draw_floor_grid(camera, view.intrinsics, out);
  draw_cloud(frame, view, depth_to_orbit(frame, camera), scratch, out);
  draw_foreground(frame, view, out);
  draw_robot(frame, view, scratch, out);
  draw_contact(frame, view, out);
}

}  // namespace hrcsense::view
