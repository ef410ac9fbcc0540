// SPDX-License-Identifier: Apache-2.0
// hrcsense — segmentation: a learnt static background, the foreground mask against it,
// speckle removal by physical size, and deprojection of the foreground into point clouds.
#pragma once

#include "hrcsense/self_filter.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense {

/// What the background model learns per pixel from the first frames. A pixel is "reliable"
/// when it was valid in at least BackgroundParams::min_valid_ratio of the learning frames.
struct BackgroundModel {
  int width = 0;
  int height = 0;
  /// Background depth the foreground test compares with: a reliable pixel's mean over its valid
  /// samples; for an unreliable pixel the smallest mean among the reliable pixels closest to it
  /// in the image, within fill_radius_px (its own few samples are never used); 0 (unknown) when
  /// there is none, and where the pixel was never valid in a long batch (unseen_min_frames).
  std::vector<float> mean_m;
  /// Depth noise: a reliable pixel's standard deviation over its valid samples, raised to the
  /// learnt noise floor where the camera has no stereo noise model; for an unreliable pixel the
  /// spread of the pixel its mean came from.
  std::vector<float> spread_m;
  std::vector<float> valid_ratio;  ///< share of learning frames with a valid sample, 0..1
};

struct BackgroundParams {
  int frames = 100;                  ///< frames to learn from
  /// A reliable pixel "moves" while learning when its spread exceeds
  /// max(moving_k_sigma · σ_noise(z), moving_min_spread_m); σ_noise is the stereo model with a
  /// baseline, else the noise floor learnt from the batch (BackgroundLearner).
  float moving_k_sigma = 6.0F;
  float moving_min_spread_m = 0.03F;  ///< metres
  /// Learning refuses to finish while more than this share of reliable pixels moves.
  float max_moving_share = 0.002F;
  /// Motion must be at least this wide (px, odd): moving pixels count only when every pixel of
  /// the square around them moved too, so that flickering depth edges and single noisy pixels
  /// are not motion. 1 counts every moving pixel.
  int motion_min_width_px = 3;
  /// Pixels valid in fewer than this share of the learning frames are unreliable: they are
  /// neither motion nor background of their own (0..1).
  float min_valid_ratio = 0.5F;
  /// An unreliable pixel takes the background of the reliable pixels closest to it when they
  /// are at most this many pixels away (8-connected steps); beyond, its background stays unknown.
  int fill_radius_px = 16;
  /// A pixel never valid in a batch of at least this many frames cannot be measured there (a
  /// shiny or dark surface, out of range): its background stays unknown, so that anything
  /// measured there later counts (ForegroundParams::workspace_base). In shorter batches "never
  /// valid" is weak evidence (a pixel valid a third of the time misses 3 frames in 30 % of
  /// batches), and such pixels are filled like the other unreliable ones.
  int unseen_min_frames = 10;
  /// Upper bound of the learnt noise σ / z² (1/m): 1 cm at 1 m, 25 cm at 5 m, above any depth
  /// camera's; a larger median spread means that most of the view moved, not noise.
  float max_noise_per_z2 = 0.01F;
  /// Stereo noise model used for σ_model(z) (subpixel RMS in px; baseline from the frame).
  float subpixel_rms_px = 0.08F;
  /// `background.motion_max_distance_m`: with a MotionRegion, motion counts only where the
  /// moving pixel's mean or its nearest sample of the batch lies within this distance of the
  /// robot's capsules (and inside the workspace): what matters for safety is motion near the
  /// robot, not at the far wall.
  float motion_max_distance_m = 2.0F;
  /// A background loaded from a file is compared with this many first frames before it is
  /// trusted (BackgroundCheck); 0 trusts it at once (tests only).
  int check_frames = 5;
  /// The loaded background is refused when more than this share of the compared pixels are
  /// measured farther than it (BackgroundCheck).
  float check_max_farther_share = 0.05F;
};

