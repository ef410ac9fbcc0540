// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the fused view of a cell with several cameras (fused_view.hpp).
#include "viewer/fused_view.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace hrcsense::view {
namespace {

constexpr float kFusedPi = 3.14159265358979F;
constexpr float kFusedNearPlane_m = 0.05F;
// A D435's depth field of view (87° × 58°): the frustum of a camera before its intrinsics came.
constexpr float kD435HalfFovX_rad = 0.5F * 87.0F * kFusedPi / 180.0F;
constexpr float kD435HalfFovY_rad = 0.5F * 58.0F * kFusedPi / 180.0F;
constexpr int kPreviewFrame_px = 2;
constexpr int kPreviewMargin_px = 8;

void consider_contact(const std::string& camera, int link, const Contact& contact, FusedPair& best) {
  if (!contact.valid || !std::isfinite(contact.distance_m)) return;
  if (best.valid && !(contact.distance_m < best.distance_m)) return;
  best.valid = true;
  best.camera = camera;
  best.link = link;
  best.distance_m = contact.distance_m;
  best.closest_base = contact.closest_base;
  best.closest_robot_base = contact.closest_robot_base;
}

// A camera's cloud as square splats in its colour, nearer points winning.
void draw_fused_cloud(const PointCloud& cloud, const Eigen::Isometry3f& T_view_base, const Intrinsics& in,
                      const Rgb& color, std::vector<float>& zbuffer, ColorImage& out) {
  const int side = kCloudPixelStride;
  const float half = 0.5F * static_cast<float>(side - 1);
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f q = T_view_base * Eigen::Vector3f(cloud.x[i], cloud.y[i], cloud.z[i]);
    if (!(q.z() > kFusedNearPlane_m)) continue;
    const std::optional<Eigen::Vector2f> px = project(in, q);
    if (!px || !px->allFinite() || std::abs(px->x()) > 1e6F || std::abs(px->y()) > 1e6F) continue;
    const int u0 = static_cast<int>(std::lround(px->x() - half));
    const int v0 = static_cast<int>(std::lround(px->y() - half));
    for (int y = std::max(v0, 0); y < std::min(v0 + side, out.height); ++y) {
      for (int x = std::max(u0, 0); x < std::min(u0 + side, out.width); ++x) {
        const size_t p = static_cast<size_t>(y) * out.width + x;
        if (q.z() >= zbuffer[p]) continue;
        zbuffer[p] = q.z();
        std::copy(color.begin(), color.end(), &out.rgb[3 * p]);
      }
    }
  }
}

// The camera's origin and the four corners of its image at kFrustumDepth_m, base frame.
std::array<Eigen::Vector3f, 5> frustum_base(const ros2::FusedCameraView& camera) {
  const Intrinsics& in = camera.intrinsics;
  float x0 = -std::tan(kD435HalfFovX_rad), x1 = -x0, y0 = -std::tan(kD435HalfFovY_rad), y1 = -y0;
  if (in.width > 0 && in.height > 0 && in.fx > 0.0F && in.fy > 0.0F) {
    x0 = (-0.5F - in.ppx) / in.fx;
    x1 = (static_cast<float>(in.width) - 0.5F - in.ppx) / in.fx;
    y0 = (-0.5F - in.ppy) / in.fy;
    y1 = (static_cast<float>(in.height) - 0.5F - in.ppy) / in.fy;
  }
  const Eigen::Isometry3f T = camera.T_base_camera.cast<float>();
  const float d = kFrustumDepth_m;
  return {T * Eigen::Vector3f::Zero(), T * Eigen::Vector3f(x0 * d, y0 * d, d), T * Eigen::Vector3f(x1 * d, y0 * d, d),
          T * Eigen::Vector3f(x1 * d, y1 * d, d), T * Eigen::Vector3f(x0 * d, y1 * d, d)};
}

void draw_frustum(const ros2::FusedCameraView& camera, const Eigen::Isometry3f& T_view_base, const Intrinsics& in,
                  const Rgb& color, ColorImage& out) {
  const std::array<Eigen::Vector3f, 5> p = frustum_base(camera);
  for (int i = 1; i <= 4; ++i) {
    draw_segment(out, in, T_view_base * p[0], T_view_base * p[static_cast<size_t>(i)], 0, color);
    draw_segment(out, in, T_view_base * p[static_cast<size_t>(i)], T_view_base * p[static_cast<size_t>(i % 4 + 1)], 0,
                 color);
  }
}

