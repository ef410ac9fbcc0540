// SPDX-License-Identifier: Apache-2.0
// hrcsense — the robot's own pixels: its padded capsules rendered into the depth image's
// geometry, so that the arm is neither foreground (an intruder next to itself) nor learnt as
// background (docs/ROBOT.md, "Self-filter").
#pragma once

#include "hrcsense/types.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace hrcsense {

struct SelfFilterParams {
  /// `self_filter.enabled`: remove the robot's pixels from the foreground. The background
  /// learner masks the rendered robot whatever this says.
  bool enabled = true;
  /// `self_filter.margin_m`: a pixel inside the silhouette is the robot's when its depth is at
  /// or behind the padded surface minus this margin, up to the padded body's far side. The
  /// margin used is never less than the foreground's own noise test at that depth
  /// (ForegroundParams: max(margin_m, min_margin_m, k_sigma · σ_stereo(z))).
  float margin_m = 0.03F;
  /// `self_filter.dilate_px`: the silhouette grows by this many pixels (square), so that depth
  /// edges, the spatial filter's smear and the calibration's error stay covered. In the
  /// filtered image's pixels (after decimation).
  int dilate_px = 2;
  /// `self_filter.memory_frames`: the union of the poses of this many frames (the current one
  /// included) is rendered, because the depth filters remember past frames: the temporal
  /// filter lags about 1.5 frames and persistence refills holes with older depth.
  int memory_frames = 3;
};

struct ForegroundParams;  // segmentation.hpp: the foreground test the margin follows

/// Which raw depths of each pixel are the robot's: [from_raw[i], to_raw[i]] (both inclusive);
/// from_raw[i] = 0 where the robot is not in the pixel. Row-major, the rendered frame's size.
/// from_raw is also 0 outside columns [u0, u1) × rows [v0, v1), so that a reader can skip the
/// rest of the image (the default: the whole image, whatever its size).
struct RobotPixels {
  const uint16_t* from_raw = nullptr;
  const uint16_t* to_raw = nullptr;
  int u0 = 0, v0 = 0;
  int u1 = std::numeric_limits<int>::max(), v1 = std::numeric_limits<int>::max();
  /// How far (px, square) the depth filters smear the arm into its surroundings
  /// (SelfFilterParams::dilate_px): a candidate beyond the padded far side with the arm nearer
  /// and the background farther within this reach is a mix of the two, the arm's; 0: none is.
  int smear_px = 0;
  bool contains(size_t i, uint16_t raw) const {
    return from_raw[i] != 0 && raw >= from_raw[i] && raw <= to_raw[i];
  }
};

/// Renders the robot's remembered poses into a frame's geometry: per pixel the depths along
/// its ray inside the padded capsules of any remembered pose (from the nearest entry to the
/// farthest exit), dilated, and widened in front by the margin. A pixel measured there is the
/// robot's. Beyond the far side of the padded body it is not: the padding lies at least
/// padding_m behind the arm's visible surface, so a hand seen past it is a hand. Buffers are
/// sized on the first frame of a size and reused, so that steady-state frames do not allocate.
class SelfFilter {
 public:
  SelfFilterParams params;

  /// Remembers the robot's capsules at the current frame (base frame, padding included),
  /// forgetting the oldest beyond params.memory_frames.
  void add_pose(const RobotModel& robot_base);
  /// Forgets every pose (a run restarts, or the robot state became invalid).
  void clear_poses();
  /// Poses remembered now (≤ params.memory_frames).
  int poses() const { return pose_count_; }

  /// Renders the union of the remembered poses into the geometry of `frame` (its size,
  /// intrinsics, depth unit and stereo baseline), the camera at `T_base_camera`; the margin
  /// never undercuts `foreground`'s own noise test.
  void render(const Frame& frame, const Pose& T_base_camera, const ForegroundParams& foreground);
  /// The robot's raw depths per pixel of the last render (valid until the next render).
  RobotPixels robot_pixels() const {
    return {from_raw_.data(), to_raw_.data(), dirty_.u0, dirty_.v0, dirty_.u1, dirty_.v1, params.dilate_px};
  }
  /// The padded body's nearest depth per pixel in metres, dilated (+inf where no robot); for
  /// tests and the viewer.
  const std::vector<float>& surface_depth_m() const { return entry_m_; }
  /// Pixels inside the dilated silhouette in the last render.
  size_t silhouette_pixels() const { return silhouette_pixels_; }

 private:
  struct Rect {
    int u0 = 0, v0 = 0, u1 = 0, v1 = 0;  ///< [u0, u1) × [v0, v1); empty when u0 ≥ u1 or v0 ≥ v1
    bool empty() const { return u0 >= u1 || v0 >= v1; }
  };

  std::vector<RobotModel> ring_;  ///< the last poses, oldest overwritten first
  int ring_next_ = 0;
  int pose_count_ = 0;

  int width_ = 0, height_ = 0;
  std::vector<float> entry_m_;     ///< nearest padded surface per pixel, +inf outside the silhouette
  std::vector<float> exit_m_;      ///< farthest, 0 outside the silhouette
  std::vector<float> scratch_m_;   ///< the dilation's first pass
  std::vector<uint16_t> from_raw_, to_raw_;  ///< RobotPixels; from_raw_ 0 outside the silhouette
  Rect dirty_;                            ///< where the buffers may differ from "no robot"
  size_t silhouette_pixels_ = 0;
  // Rays (x/z, y/z) per pixel column and row for pinhole intrinsics, or per pixel otherwise.
  Intrinsics rays_for_{};
  bool pinhole_ = true;
  std::vector<float> ray_x_, ray_y_;

  void prepare(const Frame& frame);
  void clear(const Rect& rect);
  void dilate(const Rect& rect);
  /// Ray-casts one padded capsule (camera frame, radius r m) into entry_m_ and exit_m_ and
  /// grows `drawn` by the rows and columns it may cover.
  void draw_capsule(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float r, const Intrinsics& intr, Rect& drawn);
  /// Fills from_raw_ and to_raw_ inside `grown` from the dilated silhouette; returns its pixels.
  size_t mark_robot_depths(const Frame& frame, const ForegroundParams& noise, const Rect& grown);
};

}  // namespace hrcsense
