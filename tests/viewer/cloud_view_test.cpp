// SPDX-License-Identifier: Apache-2.0
// The viewer's 3D pane without a display: the orbit camera's projection of base-frame points
// against hand-solved pinhole geometry (axis signs, yaw, pitch, the depth camera's pose), its
// controls' limits, and compose_3d() on a small synthetic frame (a flat wall, foreground, one
// capsule, a contact) against hand-computed pixel positions and the documented shading.
#include "viewer/cloud_view.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hrcsense::view {
namespace {

constexpr float kPi = 3.14159265358979F;

Rgb pixel(const ColorImage& image, int u, int v) {
  const size_t i = 3 * (static_cast<size_t>(v) * image.width + u);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

// Distance from (u, v) to the nearest pixel of `color`; infinite when there is none.
float nearest(const ColorImage& image, const Rgb& color, float u, float v) {
  float best = std::numeric_limits<float>::infinity();
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (pixel(image, x, y) != color) continue;
      best = std::min(best, std::hypot(static_cast<float>(x) - u, static_cast<float>(y) - v));
    }
  }
  return best;
}

int count(const ColorImage& image, const Rgb& color) {
  int n = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) n += pixel(image, x, y) == color ? 1 : 0;
  }
  return n;
}

// A 200×100 image with a 90° vertical field of view: fy = 50 / tan 45° = 50 px, the centre
// at (99.5, 49.5).
constexpr int kW = 200;
constexpr int kH = 100;
OrbitCamera orbit(const Eigen::Vector3f& target, float yaw_deg, float pitch_deg, float distance_m) {
  OrbitCamera camera;
  camera.target_base = target;
  camera.yaw_rad = yaw_deg * kPi / 180.0F;
  camera.pitch_rad = pitch_deg * kPi / 180.0F;
  camera.distance_m = distance_m;
  camera.vertical_fov_rad = kPi / 2.0F;
  return camera;
}

// T_camera_base the identity: depth-camera points are base-frame points.
Eigen::Vector2f project_base(const OrbitCamera& camera, const Eigen::Vector3f& point_base) {
  const ViewCamera view = orbit_view_camera(ViewFrame{}, camera, kW, kH);
  const std::optional<Eigen::Vector2f> px = project_to_view(view, point_base);
  EXPECT_TRUE(px.has_value());
  return px.value_or(Eigen::Vector2f(-1e9F, -1e9F));
}

void expect_px(const Eigen::Vector2f& px, float u, float v) {
  EXPECT_NEAR(px.x(), u, 1e-3F);
  EXPECT_NEAR(px.y(), v, 1e-3F);
}

TEST(OrbitCamera, AxisSignsFromTheSide) {
  // yaw 0, pitch 0: the eye 4 m along +x of the target, looking along −x, base z up. Seen from
  // +x, base +y points right (as the yz-plane drawn with y right, z up).
  const Eigen::Vector3f target(1.0F, 2.0F, 0.5F);
  const OrbitCamera camera = orbit(target, 0.0F, 0.0F, 4.0F);
  const ViewCamera view = orbit_view_camera(ViewFrame{}, camera, kW, kH);
  EXPECT_FLOAT_EQ(view.intrinsics.fy, 50.0F);
  expect_px(project_base(camera, target), 99.5F, 49.5F);
  expect_px(project_base(camera, target + Eigen::Vector3f(0, 0, 1)), 99.5F, 49.5F - 50.0F / 4.0F);  // above: smaller v
  expect_px(project_base(camera, target + Eigen::Vector3f(0, 1, 0)), 99.5F + 50.0F / 4.0F, 49.5F);  // +y: right
  expect_px(project_base(camera, target + Eigen::Vector3f(1, 0, 0)), 99.5F, 49.5F);                 // towards the eye
  // Behind the eye: not in the image.
  EXPECT_FALSE(project_to_view(view, target + Eigen::Vector3f(5, 0, 0)).has_value());
}

