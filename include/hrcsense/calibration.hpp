// SPDX-License-Identifier: Apache-2.0
// hrcsense — the camera's pose from the arm's own depth (`hrcsense calibrate`,
// docs/CALIBRATION.md). The arm is the calibration target: its joints say where each of its
// visual shapes is in the base frame, the depth image says where the camera sees it.
//
//   ArmSamples samples(params, intrinsics, arm, base_frame);
//   for each frame with its joints: samples.add(index, frame.depth, q_rad);  // keyframes, farthest depth
//   CameraCalibration fit = calibrate_camera(samples, T_base_camera_told);
//
// 1. The background is the farthest depth each grid sample's 5×5 patch saw over the sweep: the
//    arm only ever makes a pixel nearer, so a patch nearer than it by candidate_margin_m shows
//    the arm (or something else that moved: a person, the robust fit's outliers).
// 2. A coarse alignment from the told pose (off by up to 0.2 m and 15°): per keyframe, the
//    centroid of the candidates against the centroid of the arm's surface as the current pose
//    would see it, solved for the rigid motion over the keyframes (Kabsch), a few rounds.
// 3. A robust point-to-surface refinement over every keyframe, from the told pose and from the
//    coarse one: Gauss–Newton on the signed distance of each candidate to its frame's visual
//    shapes, with a shrinking gate, Huber weights and a trust region, the pose's update in the
//    camera frame; keyframes with something else in view are then left out whole.
// 4. Its spread: a jackknife over groups of keyframes (what the poses disagree on, the
//    kinematic model's errors included), not the far smaller formal covariance of correlated
//    pixels.
// 5. In a cell with several cameras, camera_agreement compares two calibrated cameras: their
//    keyframes paired by the nearest arm pose (the arm's shapes within 4 cm), each camera's
//    points of a link fitted to the link's shapes at its own keyframe's joints by a translation.
#pragma once

#include "hrcsense/robot.hpp"
#include "hrcsense/types.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense {

/// How the calibration reads and fits (defaults and why: docs/CALIBRATION.md).
struct CalibrationParams {
  int grid_px = 4;                    ///< one sample per this many pixels in u and v
  /// A sample whose 5×5 median is nearer than the farthest 5×5 mean it saw by more than this (m),
  /// or by 6 σ of that mean's stereo noise where that is more (D435: 1.7 cm at 2 m, 5 cm at
  /// about 3.3 m at 848x480), is an arm candidate.
  float candidate_margin_m = 0.05F;
  /// A frame becomes a keyframe when some link origin or the flange moved this far (m) since
  /// the last keyframe: a held arm adds nothing new.
  double keyframe_motion_m = 0.02;
  int max_keyframes = 1200;           ///< keyframes kept at most (the oldest are thinned)
  /// The fit's final gate (m): a candidate farther than this from the arm's surface is not the
  /// arm (a person, a cable, a mixed edge pixel).
  float inlier_gate_m = 0.03F;
  /// Refusals (exit 1): fewer inlier samples than this over all keyframes...
  int min_arm_samples = 2000;
  /// ...fewer keyframes with the arm seen (each at least min_samples_per_pose inliers)...
  int min_poses = 4;
  int min_samples_per_pose = 50;
  /// ...an RMS point-to-surface residual over the inliers above this (m)...
  float max_residual_rms_m = 0.02F;
  /// ...or a spread (the jackknife's standard error, per axis, worst) above these: the poses do
  /// not pin every degree of freedom down.
  double max_sigma_translation_m = 0.002;
  double max_sigma_rotation_deg = 0.05;
  int jackknife_groups = 8;           ///< groups of keyframes the spread is computed over
};

/// One keyframe: the depth samples of the grid (raw units, 0 no depth) and the joints.
struct ArmKeyframe {
  int64_t frame_index = 0;
  JointAngles q_rad{};
  /// The median valid depth of the 5×5 pixels about each sample (0: fewer than half valid):
  /// what the candidate test compares with the background (its noise about a fifth of a
  /// pixel's). grid_width × grid_height, row-major.
  std::vector<uint16_t> depth_grid;
  /// Which pixel of the patch holds that median, (du + 2) + 5 (dv + 2): the point is deprojected
  /// there, a real pixel at its own depth.
  std::vector<uint8_t> median_at;
};