// Each preview coloured as the 2D pane's depth, scaled by a whole number to about
// kPreviewHeight_px, framed in its camera's colour, side by side from the bottom left.
void draw_previews(const ros2::FusedView& view, FusedScratch& scratch, ColorImage& out) {
  int x = kPreviewMargin_px;
  for (size_t c = 0; c < view.cameras.size(); ++c) {
    const ros2::DepthPreview& preview = view.cameras[c].preview;
    if (preview.width <= 0 || preview.height <= 0 ||
        preview.depth_mm.size() != static_cast<size_t>(preview.width) * preview.height) {
      continue;
    }
    const int scale = std::max(1, kPreviewHeight_px / preview.height);
    const int w = preview.width * scale;
    const int h = preview.height * scale;
    const int y = out.height - kPreviewMargin_px - h;
    if (x + w + kPreviewFrame_px > out.width || y - kPreviewFrame_px < 0) return;  // the pane is too small
    DepthImage& depth = scratch.preview_depth;
    depth.resize(preview.width, preview.height);
    depth.depth_scale_m = 0.001F;
    std::copy(preview.depth_mm.begin(), preview.depth_mm.end(), depth.pixels.begin());
    colorize_depth(depth, scratch.histogram, scratch.lut, scratch.preview_rgb);
    const Rgb color = fused_camera_color(c);
    for (int v = -kPreviewFrame_px; v < h + kPreviewFrame_px; ++v) {
      for (int u = -kPreviewFrame_px; u < w + kPreviewFrame_px; ++u) {
        if (u < 0 || v < 0 || u >= w || v >= h) {
          put_pixel(out, x + u, y + v, color);
          continue;
        }
        const size_t s = static_cast<size_t>(v / scale) * preview.width + static_cast<size_t>(u / scale);
        const Rgb pixel{scratch.preview_rgb.rgb[3 * s], scratch.preview_rgb.rgb[3 * s + 1], scratch.preview_rgb.rgb[3 * s + 2]};
        put_pixel(out, x + u, y + v, pixel);
      }
    }
    x += w + 2 * kPreviewFrame_px + kPreviewMargin_px;
  }
}

}  // namespace

Rgb fused_camera_color(size_t index) {
  constexpr size_t kCount = sizeof kFusedCameraColors / sizeof kFusedCameraColors[0];
  return kFusedCameraColors[index % kCount];
}

FusedPair fused_closest_pair(const ros2::FusedView& view) {
  FusedPair best;
  for (const ros2::FusedCameraView& camera : view.cameras) {
    if (!camera.measurement || !camera.measurement->valid) continue;
    const CameraMeasurement& m = *camera.measurement;
    if (m.links.empty()) consider_contact(camera.name, m.contact.robot_link, m.contact, best);
    for (const LinkContact& link : m.links) consider_contact(camera.name, link.link, link.contact, best);
  }
  return best;
}

