// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — `hrcsense-view --fused`: a cell with several cameras seen from the cameras'
// own outputs (docs/VIEWER.md, "A cell with several cameras"). Plain C++ on the values the DDS
// reader fills (dds/fused_view_types.hpp, no DDS type): the rows of the camera list, the fused
// closest pair and the one 3D pane with every camera's cloud, pose, depth preview and the robot.
#pragma once

#include "dds/fused_view_types.hpp"
#include "viewer/cloud_view.hpp"

#include "hrcsense/robot.hpp"

#include <optional>
#include <string>
#include <vector>

namespace hrcsense::view {

/// The colour of the i-th configured camera (its cloud, its frustum, its preview's frame and its
/// row), cycling through kFusedCameraColors. None is a marker colour of view_model.hpp.
inline constexpr Rgb kFusedCameraColors[] = {{0, 190, 255}, {255, 200, 40}, {120, 230, 90}, {255, 120, 90},
                                            {190, 150, 255}, {90, 230, 210}};
Rgb fused_camera_color(size_t index);

/// The fused closest pair: the smallest distance over every camera's per-link contacts (the
/// camera's overall contact when it sent no links) among the cameras whose newest measurement
/// is valid. A camera that withholds (learning, blocked, stale robot state) contributes nothing:
/// the fused verdict of such a cell is a stop anyway, and its old contact would be a lie.
struct FusedPair {
  bool valid = false;
  std::string camera;   ///< whose contact it is
  int link = -1;
  float distance_m = 0.0F;
  Eigen::Vector3f closest_base = Eigen::Vector3f::Zero();        ///< foreground point, base frame
  Eigen::Vector3f closest_robot_base = Eigen::Vector3f::Zero();  ///< point on the robot, base frame
};
FusedPair fused_closest_pair(const ros2::FusedView& view);

/// One line of the camera list.
struct FusedCameraRow {
  std::string name;
  Rgb color{};
  std::optional<double> age_ms;  ///< none before its first measurement
  bool valid = false;
  int reason_code = 0;
  std::string reason;            ///< the measurement's; "no measurement yet" before one
  size_t cloud_points = 0;
  int64_t rejected = 0;
};
/// The rows in configuration order, ages at `now_shared_ns` (CLOCK_REALTIME, ns).
std::vector<FusedCameraRow> fused_camera_rows(const ros2::FusedView& view, int64_t now_shared_ns);

/// The robot of the newest measurement (by capture) with a valid robot state, as capsules in
/// the base frame (robot_model_at with `robot`); empty when no camera sent one.
std::vector<Capsule> fused_robot_capsules(const ros2::FusedView& view, const RobotParams& robot);

/// An orbit camera over the cell: looks at the mean of the cameras' positions lowered to 0.5 m
/// above the floor, from the side of the first camera turned 45° and 30° above, at twice the
/// largest camera distance from that point (at least 3 m).
OrbitCamera fused_default_orbit(const ros2::FusedView& view);

/// Side of a frustum drawn for a camera, m along its optical axis.
inline constexpr float kFrustumDepth_m = 0.4F;
/// The previews drawn into the pane: each scaled to this height in pixels (whole-number steps
/// of its size), side by side from the bottom left, framed 2 px in its camera's colour.
inline constexpr int kPreviewHeight_px = 120;

/// Reusable buffers of compose_fused_3d().
struct FusedScratch {
  Cloud3dScratch cloud;
  std::vector<uint32_t> histogram, lut;
  DepthImage preview_depth;
  ColorImage preview_rgb;
};

/// The fused 3D pane, in this order, into `out` (width × height rgb8):
/// - kCloudBackdrop and the floor grid, as compose_3d();
/// - each camera's cloud (base frame) as kCloudPixelStride-square splats in its colour,
///   z-buffered among the cameras;
/// - each camera's frustum in its colour: lines from its origin (T_base_camera) to the four
///   image corners at kFrustumDepth_m (its measurement's intrinsics; 87° × 58°, a D435's depth
///   field, before one came) and the far rectangle;
/// - `capsules_base` brightened halfway to white, outlined in kRobotOutline;
/// - the fused pair: a 3 px kContactLine and discs of kCloudMarkerRadius_px in kContactMarker
///   (the foreground point) and kRobotMarker (the robot's);
/// - each camera's depth preview, coloured as the 2D pane's depth (Jet after equalisation,
///   invalid black), along the bottom (skipped when the pane is too small).
void compose_fused_3d(const ros2::FusedView& view, const std::vector<Capsule>& capsules_base, const FusedPair& pair,
                      const OrbitCamera& camera, int width, int height, FusedScratch& scratch, ColorImage& out);

}  // namespace hrcsense::view
