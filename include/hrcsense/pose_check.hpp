// SPDX-License-Identifier: Apache-2.0
// hrcsense — the per-frame camera pose check (docs/SAFETY.md, "Watchdogs", camera_pose_mismatch):
// the arm's visual shapes, placed by the frame's joints and seen through the told camera pose,
// must be where the camera measures the arm. A sparse grid of rays through the arm's projected
// silhouette is cast against those shapes; at each ray the predicted depth of the visible surface
// is compared with the measured depth (5×5-pixel means of the source frame). A told pose wrong
// by a centimetre or a degree moves the arm by pixels and centimetres: its pixels then show the
// table behind it, or its surface at another depth. Unlike camera_moved it needs no background, so it also sees a pose that was
// wrong before learning.
#pragma once

#include "hrcsense/types.hpp"

#include <cstddef>
#include <vector>

namespace hrcsense {

/// `safety.pose_check*` (defaults and why: docs/SAFETY.md, "The camera pose check").
struct PoseCheckParams {
  /// `safety.pose_check`: check the told pose against the arm each frame (arms only; the check
  /// does nothing for robot.model points, which have no body to see).
  bool enabled = true;
  /// `safety.pose_check_threshold_m`: the mean disagreement beyond the stereo noise's own over
  /// the window above which the pose is wrong, m (a sample's disagreement is |measured −
  /// predicted| depth, at most cap_m; the noise's share is PoseDisagreement::noise_floor_m).
  float threshold_m = 0.004F;
  /// The depth camera's disparity noise, σ in pixels (the D435's subpixel RMS): with the frame's
  /// stereo baseline it gives each sample's expected |disagreement| from noise alone, which
  /// grows as z² (a 5×5 mean: 2.7 mm at 2.1 m, 6 mm at 3.2 m) and is taken off before the
  /// threshold. 0, or a frame without a baseline: no noise is taken off.
  float noise_px = 0.08F;
  /// `safety.pose_check_min_arm_pixels`: fewer usable samples in a frame: the arm is not in
  /// view and the frame says nothing (neither fires nor clears).
  int min_arm_pixels = 100;
  /// `safety.pose_check_window_frames`: frames with the arm in view the decision spans; the
  /// check fires when their mean disagreement exceeds threshold_m and clears when each of them
  /// is at or below it.
  int window_frames = 8;
  int grid_px = 3;             ///< one ray per this many pixels in u and v
  /// A ray counts only where it passes the hit shape's axis within this share of its radius:
  /// away from the silhouette's edge, where depth mixes the arm with what lies behind it.
  float core_share = 0.6F;
  /// Measured nearer than predicted by more than this (m): something in front of the arm (a
  /// person's hand) occludes it there; the sample is not used.
  float occlusion_m = 0.08F;
  /// A sample's measured depth is the mean of the valid pixels within this many pixels of it
  /// (a square): the stereo noise averaged down.
  int patch_px = 2;
  float cap_m = 0.2F;          ///< a sample's disagreement counts at most this much, m
};

/// One frame's comparison of the measured arm with its shapes.
struct PoseDisagreement {
  size_t samples = 0;          ///< usable samples: valid depth, inside the core, not occluded
  float mean_m = 0.0F;         ///< mean of min(|measured − predicted|, cap_m) over them, m
  float signed_mean_m = 0.0F;  ///< mean of measured − predicted (clamped to ±cap_m), m
  /// The part of mean_m stereo noise alone gives with the pose right: the mean over the samples
  /// of E|N(0, σ)| = σ·√(2/π), σ = z²·noise_px / (fx·B) / √(valid pixels of the patch), m.
  float noise_floor_m = 0.0F;
};

/// Nearest depth (camera z, m) at which the ray through the camera-frame direction
/// `ray_camera` (its z must be 1, so that the ray parameter is the depth) enters the capsule
/// from a_camera to b_camera of radius `radius_m`, and the ray's least distance to the capsule's
/// axis segment as a share of the radius (in [0, 1) for a hit). Returns false when the ray
/// misses or the capsule lies behind the camera.
struct CapsuleHit {
  float depth_m = 0.0F;
  float axis_share = 1.0F;
};
bool ray_capsule_depth(const Eigen::Vector3f& ray_camera, const Eigen::Vector3f& a_camera,
                       const Eigen::Vector3f& b_camera, float radius_m, CapsuleHit& hit);

/// A visual shape in the camera frame and the pixels its projection may cover,
/// [u0, u1] × [v0, v1] (pose_disagreement's scratch; the calibration's predicted arm).
struct ShapeInCamera {
  Eigen::Vector3f a_camera = Eigen::Vector3f::Zero();
  Eigen::Vector3f b_camera = Eigen::Vector3f::Zero();
  float radius_m = 0.0F;
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;
};

/// The visual shapes `visual_base` (base frame) mapped into the camera with `T_base_camera`, each
/// with the pixels its projection may cover; shapes too near or behind the camera, or outside
/// the image, are left out. Reuses `shapes` (no allocation once sized).
void shapes_in_camera(const Intrinsics& intrinsics, const Pose& T_base_camera, const RobotModel& visual_base,
                      std::vector<ShapeInCamera>& shapes);

/// The pixels all of `shapes` may cover: [u0, u1] × [v0, v1]; empty (u1 < u0) without shapes.
struct ShapesPixelBox {
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;
};
ShapesPixelBox shapes_pixel_box(const std::vector<ShapeInCamera>& shapes, const Intrinsics& intrinsics);

/// The nearest entry along `ray_camera` (z = 1) through pixel (u, v) into those of `shapes` that
/// may cover it; depth 0 when none is hit.
CapsuleHit nearest_shape_hit(const std::vector<ShapeInCamera>& shapes, int u, int v, const Eigen::Vector3f& ray_camera);

/// Compares `depth` (the pipeline gives the source frame's, before the filters; with its
/// `intrinsics`: pinhole, distortion ignored, D435 depth has none) with the arm's visual shapes
/// `visual_base` (robot_render_capsules at this frame's joints, base frame) seen from
/// `T_base_camera`. The depth must be of the frame's own moment: an image from the temporal
/// filter shows a moving arm where it was. `stereo_baseline_m` (0: unknown) sets the noise
/// floor. `shapes` is scratch, reused (no allocation once sized).
PoseDisagreement pose_disagreement(const PoseCheckParams& params, const DepthImage& depth,
                                   const Intrinsics& intrinsics, const Pose& T_base_camera,
                                   const RobotModel& visual_base, std::vector<ShapeInCamera>& shapes,
                                   float stereo_baseline_m = 0.0F);

/// The decision over frames: a window of the last in-view frames' disagreements. A frame
/// without the arm in view leaves it as it was.
struct PoseCheck {
  PoseCheckParams params;
  /// Adds one frame's comparison; returns whether the pose is now judged wrong.
  bool add(const PoseDisagreement& frame);
  bool mismatch() const { return mismatch_; }
  /// The mean disagreement beyond the noise floor over the window (m), 0 before the window is full.
  float window_mean_m() const { return window_mean_m_; }
  /// Forgets every frame (a new run).
  void reset();

 private:
  std::vector<float> window_m_;  ///< ring of the last window_frames in-view disagreements
  size_t next_ = 0;
  size_t filled_ = 0;
  bool mismatch_ = false;
  float window_mean_m_ = 0.0F;
};

}  // namespace hrcsense