TEST(OrbitCamera, YawTurnsTheEyeCounterClockwise) {
  // yaw +90°: the eye on +y of the target, looking along −y; its right is −x. So the point on
  // −x of the target lands where the point on +y was at yaw 0, the point on +x where −y was.
  const Eigen::Vector3f target(1.0F, 2.0F, 0.5F);
  const OrbitCamera camera = orbit(target, 90.0F, 0.0F, 4.0F);
  expect_px(project_base(camera, target + Eigen::Vector3f(-1, 0, 0)), 112.0F, 49.5F);
  expect_px(project_base(camera, target + Eigen::Vector3f(1, 0, 0)), 87.0F, 49.5F);
  expect_px(project_base(camera, target + Eigen::Vector3f(0, 1, 0)), 99.5F, 49.5F);
  expect_px(project_base(camera, target + Eigen::Vector3f(0, 0, 1)), 99.5F, 37.0F);
}

TEST(OrbitCamera, PitchLooksDown) {
  // pitch 45°, distance 2√2: the eye 2 m out along +x and 2 m up. The point straight below the
  // eye is 45° below the optical axis: the bottom edge of a 90° field of view (v = 49.5 + 50).
  const Eigen::Vector3f target(0.0F, 0.0F, 0.0F);
  const OrbitCamera camera = orbit(target, 0.0F, 45.0F, 2.0F * std::sqrt(2.0F));
  expect_px(project_base(camera, Eigen::Vector3f(2, 0, 0)), 99.5F, 99.5F);
  expect_px(project_base(camera, target), 99.5F, 49.5F);
}

// A camera 1 m above the base origin looking along base +x (optical x = base −y, optical y =
// base −z): camera point (x, y, z) is base point (z, −x, 1 − y).
Pose T_camera_base_level() {
  Pose T_base_camera = Pose::Identity();
  T_base_camera.linear().col(0) = Eigen::Vector3d(0, -1, 0);
  T_base_camera.linear().col(1) = Eigen::Vector3d(0, 0, -1);
  T_base_camera.linear().col(2) = Eigen::Vector3d(1, 0, 0);
  T_base_camera.translation() = Eigen::Vector3d(0, 0, 1);
  return T_base_camera.inverse();
}

TEST(OrbitCamera, DepthCameraPointsGoThroughTheBaseFrame) {
  ViewFrame frame;
  frame.T_camera_base = T_camera_base_level();
  // yaw 0, pitch 0, 4 m from base (2, 0, 1): camera point (0, 0, 2) is that target; camera
  // point (0, −1, 2) is base (2, 0, 2), 1 m above it.
  const OrbitCamera camera = orbit(Eigen::Vector3f(2, 0, 1), 0.0F, 0.0F, 4.0F);
  const ViewCamera view = orbit_view_camera(frame, camera, kW, kH);
  expect_px(*project_to_view(view, Eigen::Vector3f(0, 0, 2)), 99.5F, 49.5F);
  expect_px(*project_to_view(view, Eigen::Vector3f(0, -1, 2)), 99.5F, 37.0F);
  // Camera x = base −y: seen from +x, base −y is on the left.
  expect_px(*project_to_view(view, Eigen::Vector3f(1, 0, 2)), 87.0F, 49.5F);
}