/// What the sweep showed: the farthest depth per grid sample and the keyframes.
class ArmSamples {
 public:
  /// `visual` is the arm's description; its visual shapes (robot_render_capsules) are the
  /// target, in `base_frame`.
  ArmSamples(const CalibrationParams& params, const Intrinsics& intrinsics, const RobotDescription& arm,
             BaseFrame base_frame);
  /// Adds one frame: its depth (of `intrinsics`' size; another size throws std::invalid_argument)
  /// and the arm's joints at its capture. `stereo_baseline_mm` scales the noise margin (0:
  /// the D435's). Returns whether it became a keyframe.
  bool add(int64_t frame_index, const DepthImage& depth, const JointAngles& q_rad, float stereo_baseline_mm = 0.0F);

  const CalibrationParams& params() const { return params_; }
  const Intrinsics& intrinsics() const { return intrinsics_; }
  const RobotDescription& arm() const { return arm_; }
  BaseFrame base_frame() const { return base_frame_; }
  int grid_width() const { return grid_width_; }
  int grid_height() const { return grid_height_; }
  float depth_scale_m() const { return depth_scale_m_; }
  int64_t frames() const { return frames_; }
  const std::vector<ArmKeyframe>& keyframes() const { return keyframes_; }
  /// Farthest 5×5 mean depth (raw) each grid sample saw (0: never a depth).
  const std::vector<uint16_t>& farthest() const { return farthest_; }
  /// Grid samples whose farthest depth grew by more than candidate_margin_m since the last
  /// call (the background still being uncovered); resets the count.
  int64_t take_background_changes();
  /// The candidate margin (raw depth units) against a farthest mean of `farthest_raw`.
  int margin_raw(uint16_t farthest_raw) const;
  /// `sigmas` times one pixel's stereo depth noise at `depth_raw` (raw units).
  int noise_raw(uint16_t depth_raw, double sigmas) const;

 private:
  CalibrationParams params_;
  Intrinsics intrinsics_;
  RobotDescription arm_;
  BaseFrame base_frame_;
  int grid_width_ = 0;
  int grid_height_ = 0;
  float depth_scale_m_ = 0.001F;
  float baseline_mm_ = 0.0F;
  int64_t frames_ = 0;
  int64_t background_changes_ = 0;
  std::vector<uint16_t> farthest_;
  std::vector<ArmKeyframe> keyframes_;
  std::vector<Eigen::Vector3d> last_key_origins_base_;
};

/// The arm candidates of one keyframe: for the grid samples whose 5×5 median stands nearer than
/// the farthest mean by margin_raw, the camera-frame point of the pixel holding that median.
std::vector<Eigen::Vector3f> arm_candidates(const ArmSamples& samples, const ArmKeyframe& keyframe);

/// Signed distance (m) from `point_base` to the surface of the nearest of `shapes` (negative
/// inside), and that surface's outward normal there (unit; any unit vector on an axis).
float distance_to_shapes(const std::vector<Capsule>& shapes, const Eigen::Vector3f& point_base,
                         Eigen::Vector3f& normal_base);

/// The result of calibrate_camera.
struct CameraCalibration {
  bool ok = false;                 ///< false: refused; `problem` says why
  std::string problem;             ///< for people: what is missing and what to do
  Pose T_base_camera = Pose::Identity();
  Pose T_base_camera_coarse = Pose::Identity();  ///< after the coarse alignment
  double residual_rms_m = 0.0;     ///< RMS signed distance of the inliers to the shapes
  double sigma_translation_m = 0.0;  ///< jackknife standard error of the camera's position, worst axis
  double sigma_rotation_deg = 0.0;   ///< ...of its orientation, worst axis (camera frame)
  size_t inliers = 0;              ///< samples within the final gate
  size_t candidates = 0;           ///< arm candidates over all keyframes
  int poses = 0;                   ///< keyframes with at least min_samples_per_pose inliers
  /// Keyframes left out whole: more than a tenth of their candidates lie 10 cm or more off the
  /// fitted arm (a person or another moving thing in view).
  size_t keyframes_left_out = 0;
  int iterations = 0;              ///< Gauss–Newton steps of the refinement
};

/// Fits the camera pose to the samples, starting from `T_base_camera_told` (the configured
/// pose), and checks it against the refusal limits of the params. Without `with_spread` the
/// jackknife is skipped (sigma_* stay 0 and cannot refuse): the quicker fit of a progress check.
CameraCalibration calibrate_camera(const ArmSamples& samples, const Pose& T_base_camera_told, bool with_spread = true);