/// Axis-aligned box in the base frame.
struct AlignedBox {
  Eigen::Vector3f min = Eigen::Vector3f::Constant(-1e9F);
  Eigen::Vector3f max = Eigen::Vector3f::Constant(1e9F);
  bool contains(const Eigen::Vector3f& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

/// Where motion during learning counts (BackgroundLearner::add): near the robot and inside the
/// workspace, base frame. Pixels that move elsewhere do not restart learning; their background
/// becomes unknown instead (foreground wherever it lies in the workspace, like an unseen
/// pixel), and BackgroundLearner::unsettled_pixels() counts them.
struct MotionRegion {
  Pose T_base_camera = Pose::Identity();
  const RobotModel* robot = nullptr;  ///< the robot's capsules now; null or empty: motion counts everywhere
  AlignedBox workspace_base;          ///< `foreground.workspace_base`
};

/// Learns the background from consecutive frames. When the scene moved during a batch of
/// `frames` frames, the batch is discarded and learning starts over (a person walking by
/// is never learnt as background).
namespace segmentation_detail {
struct BatchView;
}

struct BackgroundLearner {
  enum class Status { learning, restarted, ready };

  BackgroundParams params;
  /// `foreground.min_object_mm` (the Pipeline sets it): a blob of motion smaller than this at
  /// its depth is no person or object and does not restart learning; 0 counts every blob.
  float min_object_mm = 0.0F;
  /// A moving pixel is checked for edge flicker against the still pixels this far around it,
  /// so that a flickering band is at most 3 px wide (a depth camera's edge flicker is 1-3 px).
  /// A person swaying by 10 cm at 2.5 m moves their outline by about 5 px: only the middle of
  /// that band passes as flicker, the rest stays motion (and the erosion is taken before
  /// flicker is cleared, so the middle does not make the rest thin).
  static constexpr int kFlickerRadiusPx = 3;
  /// A flickering pixel's spread reaches its farther side within this many spreads
  /// (foreground.k_sigma's default).
  static constexpr float kFlickerCoverSigmas = 4.0F;

  /// Adds one frame. Returns `restarted` (with `message()` saying why) when the batch just
  /// completed showed motion, `ready` once `model()` is usable.
  /// With `region`, motion counts only inside it (see MotionRegion). With `robot`
  /// (SelfFilter::robot_pixels(), the frame's size), the robot's own pixels are no samples:
  /// the background behind the arm is learnt from the frames where the arm is elsewhere, and
  /// the arm's motion is never the scene's.
  Status add(const Frame& frame, const MotionRegion* region = nullptr, const RobotPixels* robot = nullptr);
  /// Pixels whose background is unknown because they moved outside the motion region in the
  /// batch that was learnt (0 before).
  size_t unsettled_pixels() const { return unsettled_; }
  bool ready() const { return ready_; }
  const BackgroundModel& model() const { return model_; }
  /// Why learning last restarted; empty if it never did.
  const std::string& message() const { return message_; }
  int frames_seen() const { return count_; }
  /// Throws the batch just learnt away (a ReferenceCheck found someone in it): learning starts
  /// over with the next frame, and message() says `why`.
  void refuse(const std::string& why);
  /// The depth noise σ / z² (1/m) the last completed batch was judged with: the stereo model's
  /// with a baseline, else learnt from the batch; 0 before the first batch.
  double noise_per_z2() const { return noise_per_z2_; }
  /// Pixels of the last completed batch that flickered at a depth edge: filled from their
  /// neighbours, never motion (0 before).
  size_t flickering_pixels() const { return flickering_; }

 private:
  std::vector<double> sum_, sum_sq_;
  size_t unsettled_ = 0;
  std::vector<uint32_t> valid_count_;
  std::vector<uint16_t> nearest_raw_;  ///< per pixel: the batch's nearest valid sample, 0 for none
  std::vector<uint16_t> farthest_raw_; ///< per pixel: the batch's farthest valid sample, 0 for none
  size_t flickering_ = 0;
  int count_ = 0;
  bool ready_ = false;
  double noise_per_z2_ = 0.0;
  BackgroundModel model_;
  std::string message_;
  // Scratch of the batch summary, sized with the image: spread / mean² samples for the noise
  // median, the moving mask and its erosion, and the fill's queue and distance per pixel.
  std::vector<float> ratios_;
  /// Per pixel: moved, row pass of the erosion, wide motion, moved outside the region, flickered
  /// at an edge, visited by the blob search.
  std::vector<uint8_t> moving_, eroded_, wide_, outside_, flicker_, seen_;
  std::vector<int32_t> fill_queue_;
  std::vector<uint16_t> fill_layer_;

  /// Steps of add(): start (or restart) a batch for a width × height image; add one frame's
  /// samples; summarise the completed batch into the model.
  Status start_batch(int width, int height);
  void accumulate(const DepthImage& depth, const RobotPixels* robot);
  Status finish_batch(const Frame& frame, const MotionRegion* region);
  /// Marks wide_ from moving_ and clears edge flicker (flicker_) from both.
  void mark_wide_motion();
  /// Noise floor, filled and flicker-covered pixels, unsettled pixels cleared: a still batch's
  /// model made ready for use.
  void settle_model(const segmentation_detail::BatchView& batch, int batch_frames, bool have_model);
  /// Marks moving_ (motion far from the robot cleared; edge flicker still in), flicker_,
  /// outside_; returns the number of reliable pixels.
  size_t find_motion(const segmentation_detail::BatchView& batch, const Intrinsics& intrinsics,
                     const MotionRegion* region);
  void cover_flicker(const segmentation_detail::BatchView& batch);
};

/// Checks a background loaded from a file against the first frames of the live scene. A
/// background nearer than the scene hides whatever stands in front of the true background, so
/// the check counts reliable background pixels that the frames measure *farther* than the
/// background by more than max(k_sigma · spread, min_margin_m): a person in the cell only makes
/// pixels nearer, while a moved camera or another cell's file makes many farther.
struct BackgroundCheck {
  int frames = 5;                  ///< frames to compare before the background is trusted
  float max_farther_share = 0.05F; ///< more of the compared pixels farther than this: mismatch
  float k_sigma = 4.0F;            ///< as ForegroundParams::k_sigma
  float min_margin_m = 0.02F;      ///< as ForegroundParams::min_margin_m
  float min_valid_ratio = 0.5F;    ///< reliable pixels only, as BackgroundParams::min_valid_ratio

  /// Compares one frame (same size as `model`); returns the number of frames seen so far.
  int add(const BackgroundModel& model, const DepthImage& depth);
  bool done() const { return seen_ >= frames; }
  /// Share of compared pixels measured farther than the background, 0..1 (0 before any).
  double farther_share() const { return compared_ > 0 ? static_cast<double>(farther_) / compared_ : 0.0; }
  /// Whether the frames seen contradict the background (meaningful once done()).
  bool mismatch() const { return farther_share() > max_farther_share; }

 private:
  int seen_ = 0;
  int64_t compared_ = 0;
  int64_t farther_ = 0;
};

struct ForegroundParams {
  /// A pixel is foreground when valid and nearer than the background by more than
  /// max(k_sigma · learnt spread, k_sigma · σ_model(z), min_margin_m).
  float k_sigma = 4.0F;
  float min_margin_m = 0.02F;     ///< metres
  /// Blobs whose physical size at their depth is below this are removed (speckles), mm. A blob's
  /// size is the diameter of the disc of its pixel area at its mean depth z:
  /// 2 · sqrt(pixels / π) · z / fx (8-connected pixels, split at depth jumps), so that it
  /// compares with a detection capability d given as a test piece's diameter (ISO 13855).
  /// 32 = 0.8 · the default d of 40 mm: a 40 mm sphere measures 35-45 mm (its visible cap's
  /// mean depth is nearer than its outline, edge pixels drop out; docs/SAFETY.md, "C and the
  /// detection capability"), so a threshold at d itself would remove it.
  float min_object_mm = 32.0F;
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
  /// Pixels that passed the background test but were the robot's own (SelfFilter), removed
  /// before speckle removal.
  size_t self_filtered_pixels = 0;
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
  /// With `robot` (SelfFilter::robot_pixels(), the frame's size), the robot's own pixels leave
  /// the foreground.
  bool extract(const Frame& frame, const Pose& T_base_camera, Foreground& out, const RobotPixels* robot = nullptr);

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

/// What a learnt background holds that the reference does not: one blob of pixels nearer than
/// the reference (ReferenceCheck::compare). Pixel coordinates are of the filtered image.
struct ReferenceFinding {
  bool found = false;       ///< a blob of at least the detection size lies near the robot
  int blobs = 0;            ///< such blobs; the fields below describe the one nearest the robot
  int u_min = 0, u_max = 0, v_min = 0, v_max = 0;  ///< its pixel box, inclusive
  size_t pixels = 0;        ///< its pixels
  float depth_m = 0.0F;     ///< its mean depth in the learnt background (camera z)
  float size_mm = 0.0F;     ///< its size: the diameter of the disc of its area at depth_m
  /// Its nearest point's distance to the robot's capsules (the surface, padding included) over
  /// the poses given; NaN when no pose was given (every blob then counts as near).
  float distance_m = 0.0F;
};

/// Compares a background learnt at start with a reference taught with the cell confirmed empty
/// (`background.reference`, `hrcsense teach`): someone who stood still while the background was
/// learnt is in the learnt background and nearer than the reference there, and would otherwise
/// never be foreground. A learnt pixel is "nearer" by the foreground test itself (the learnt
/// depth as a frame against the reference as background: ForegroundParams k_sigma, min_margin_m,
/// the stereo noise model, depth-jump splitting), and a blob counts when its disc diameter at its
/// depth is at least detection_mm and any of its points lies within max_distance_m of the
/// robot. Pixels where either background is unknown are not compared: the reference cannot speak
/// for what it never measured (the arm's own silhouette when it was taught, surfaces the camera
/// does not measure), and an unknown learnt pixel holds nobody.
struct ReferenceCheck {
  ForegroundParams foreground;   ///< the foreground test; its min_object_mm and workspace are not used
  float detection_mm = 40.0F;    ///< blobs at least this across count (`safety.detection_mm`)
  /// Blobs count within this distance of the robot (S_p at rest, or `safety.slow_distance_m`).
  float max_distance_m = 1.0F;

  /// The reference to compare with (a background file taught with the cell empty).
  void set_reference(BackgroundModel reference);
  bool has_reference() const { return has_reference_; }
  const BackgroundModel& reference() const { return reference_; }

  /// Compares `learnt` with the reference, for frames like `frame` (its size, intrinsics, depth
  /// unit and stereo baseline: the filtered frames the background was learnt from), the camera
  /// at `T_base_camera`. `robot_poses` holds the robot's capsules (base frame) at every pose the
  /// distance is taken over; empty: every blob counts. `robot` (the frame's size) removes the
  /// arm's own pixels. Nothing is found without a reference, or when `learnt` or `frame` is not
  /// of its size (the caller refuses such a reference first). Allocates on the first call and
  /// when the camera changes, not after.
  ReferenceFinding compare(const BackgroundModel& learnt, const Frame& frame, const Pose& T_base_camera,
                           const RobotModel& robot_poses, const RobotPixels* robot);

 private:
  BackgroundModel reference_;
  bool has_reference_ = false;
  ForegroundExtractor extractor_;   ///< prepared against reference_
  Frame learnt_frame_;              ///< the learnt background as a depth frame
  Foreground nearer_;               ///< its pixels nearer than the reference
  std::vector<float> distance_m_;   ///< per pixel of nearer_: distance to the robot
  std::vector<int32_t> queue_;      ///< the labelling's flood fill
};

}  // namespace hrcsense