TEST(OrbitCamera, DragTurnsAsIfGrabbedAndClampsPitch) {
  OrbitCamera camera = orbit(Eigen::Vector3f::Zero(), 0.0F, 0.0F, 4.0F);
  // The near side of the cell (the point towards the eye, on the axis) moves right when
  // dragged right, down when dragged down.
  orbit_drag(camera, 10.0F, 0.0F);
  EXPECT_GT(project_base(camera, Eigen::Vector3f(1, 0, 0)).x(), 99.6F);
  camera = orbit(Eigen::Vector3f::Zero(), 0.0F, 0.0F, 4.0F);
  orbit_drag(camera, 0.0F, 10.0F);
  EXPECT_GT(project_base(camera, Eigen::Vector3f(1, 0, 0)).y(), 49.6F);
  EXPECT_GT(camera.pitch_rad, 0.0F);
  // 0.01 rad per pixel.
  camera = orbit(Eigen::Vector3f::Zero(), 0.0F, 0.0F, 4.0F);
  orbit_drag(camera, 100.0F, 0.0F);
  EXPECT_NEAR(camera.yaw_rad, -1.0F, 1e-5F);
  // Pitch never reaches a pole: ±85°.
  orbit_drag(camera, 0.0F, 1e5F);
  EXPECT_NEAR(camera.pitch_rad, 85.0F * kPi / 180.0F, 1e-5F);
  orbit_drag(camera, 0.0F, -1e5F);
  EXPECT_NEAR(camera.pitch_rad, -85.0F * kPi / 180.0F, 1e-5F);
  // Yaw stays within (−π, π] however far it is dragged.
  orbit_drag(camera, 1e5F, 0.0F);
  EXPECT_LE(std::abs(camera.yaw_rad), kPi + 1e-5F);
  const OrbitCamera before = camera;
  orbit_drag(camera, std::nanf(""), 1.0F);
  EXPECT_EQ(camera.yaw_rad, before.yaw_rad);
  EXPECT_EQ(camera.pitch_rad, before.pitch_rad);
}

TEST(OrbitCamera, ZoomMultipliesAndClamps) {
  OrbitCamera camera = orbit(Eigen::Vector3f::Zero(), 0.0F, 0.0F, 5.0F);
  orbit_zoom(camera, 1.0F);
  EXPECT_NEAR(camera.distance_m, 4.5F, 1e-5F);
  orbit_zoom(camera, -2.0F);
  EXPECT_NEAR(camera.distance_m, 4.5F / 0.81F, 1e-4F);
  orbit_zoom(camera, 100.0F);
  EXPECT_FLOAT_EQ(camera.distance_m, 0.3F);
  orbit_zoom(camera, -1000.0F);
  EXPECT_FLOAT_EQ(camera.distance_m, 20.0F);
  orbit_zoom(camera, std::nanf(""));
  EXPECT_FLOAT_EQ(camera.distance_m, 20.0F);
}

TEST(OrbitCamera, DefaultShowsTheBaseAndTheCamera) {
  ViewFrame frame;
  Pose T_base_camera = Pose::Identity();
  T_base_camera.translation() = Eigen::Vector3d(2, 0, 2);
  frame.T_camera_base = T_base_camera.inverse();
  const OrbitCamera camera = default_orbit(frame);
  // A metre along the camera's optical axis, which is base +z here.
  EXPECT_NEAR((camera.target_base - Eigen::Vector3f(2, 0, 3)).norm(), 0.0F, 1e-5F);
  EXPECT_NEAR(camera.distance_m, 2.0F * std::sqrt(8.0F), 1e-4F);
  EXPECT_NEAR(camera.yaw_rad, kPi / 4.0F, 1e-5F);    // the camera's azimuth 0, turned 45°
  EXPECT_NEAR(camera.pitch_rad, kPi / 6.0F, 1e-5F);  // 30° above
  // Both the base origin (camera point −(2, 0, 2), axes aligned) and the camera in view.
  const ViewCamera view = orbit_view_camera(frame, camera, 1280, 720);
  for (const Eigen::Vector3f& p : {Eigen::Vector3f(-2, 0, -2), Eigen::Vector3f(0, 0, 0)}) {
    const std::optional<Eigen::Vector2f> px = project_to_view(view, p);
    ASSERT_TRUE(px.has_value());
    EXPECT_GT(px->x(), 0.0F);
    EXPECT_LT(px->x(), 1280.0F);
    EXPECT_GT(px->y(), 0.0F);
    EXPECT_LT(px->y(), 720.0F);
  }
  const OrbitCamera home = default_orbit(ViewFrame{});
  EXPECT_EQ(home.target_base, Eigen::Vector3f(0, 0, 1));
  EXPECT_FLOAT_EQ(home.distance_m, 3.0F);
}