/// What one camera saw of the arm in one keyframe: its arm candidates in the base frame (through
/// the camera's pose) and the arm's visual shapes at the keyframe's joints.
struct ArmView {
  JointAngles q_rad{};
  std::vector<Eigen::Vector3f> points_base;
  std::vector<Capsule> shapes_base;
};

/// The keyframes with arm candidates, seen through `T_base_camera` (a fitted or configured pose).
std::vector<ArmView> arm_views(const ArmSamples& samples, const Pose& T_base_camera);

/// How camera_agreement pairs views and points (docs/CALIBRATION.md, "Cells with several cameras").
struct AgreementParams {
  /// Two views may pair when no end of any of the arm's shapes lies farther than this (m) from
  /// where it is in the other view. Each camera's offset is measured against the arm's model at
  /// its own view's joints, so the move itself does not bias it; what differs between the two
  /// poses is only what a camera's rotation error ε adds, at most ε times this (1° over 4 cm:
  /// 0.7 mm). Twice the keyframes' spacing (keyframe_motion_m), so that a camera at another
  /// rate or phase finds a neighbour for nearly every keyframe of a sweep.
  double pair_travel_m = 0.04;
  /// A point farther than this (m) from the arm's shapes is not the arm (wider than the fit's
  /// 3 cm gate, so that a pose some centimetres off still finds its points).
  float gate_m = 0.06F;
  /// A link counts in a view pair when each camera has at least this many points on it...
  int min_points = 20;
  /// ...and is compared when each camera has this many over all view pairs: fewer, and the
  /// noise alone moves an offset by millimetres (a wrist seen in a handful of views).
  int min_link_points = 500;
  /// A direction whose eigenvalue of the points' Σ n nᵀ is below this share of the largest is not
  /// constrained: the offset's component there is 0 (a link seen along a line of normals only).
  double min_axis_share = 0.02;
};

/// Two cameras' offsets of one link's surface (or of every shared link's, `link` −1).
struct LinkAgreement {
  int link = 0;             ///< Capsule::link, −1 for all shared links together
  int views = 0;            ///< view pairs in which both cameras saw the link (link views for −1)
  size_t points_a = 0;      ///< points of camera a in those views
  size_t points_b = 0;
  /// The translation (base frame, m) that moves the arm's shapes onto each camera's points best
  /// (least squares of the points' signed distances to the link's shapes).
  Eigen::Vector3d offset_a_base_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d offset_b_base_m = Eigen::Vector3d::Zero();
  double disagreement_m = 0.0;  ///< |offset_a − offset_b|: where the two cameras put the same surface apart
  int constrained_axes = 0;     ///< directions both offsets are constrained in (3: all)
};

/// How two cameras agree on the parts of the arm both saw at nearby arm poses.
struct CameraAgreement {
  int views_a = 0;                  ///< the views given of camera a (keyframes with arm points)
  int views_b = 0;                  ///< the same of camera b
  int paired_views = 0;             ///< pairs of a view of a and one of b, each view in one pair at most
  double pair_travel_median_m = 0.0;  ///< how far the arm's shapes lie apart between a pair's views: the median...
  double pair_travel_max_m = 0.0;     ///< ...and the largest over the pairs (at most pair_travel_m)
  double pair_joint_max_rad = 0.0;    ///< the largest difference of a joint between a pair's views
  std::vector<LinkAgreement> links; ///< per link both saw enough of (min_points, min_link_points), by link
  LinkAgreement all;                ///< every shared link's points together
};

/// Pairs the views of `a` with views of `b` of nearby arm poses (nearest first, each view once,
/// within params.pair_travel_m; views of two different shape lists never pair) and compares, per
/// link both saw in a pair, the two cameras' surface offsets from the arm's shapes, each at its
/// own view's joints: with both poses right both are near 0; a camera whose pose is shifted by δ
/// has an offset of about δ. Deterministic: ties go to the earlier views.
CameraAgreement camera_agreement(const std::vector<ArmView>& a, const std::vector<ArmView>& b,
                                 const AgreementParams& params = {});

/// The rotation angle (deg) and translation (m) between two poses: how far a calibration is
/// from another.
double rotation_between_deg(const Pose& a, const Pose& b);
double translation_between_m(const Pose& a, const Pose& b);

}  // namespace hrcsense