std::vector<FusedCameraRow> fused_camera_rows(const ros2::FusedView& view, int64_t now_shared_ns) {
  std::vector<FusedCameraRow> rows;
  for (size_t i = 0; i < view.cameras.size(); ++i) {
    const ros2::FusedCameraView& camera = view.cameras[i];
    FusedCameraRow row;
    row.name = camera.name;
    row.color = fused_camera_color(i);
    row.age_ms = ros2::camera_age_ms(camera, now_shared_ns);
    row.cloud_points = camera.cloud_base.size();
    row.rejected = camera.rejected;
    if (camera.measurement) {
      row.valid = camera.measurement->valid;
      row.reason_code = static_cast<int>(camera.measurement->reason_code);
      row.reason = camera.measurement->reason;
    } else {
      row.reason = "no measurement yet";
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

std::vector<Capsule> fused_robot_capsules(const ros2::FusedView& view, const RobotParams& robot) {
  const CameraMeasurement* newest = nullptr;
  for (const ros2::FusedCameraView& camera : view.cameras) {
    if (!camera.measurement || !camera.measurement->robot_state.valid) continue;
    if (newest == nullptr || camera.measurement->capture_ns > newest->capture_ns) newest = &*camera.measurement;
  }
  if (newest == nullptr) return {};
  return robot_model_at(robot, newest->robot_state.q_rad).capsules;
}

OrbitCamera fused_default_orbit(const ros2::FusedView& view) {
  OrbitCamera orbit;
  if (view.cameras.empty()) return orbit;
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  for (const ros2::FusedCameraView& camera : view.cameras) mean += camera.T_base_camera.translation().cast<float>();
  mean /= static_cast<float>(view.cameras.size());
  orbit.target_base = Eigen::Vector3f(mean.x(), mean.y(), 0.5F);
  float reach = 0.0F;
  for (const ros2::FusedCameraView& camera : view.cameras) {
    reach = std::max(reach, (camera.T_base_camera.translation().cast<float>() - orbit.target_base).norm());
  }
  const Eigen::Vector3f first = view.cameras.front().T_base_camera.translation().cast<float>() - orbit.target_base;
  orbit.yaw_rad = std::remainder(std::atan2(first.y(), first.x()) + kFusedPi / 4.0F, 2.0F * kFusedPi);
  orbit.pitch_rad = kFusedPi / 6.0F;
  orbit.distance_m = std::clamp(std::max(2.0F * reach, 3.0F), kOrbitMinDistance_m, kOrbitMaxDistance_m);
  if (!orbit.target_base.allFinite() || !std::isfinite(orbit.distance_m) || !std::isfinite(orbit.yaw_rad)) {
    orbit = OrbitCamera{};
  }
  return orbit;
}

void compose_fused_3d(const ros2::FusedView& view, const std::vector<Capsule>& capsules_base, const FusedPair& pair,
                      const OrbitCamera& camera, int width, int height, FusedScratch& scratch, ColorImage& out) {
  const size_t pixels = clear_3d_pane(width, height, scratch.cloud.zbuffer, out);
  if (pixels == 0) return;
  // The base frame stands for the depth camera of orbit_view_camera(): depth_to_view is then
  // the orbit camera's own pose.
  const ViewFrame base_frame;
  const ViewCamera view_camera = orbit_view_camera(base_frame, camera, out.width, out.height);
  const Intrinsics& in = view_camera.intrinsics;
  const Eigen::Isometry3f T_view_base = orbit_T_view_base(camera).cast<float>();
  for (float c = -kFloorGridHalfSize_m; c <= kFloorGridHalfSize_m + 0.5F; c += 1.0F) {
    const float h = kFloorGridHalfSize_m;
    draw_segment(out, in, T_view_base * Eigen::Vector3f(c, -h, 0.0F), T_view_base * Eigen::Vector3f(c, h, 0.0F), 0,
                 kCloudFloorGrid);
    draw_segment(out, in, T_view_base * Eigen::Vector3f(-h, c, 0.0F), T_view_base * Eigen::Vector3f(h, c, 0.0F), 0,
                 kCloudFloorGrid);
  }
  for (size_t i = 0; i < view.cameras.size(); ++i) {
    if (ros2::camera_withholds(view.cameras[i])) continue;
    draw_fused_cloud(view.cameras[i].cloud_base, T_view_base, in, fused_camera_color(i), scratch.cloud.zbuffer, out);
  }
  for (size_t i = 0; i < view.cameras.size(); ++i) draw_frustum(view.cameras[i], T_view_base, in, fused_camera_color(i), out);
  robot_mask(capsules_base, Pose::Identity(), view_camera, scratch.cloud.robot);
  draw_robot_pixels(scratch.cloud.robot, out);
  if (pair.valid) {
    draw_segment(out, in, T_view_base * pair.closest_base, T_view_base * pair.closest_robot_base, 1, kContactLine);
    const std::optional<Eigen::Vector2f> robot_px = project_to_view(view_camera, pair.closest_robot_base);
    const std::optional<Eigen::Vector2f> contact_px = project_to_view(view_camera, pair.closest_base);
    if (robot_px && robot_px->allFinite()) draw_disc(out, *robot_px, kCloudMarkerRadius_px, kRobotMarker);
    if (contact_px && contact_px->allFinite()) draw_disc(out, *contact_px, kCloudMarkerRadius_px, kContactMarker);
  }
  draw_previews(view, scratch, out);
}

}  // namespace hrcsense::view
