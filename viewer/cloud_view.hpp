// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — what the 3D pane shows, computed on the CPU without OpenGL (as the 2D pane
// in view_model.hpp): the depth frame as a point cloud seen by an orbit camera around a point
// of the robot base frame, the foreground, the robot's capsules and the closest pair. The GL
// part only uploads the composed image as a texture and turns mouse input into orbit_drag()
// and orbit_zoom() calls.
#pragma once

#include "viewer/view_model.hpp"

#include <vector>

namespace hrcsense::view {

/// Colours of the 3D pane besides the exact markers of view_model.hpp (kContactMarker,
/// kRobotMarker, kRobotOutline, kContactLine), none of which any of these equals.
inline constexpr Rgb kCloudBackdrop{24, 24, 28};    ///< where nothing is drawn
inline constexpr Rgb kCloudFloorGrid{56, 60, 70};   ///< the 1 m grid on the floor (base z = 0)
inline constexpr Rgb kCloudForeground{164, 69, 164}; ///< foreground: 3/8 of the way from grey 110 to kContactMarker
/// Background points are grey, (g, g, g) with g from kCloudGreyNear (at the orbit camera) down
/// to kCloudGreyFar (kCloudGreyFar_m and beyond), so that depth reads from the shade.
inline constexpr int kCloudGreyNear = 160;
inline constexpr int kCloudGreyFar = 70;
inline constexpr float kCloudGreyFar_m = 8.0F;
/// Every kCloudPixelStride-th depth pixel in u and in v is drawn (848×480 → 424×240 points),
/// each as a kCloudPixelStride-square splat so that the subsampled cloud keeps no holes at
/// the default distance; nearer points win through a z-buffer.
inline constexpr int kCloudPixelStride = 2;
/// Foreground points are drawn as squares of this side, over the cloud and without a depth
/// test: a person behind a wall from the orbit camera's viewpoint stays visible.
inline constexpr int kCloudForegroundSide_px = 2;
inline constexpr int kCloudMarkerRadius_px = 4;  ///< radius of the closest-pair discs
inline constexpr float kFloorGridHalfSize_m = 4.0F;  ///< the grid covers base x, y in ±this, 1 m cells

/// Limits of the orbit camera's controls.
inline constexpr float kOrbitMinDistance_m = 0.3F;
inline constexpr float kOrbitMaxDistance_m = 20.0F;
inline constexpr float kOrbitMaxPitch_rad = 1.4835298F;  ///< 85°: away from the poles, where yaw is undefined
inline constexpr float kOrbitRadPerPx = 0.01F;           ///< drag sensitivity, radians per pixel
inline constexpr float kOrbitZoomPerStep = 0.9F;         ///< distance factor per wheel step (towards the target)

/// A camera on a sphere around `target_base`, in the robot base frame (z up, metres). Its eye
/// is at target_base + distance_m · (cos pitch · cos yaw, cos pitch · sin yaw, sin pitch): yaw
/// is the eye's azimuth, counter-clockwise seen from above (from +x towards +y), pitch its
/// elevation above the target's horizontal plane (positive: looking down). It always looks at
/// the target with base +z up in the image.
struct OrbitCamera {
  Eigen::Vector3f target_base = Eigen::Vector3f::Zero();  ///< the point looked at, base frame, metres
  float yaw_rad = 0.0F;                                   ///< the eye's azimuth around base z
  float pitch_rad = 0.5235988F;                           ///< the eye's elevation, in ±kOrbitMaxPitch_rad
  float distance_m = 5.0F;                                ///< eye to target, metres, within the distance limits
  float vertical_fov_rad = 1.0471976F;                    ///< full vertical field of view (60°)
};

/// An orbit camera that shows the cell: it looks at the midpoint of the robot base origin and
/// the real camera (inverse of frame.T_camera_base), from the real camera's side turned 45°
/// counter-clockwise and 30° above, at twice the base–camera distance (at least 3 m, within
/// the distance limits). A frame without a pose (identity) looks at the base origin from 3 m.
OrbitCamera default_orbit(const ViewFrame& frame);

/// A mouse drag of (dx_px, dy_px) window pixels turns the cell as if grabbed: dragging right
/// moves the near side of the cell right (yaw decreases), dragging down moves it down (the
/// eye rises: pitch increases), kOrbitRadPerPx per pixel; pitch is clamped to
/// ±kOrbitMaxPitch_rad, yaw wrapped to (-π, π]. Non-finite input leaves the camera unchanged.
void orbit_drag(OrbitCamera& camera, float dx_px, float dy_px);

/// Wheel steps (positive: towards the target) multiply the distance by
/// kOrbitZoomPerStep^steps, clamped to [kOrbitMinDistance_m, kOrbitMaxDistance_m].
/// Non-finite input leaves the camera unchanged.
void orbit_zoom(OrbitCamera& camera, float wheel_steps);

/// The orbit camera's pose: maps base-frame points into its optical frame, x right, y down,
/// z forward (towards the target), as the RealSense optical frames.
Pose orbit_T_view_base(const OrbitCamera& camera);

/// The orbit camera as a ViewCamera for project_to_view() and robot_mask(): a distortion-free
/// pinhole of width × height with square pixels, fy = (height / 2) / tan(fov / 2) and the
/// principal point at the image centre ((width − 1) / 2, (height − 1) / 2: the target lands
/// there); depth_to_view = orbit_T_view_base · inverse(frame.T_camera_base), so depth-camera
/// points go to the base frame and then into the orbit camera.
ViewCamera orbit_view_camera(const ViewFrame& frame, const OrbitCamera& camera, int width, int height);

/// A line between two points of the orbit camera's optical frame, cut at its near plane and at
/// the image (`in`: orbit_view_camera's intrinsics), 2·half_width + 1 pixels wide.
void draw_segment(ColorImage& image, const Intrinsics& in, const Eigen::Vector3f& a_view, const Eigen::Vector3f& b_view,
                  int half_width, const Rgb& color);

/// The robot's pixels (`robot`: robot_mask() of `out`'s size) brightened halfway to white, its
/// edge pixels (a robot pixel with a 4-neighbour that is not, or on the image border) exactly
/// kRobotOutline.
void draw_robot_pixels(const std::vector<uint8_t>& robot, ColorImage& out);

/// Sizes `out` to width × height (0 for a size ≤ 0), fills it with kCloudBackdrop and sets
/// `zbuffer` to +inf per pixel: the start of every 3D pane. Returns the pixel count.
size_t clear_3d_pane(int width, int height, std::vector<float>& zbuffer, ColorImage& out);

/// Reusable buffers of compose_3d(): sized on the first call of an image size, reused after.
struct Cloud3dScratch {
  std::vector<float> zbuffer;  ///< orbit-camera z per output pixel, metres
  std::vector<uint8_t> robot;  ///< robot_mask() of the orbit camera
};

/// Everything the 3D pane draws, in this order, into `out` (width × height rgb8; empty for a
/// size ≤ 0):
/// - kCloudBackdrop, then the floor grid in kCloudFloorGrid (1 px lines);
/// - the valid pixels of frame.depth (every kCloudPixelStride-th, deprojected with
///   frame.depth_intrinsics) as grey splats, the nearest to the orbit camera winning;
/// - frame.foreground_camera (depth camera frame) in kCloudForeground, on top;
/// - the robot's pixels (robot_mask) brightened halfway to white, its edge pixels (a robot
///   pixel with a 4-neighbour that is not, or on the image border) exactly kRobotOutline;
/// - with a valid contact: a 3 px line in kContactLine between the two closest points, then
///   discs of kCloudMarkerRadius_px in exactly kContactMarker (contact.closest_camera) and
///   kRobotMarker (contact.closest_robot_base).
/// A frame whose depth size differs from its intrinsics' draws no cloud (the rest still).
void compose_3d(const ViewFrame& frame, const OrbitCamera& camera, int width, int height, Cloud3dScratch& scratch,
                ColorImage& out);

}  // namespace hrcsense::view
