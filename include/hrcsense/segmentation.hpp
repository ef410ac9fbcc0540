// SPDX-License-Identifier: Apache-2.0
// hrcsense — segmentation: a learnt static background, the foreground mask against it,
// speckle removal by physical size, and deprojection of the foreground into point clouds.
#pragma once

#include "hrcsense/types.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense {

/// What the background model learns per pixel from the first frames.
struct BackgroundModel {
  int width = 0;
  int height = 0;
  std::vector<float> mean_m;       ///< mean depth over the valid samples; 0 if never valid
  std::vector<float> spread_m;     ///< standard deviation over the valid samples
  std::vector<float> valid_ratio;  ///< share of learning frames with a valid sample, 0..1
};

struct BackgroundParams {
  int frames = 100;                  ///< frames to learn from
  /// A pixel "moves" while learning when its spread exceeds
  /// max(moving_k_sigma · σ_model(z), moving_min_spread_m).
  float moving_k_sigma = 6.0F;
  float moving_min_spread_m = 0.03F;  ///< metres
  /// Learning refuses to finish while more than this share of valid pixels moves.
  float max_moving_share = 0.002F;
  /// Stereo noise model used for σ_model(z) (subpixel RMS in px; baseline from the frame).
  float subpixel_rms_px = 0.08F;
};

/// Learns the background from consecutive frames. When the scene moved during a batch of
/// `frames` frames, the batch is discarded and learning starts over (a person walking by
/// is never learnt as background).
struct BackgroundLearner {
  enum class Status { learning, restarted, ready };

  BackgroundParams params;

  /// Adds one frame. Returns `restarted` (with `message()` saying why) when the batch just
  /// completed showed motion, `ready` once `model()` is usable.
  Status add(const Frame& frame);
  bool ready() const { return ready_; }
  const BackgroundModel& model() const { return model_; }
  /// Why learning last restarted; empty if it never did.
  const std::string& message() const { return message_; }
  int frames_seen() const { return count_; }

 private:
  std::vector<double> sum_, sum_sq_;
  std::vector<uint32_t> valid_count_;
  int count_ = 0;
  bool ready_ = false;
  BackgroundModel model_;
  std::string message_;
};

/// Axis-aligned box in the base frame.
struct AlignedBox {
  Eigen::Vector3f min = Eigen::Vector3f::Constant(-1e9F);
  Eigen::Vector3f max = Eigen::Vector3f::Constant(1e9F);
  bool contains(const Eigen::Vector3f& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

struct ForegroundParams {
  /// A pixel is foreground when valid and nearer than the background by more than
  /// max(k_sigma · learnt spread, k_sigma · σ_model(z), min_margin_m).
  float k_sigma = 4.0F;
  float min_margin_m = 0.02F;     ///< metres
  /// Blobs whose physical size at their depth is below this are removed (speckles).
  float min_object_mm = 40.0F;
  /// Where the background was never valid, a pixel counts only inside this box (base frame).
  /// Default: everywhere, so nothing unknown is ignored.
  AlignedBox workspace_base;
  float subpixel_rms_px = 0.08F;  ///< stereo noise model for σ_model(z)
};

/// The segmented foreground of one frame.
struct Foreground {
  std::vector<uint8_t> mask;  ///< 1 = foreground pixel (after speckle removal)
  PointCloud points_camera;   ///< camera frame, metres
  PointCloud points_base;     ///< robot base frame, metres
};

/// Extracts the foreground. set_background() solves the background test once per pixel into
/// a raw-depth threshold, so that the per-frame test is one 16-bit comparison; the extractor
/// also holds scratch buffers, so that extract() does not allocate after its first frame.
struct ForegroundExtractor {
  ForegroundParams params;

  /// Prepares the test against `background` for frames of its size from a camera with focal
  /// length `fx_px` (px), stereo baseline `stereo_baseline_mm` (0 when unknown: no noise-model
  /// margin) and depth unit `depth_scale_m` (metres per raw unit, > 0), with the current
  /// `params` (k_sigma ≥ 0). Allocates and takes a few milliseconds at 848x480: call it once
  /// per background, and again when the camera or `params` change.
  void set_background(const BackgroundModel& background, float fx_px, float stereo_baseline_mm,
                      float depth_scale_m);
  /// Forgets the prepared background; extract() fails until the next set_background().
  void clear_background() { prepared_ = false; }
  /// Whether set_background() prepared the test for frames like `frame` (same size, fx,
  /// baseline and depth unit) with the current `params`.
  bool prepared_for(const Frame& frame) const;

  /// Fills `out` from `frame` against the prepared background, with `T_base_camera` for the
  /// base frame. Returns false, with an empty mask and clouds, when !prepared_for(frame): the
  /// caller must then treat the frame as unusable (a stop), never as free of foreground.
  bool extract(const Frame& frame, const Pose& T_base_camera, Foreground& out);

 private:
  // What set_background() was called with; prepared_for() compares frames and params to it.
  bool prepared_ = false;
  int width_ = 0, height_ = 0;
  float fx_px_ = 0.0F, stereo_baseline_mm_ = 0.0F, depth_scale_m_ = 0.0F;
  ForegroundParams prepared_params_;
  // Per pixel: candidate iff uint16(raw − 1) < nearer_count_[i]; unknown_[i] holds the mask's
  // "unknown background" state where the background was never valid, else 0.
  std::vector<uint16_t> nearer_count_;
  std::vector<uint8_t> unknown_;
  // The flood fill's jump limit per raw depth (65536 entries), in raw units, rounded up.
  std::vector<int32_t> jump_limit_raw_;
  // Scratch reused across frames (sized once per image size): the flood fill's queue of
  // packed (v << 16 | u) pixels, the pinhole rays (u − ppx) / fx and (v − ppy) / fy, and which
  // mask states each row holds after the background test.
  std::vector<int32_t> stack_;
  std::vector<float> ray_x_;
  std::vector<float> ray_y_;
  std::vector<uint8_t> row_states_;
};

}  // namespace hrcsense