// The level camera of T_camera_base_level(), an 80×60 depth image (focal 40 px, principal
// point (40, 30)) of a flat wall 2 m ahead, seen by an orbit camera 2 m behind it (yaw 180°:
// the eye at base (−2, 0, 1) looking along +x, its right base −y = camera x). So camera point
// (x, y, z) is orbit point (x, y, z + 2), at u = 99.5 + 50·x/(z + 2), v = 49.5 + 50·y/(z + 2).
ViewFrame wall_frame(uint16_t raw_depth) {
  ViewFrame frame;
  frame.frame = 3;
  frame.valid = true;
  frame.T_camera_base = T_camera_base_level();
  frame.depth_intrinsics.width = 80;
  frame.depth_intrinsics.height = 60;
  frame.depth_intrinsics.fx = 40.0F;
  frame.depth_intrinsics.fy = 40.0F;
  frame.depth_intrinsics.ppx = 40.0F;
  frame.depth_intrinsics.ppy = 30.0F;
  frame.depth.resize(80, 60);
  std::fill(frame.depth.pixels.begin(), frame.depth.pixels.end(), raw_depth);
  return frame;
}
const OrbitCamera kBehind = orbit(Eigen::Vector3f(2, 0, 1), 180.0F, 0.0F, 4.0F);

// The documented shade: 160 at the orbit camera down to 70 at 8 m, linear.
uint8_t grey_at(float z_m) { return static_cast<uint8_t>(std::lround(160.0F - 90.0F * std::min(z_m / 8.0F, 1.0F))); }

TEST(Compose3d, WallForegroundRobotAndContact) {
  ViewFrame frame = wall_frame(2000);
  frame.foreground_camera = {0.5F, -0.5F, 1.5F};  // u = 99.5 + 50·0.5/3.5 = 106.64, v = 42.36
  // A capsule 1 m ahead, camera x from −0.6 to −0.2 at y = −0.3 (base (1, 0.6, 1.3) to
  // (1, 0.2, 1.3)), radius 0.15 m: at orbit depth 3, u from 89.5 to 96.17 at v = 44.5, 2.5 px
  // thick either side.
  frame.capsules_base = {{Eigen::Vector3f(1.0F, 0.6F, 1.3F), Eigen::Vector3f(1.0F, 0.2F, 1.3F), 0.15F, 2}};
  frame.contact.valid = true;
  frame.contact.closest_camera = Eigen::Vector3f(0.4F, 0.2F, 1.0F);      // u = 106.17, v = 52.83
  frame.contact.closest_robot_base = Eigen::Vector3f(1.0F, 0.2F, 1.3F);  // u = 96.17, v = 44.5
  Cloud3dScratch scratch;
  ColorImage out;
  compose_3d(frame, kBehind, kW, kH, scratch, out);
  ASSERT_EQ(out.width, kW);
  ASSERT_EQ(out.height, kH);
  ASSERT_EQ(out.rgb.size(), static_cast<size_t>(kW * kH * 3));
  EXPECT_LE(nearest(out, kContactMarker, 106.17F, 52.83F), 2.0F);
  EXPECT_LE(nearest(out, kRobotMarker, 96.17F, 44.5F), 2.0F);
  EXPECT_GE(count(out, kContactMarker), 40);  // a disc of radius 4: 49 pixels
  EXPECT_LE(nearest(out, kContactLine, 101.17F, 48.67F), 1.5F);  // halfway between
  EXPECT_LE(nearest(out, kCloudForeground, 106.64F, 42.36F), 1.0F);
  // The capsule near its start (clear of the robot marker's disc): inside brightened halfway
  // from the wall's grey (orbit depth 4) to white, its upper edge exact.
  const int inside = (grey_at(4.0F) + 255) / 2;
  EXPECT_EQ(pixel(out, 90, 44), (Rgb{static_cast<uint8_t>(inside), static_cast<uint8_t>(inside),
                                     static_cast<uint8_t>(inside)}));
  EXPECT_LE(nearest(out, kRobotOutline, 90.0F, 42.0F), 1.0F);
  // The wall at camera (1.5, 1, 2): u = 118.25, v = 62, grey of orbit depth 4.
  EXPECT_EQ(pixel(out, 118, 62), (Rgb{grey_at(4.0F), grey_at(4.0F), grey_at(4.0F)}));
  // The wall covers camera x in ±2 m and y in ±1.5 m: u within 74.5..124.5, v 30.75..68.25.
  EXPECT_EQ(pixel(out, 60, 40), kCloudBackdrop);  // left of the wall, above the floor's horizon
  int grey = 0;
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      const Rgb c = pixel(out, u, v);
      grey += c[0] == c[1] && c[1] == c[2] && c != kCloudBackdrop ? 1 : 0;
    }
  }
  EXPECT_GT(grey, 1500);  // about 50 × 37 px of wall
}

