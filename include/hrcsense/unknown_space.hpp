// SPDX-License-Identifier: Apache-2.0
// hrcsense — unknown space near the robot (docs/SAFETY.md, "Unknown space"): the rays along
// which the camera cannot tell whether something is there, and how close the robot comes to
// them. A pixel is unknown when it has no depth now but had a reliable background (from the
// camera to the background), or when it is foreground (hidden behind it: from the measured
// depth to the background). The robot's own envelope (the self-filter's rendered, dilated
// projection: the arm and the stereo shadow at its edges) is never unknown, so that the arm
// does not freeze itself.
#pragma once

#include "hrcsense/segmentation.hpp"
#include "hrcsense/self_filter.hpp"
#include "hrcsense/types.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace hrcsense {

/// What unknown_space() finds in one filtered frame.
struct UnknownSpace {
  /// The robot's smallest distance to an unknown ray segment (its closest approach to the
  /// capsules' surfaces, 0 when a segment passes through one), m; NaN without unknown space.
  float distance_m = std::numeric_limits<float>::quiet_NaN();
  size_t no_depth_pixels = 0;   ///< invalid now, reliable background, outside the robot's envelope
  size_t hidden_pixels = 0;     ///< foreground: the space behind it is hidden
  /// Invalid now where the background was not always valid while learning (valid in fewer
  /// than min_valid_ratio of its frames: a shiny table, a far wall at the edge of the range):
  /// unknown when the cell was taught, reported apart and not measured against.
  size_t never_valid_pixels = 0;
  /// Invalid now in the robot's stereo shadow: immediately left of its envelope, at most
  /// fx·B·(1/z_robot − 1/z_background) + 1 px wide (the D435 sensor model's occlusion band).
  size_t robot_shadow_pixels = 0;
  /// Without depth for fewer than min_no_depth_frames frames: the sensor's random dropouts.
  size_t dropout_pixels = 0;
};

/// The segment of the ray through pixel centre (u, v) between depths z0 and z1 (m, along the
/// camera's z axis), in the base frame. Pinhole model (the depth stream has no distortion).
struct RaySegment {
  Eigen::Vector3f from_base = Eigen::Vector3f::Zero();
  Eigen::Vector3f to_base = Eigen::Vector3f::Zero();
};
RaySegment ray_segment(const Intrinsics& intrinsics, const Pose& T_base_camera, int u, int v, float z0_m, float z1_m);

/// Smallest distance between segment [p0, p1] and the capsules' surfaces (≥ 0); +inf without capsules.
float segment_capsule_distance(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, const RobotModel& robot);

/// How unknown_space() tells unknown space from the sensor's own gaps.
struct UnknownSpaceParams {
  /// Unknown rays start this far from the camera (m): nothing nearer can be measured, nor stand
  /// there in a cell (the blocked watchdog's job).
  float near_m = 0.2F;
  /// A pixel without depth now is unknown only where it had depth in at least this share of
  /// the learning frames.
  float min_valid_ratio = 0.95F;
  /// ... and only once it has had no depth for this many frames in a row (count_no_depth_frames):
  /// a single frame's gap is the sensor's random dropout. 3 frames: 100 ms at 30 frames/s.
  int min_no_depth_frames = 3;
};

/// The pixels of a background that unknown_space() calls reliable — known (mean > 0) and with
/// depth in at least min_valid_ratio of its learning frames (NaN is neither) — one bit each,
/// prepared once per background. The model's two float arrays are 8 bytes a pixel, read where a
/// pixel has no depth; the stages before unknown space push them out of the cache, so that each
/// frame paid two cache misses per block with a gap. These bits are 1/64 of that.
struct ReliableBackground {
  std::vector<uint8_t> bits;  ///< pixel i: bit i % 8 of bits[i / 8]; two bytes of padding after
  size_t pixels = 0;          ///< the model's pixel count
};
ReliableBackground reliable_background(const BackgroundModel& background, float min_valid_ratio);

/// Counts, per pixel, the frames in a row without depth up to and including `depth` (saturating
/// at 255); resized (and zeroed) when the image size changes.
void count_no_depth_frames(const DepthImage& depth, std::vector<uint8_t>& no_depth_frames);

/// Unknown space in `depth` (filtered, with `intrinsics`) against `background`, behind the
/// foreground `foreground_mask` (1 = foreground; may be empty), outside `robot_pixels` (may be
/// null: no envelope) and the robot's stereo shadow (`stereo_baseline_m` 0: no shadow is
/// recognised), measured against `robot`. `no_depth_frames` from count_no_depth_frames (empty:
/// every gap counts at once).
UnknownSpace unknown_space(const DepthImage& depth, const Intrinsics& intrinsics, const BackgroundModel& background,
                           const std::vector<uint8_t>& foreground_mask, const RobotPixels* robot_pixels,
                           const Pose& T_base_camera, const RobotModel& robot, float stereo_baseline_m,
                           const std::vector<uint8_t>& no_depth_frames, const UnknownSpaceParams& params = {});

/// The same with the background's reliable pixels prepared (reliable_background(background,
/// params.min_valid_ratio)): what a stream of frames against one background calls. The ratio
/// is the one `reliable` was prepared with (params.min_valid_ratio is not read again); nothing
/// is reliable when `reliable` was prepared for another size.
UnknownSpace unknown_space(const DepthImage& depth, const Intrinsics& intrinsics, const BackgroundModel& background,
                           const ReliableBackground& reliable, const std::vector<uint8_t>& foreground_mask,
                           const RobotPixels* robot_pixels, const Pose& T_base_camera, const RobotModel& robot,
                           float stereo_baseline_m, const std::vector<uint8_t>& no_depth_frames,
                           const UnknownSpaceParams& params = {});

}  // namespace hrcsense