TEST(Compose3d, NearerPointsWinInEitherOrder) {
  // Two pairs of depth pixels on one ray of the orbit camera each: camera (0.5, 0, 1) at depth
  // pixel u = 60 and (1, 0, 4) at u = 50 both land at orbit u = 99.5 + 50/6; (−0.5, 0, 1) at
  // u = 20 and (−1, 0, 4) at u = 30 both at 99.5 − 50/6. Row-major drawing meets the far
  // point first in one pair and last in the other.
  ViewFrame frame = wall_frame(0);
  const auto set = [&](int u, uint16_t raw) { frame.depth.pixels[30 * 80 + u] = raw; };
  set(60, 1000);
  set(50, 4000);
  set(20, 1000);
  set(30, 4000);
  Cloud3dScratch scratch;
  ColorImage out;
  compose_3d(frame, kBehind, kW, kH, scratch, out);
  const Rgb near{grey_at(3.0F), grey_at(3.0F), grey_at(3.0F)};
  EXPECT_EQ(pixel(out, 108, 49), near);  // 107.83 → splat 107..108 × 49..50
  EXPECT_EQ(pixel(out, 91, 49), near);   // 91.17 → 91..92
  EXPECT_EQ(count(out, Rgb{grey_at(6.0F), grey_at(6.0F), grey_at(6.0F)}), 0);
}

TEST(Compose3d, EmptyFrameIsTheBackdropAndTheGrid) {
  const ViewFrame frame;  // frame −1, no depth, no pose
  Cloud3dScratch scratch;
  ColorImage out;
  compose_3d(frame, default_orbit(frame), 64, 48, scratch, out);
  ASSERT_EQ(out.rgb.size(), 64U * 48U * 3U);
  int grid = 0;
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      const Rgb c = pixel(out, u, v);
      ASSERT_TRUE(c == kCloudBackdrop || c == kCloudFloorGrid) << u << ", " << v;
      grid += c == kCloudFloorGrid ? 1 : 0;
    }
  }
  EXPECT_GT(grid, 0);
  compose_3d(frame, default_orbit(frame), 0, 0, scratch, out);
  EXPECT_TRUE(out.rgb.empty());
}

TEST(Compose3d, ReusesItsBuffers) {
  ViewFrame frame = wall_frame(2000);
  frame.capsules_base = {{Eigen::Vector3f(1.0F, 0.6F, 1.3F), Eigen::Vector3f(1.0F, 0.2F, 1.3F), 0.15F, 2}};
  Cloud3dScratch scratch;
  ColorImage out;
  compose_3d(frame, kBehind, kW, kH, scratch, out);
  const uint8_t* rgb = out.rgb.data();
  const float* z = scratch.zbuffer.data();
  const uint8_t* robot = scratch.robot.data();
  const std::vector<uint8_t> first = out.rgb;
  compose_3d(frame, kBehind, kW, kH, scratch, out);
  EXPECT_EQ(out.rgb.data(), rgb);
  EXPECT_EQ(scratch.zbuffer.data(), z);
  EXPECT_EQ(scratch.robot.data(), robot);
  EXPECT_EQ(out.rgb, first);  // and the same image: nothing left over from the last call
}

TEST(Compose3d, PaneColoursAreNoMarkerColour) {
  for (const Rgb& c : {kCloudBackdrop, kCloudFloorGrid, kCloudForeground}) {
    EXPECT_NE(c, kContactMarker);
    EXPECT_NE(c, kRobotMarker);
    EXPECT_NE(c, kRobotOutline);
    EXPECT_NE(c, kContactLine);
  }
}

}  // namespace
}  // namespace hrcsense::view
