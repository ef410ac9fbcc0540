// SPDX-License-Identifier: Apache-2.0
// hrcsense — background learning: per-pixel mean, spread and valid ratio over a still batch, a
// noise floor learnt from the batch when the camera has no noise model, and a background for
// the pixels the camera measures too rarely to learn one of their own.
//
// Why it is built this way: a structured-light camera at 2–9 m (../shared/data/
// ist_piv_lab_people) loses and regains about 12 % of its pixels between frames of an empty
// room and quantises depth in steps of ~0.003·z² (7 cm at 5 m). Counting every flickering or
// one-step pixel as motion makes learning restart forever; so flicker makes a pixel unreliable,
// not moving, noise is judged against a floor learnt from the whole image, and motion has to
// cover an area (a person does, a flickering depth edge does not).

#include "hrcsense/camera.hpp"
#include "hrcsense/segmentation.hpp"

#include "background_motion.hpp"
#include "capsule_distance.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

namespace hrcsense {

using segmentation_detail::BatchView;
using segmentation_detail::mark_edge_flicker;
using segmentation_detail::describe_blob;
using segmentation_detail::object_motion;
using segmentation_detail::ObjectMotion;
using segmentation_detail::pooled_noise_per_z2;

namespace {

std::string size_changed_message(int old_w, int old_h, int new_w, int new_h) {
  char text[160];
  std::snprintf(text, sizeof text,
                "background learning restarted: the depth image size changed from %dx%d to %dx%d",
                old_w, old_h, new_w, new_h);
  return text;
}

std::string motion_message(double moving_share, int frames, double limit_share, const std::string& where) {
  char text[160];
  std::snprintf(text, sizeof text,
                "background learning restarted: %.1f %% of pixels changed during the last %d frames "
                "(limit %.1f %%); ",
                100.0 * moving_share, frames, 100.0 * limit_share);
  return text + where + "; is something moving in the cell?";
}

/// The running sums of one learning batch, in raw depth units.
struct BatchSums {
  const double* sum;
  const double* sum_sq;
  const uint32_t* valid_count;
  size_t pixels;
  int frames;
};

/// Writes mean and spread over the valid samples and the valid ratio of every pixel.
void write_statistics(const BatchSums& sums, double scale_m, BackgroundModel& model) {
  const double frames = sums.frames;
  for (size_t i = 0; i < sums.pixels; ++i) {
    const uint32_t valid = sums.valid_count[i];
    if (valid == 0) {
      model.mean_m[i] = 0.0F;
      model.spread_m[i] = 0.0F;
      model.valid_ratio[i] = 0.0F;
      continue;
    }
    const double mean_raw = sums.sum[i] / valid;
    const double variance_raw = std::max(0.0, sums.sum_sq[i] / valid - mean_raw * mean_raw);
    model.mean_m[i] = static_cast<float>(mean_raw * scale_m);
    model.spread_m[i] = static_cast<float>(std::sqrt(variance_raw) * scale_m);
    model.valid_ratio[i] = static_cast<float>(valid / frames);
  }
}

bool is_reliable(const BackgroundModel& model, size_t i, float min_valid_ratio) {
  return model.valid_ratio[i] > 0.0F && model.valid_ratio[i] >= min_valid_ratio;
}

/// How much smaller the median spread of n Gaussian samples (population formula) is than σ:
/// sqrt(median(χ²ₙ₋₁) / n), with the Wilson–Hilferty approximation of the χ² median
/// (k · (1 − 2 / 9k)³, within 1 % for k ≥ 1). 0.68 for 3 samples, 0.91 for 10.
double median_spread_per_sigma(uint32_t samples) {
  const double k = samples - 1.0;
  const double c = 1.0 - 2.0 / (9.0 * k);
  return std::sqrt(k * c * c * c / samples);
}

/// The depth noise σ / z² (1/m) of a batch without a stereo noise model: the median over the
/// reliable pixels with at least two samples of spread / mean², each spread corrected for its
/// sample count (a spread over a few samples is mostly smaller than σ). The median, because up
/// to half of the pixels may move or flicker without moving it, while any higher quantile would
/// let a person covering a fifth of the view raise the floor above their own motion. A noise-free
/// camera gives 0.
double learnt_noise_per_z2(const BatchSums& sums, const BackgroundModel& model, float min_valid_ratio,
                           std::vector<float>& ratios) {
  ratios.clear();  // keeps its capacity: no allocation after the first batch of a size
  for (size_t i = 0; i < sums.pixels; ++i) {
    const uint32_t samples = sums.valid_count[i];
    if (samples < 2 || !is_reliable(model, i, min_valid_ratio)) continue;
    const double mean_m = model.mean_m[i];
    ratios.push_back(static_cast<float>(model.spread_m[i] / (mean_m * mean_m * median_spread_per_sigma(samples))));
  }
  if (ratios.empty()) return 0.0;
  const auto middle = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
  std::nth_element(ratios.begin(), middle, ratios.end());
  return *middle;
}

/// Marks (1) the reliable pixels whose spread exceeds max(k · noise_per_z2 · mean², min_spread_m)
/// and returns how many pixels are reliable.
size_t mark_moving(const BackgroundModel& model, const BackgroundParams& params, double noise_per_z2,
                   uint8_t* moving) {
  const size_t n = model.mean_m.size();
  const double k_noise = params.moving_k_sigma * noise_per_z2;
  size_t reliable = 0;
  for (size_t i = 0; i < n; ++i) {
    moving[i] = 0;
    if (!is_reliable(model, i, params.min_valid_ratio)) continue;
    ++reliable;
    const double mean_m = model.mean_m[i];
    const double limit_m = std::max(k_noise * mean_m * mean_m, static_cast<double>(params.moving_min_spread_m));
    moving[i] = model.spread_m[i] > limit_m ? 1 : 0;
  }
  return reliable;
}

/// Marks in `wide` the moving pixels whose whole width_px × width_px square (clipped to the
/// image, so that motion at the border counts) moved too: a binary erosion, separable into a
/// row and a column pass.
void erode_motion(const uint8_t* moving, int width, int height, int width_px, uint8_t* rows_ok, uint8_t* wide) {
  const int r = std::max(width_px, 1) / 2;
  for (int v = 0; v < height; ++v) {
    const uint8_t* row = moving + static_cast<size_t>(v) * width;
    for (int u = 0; u < width; ++u) {
      uint8_t all = 1;
      for (int k = std::max(u - r, 0); k <= std::min(u + r, width - 1); ++k) all &= row[k];
      rows_ok[static_cast<size_t>(v) * width + u] = all;
    }
  }
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      uint8_t all = 1;
      for (int k = std::max(v - r, 0); k <= std::min(v + r, height - 1); ++k) {
        all &= rows_ok[static_cast<size_t>(k) * width + u];
      }
      wide[static_cast<size_t>(v) * width + u] = all;
    }
  }
}

/// A few frames cannot measure one pixel's noise (three samples of a quantising camera are
/// often equal): raise each reliable pixel's spread to the batch's noise at its depth.
void apply_noise_floor(BackgroundModel& model, double noise_per_z2, float min_valid_ratio) {
  for (size_t i = 0; i < model.mean_m.size(); ++i) {
    if (!is_reliable(model, i, min_valid_ratio)) continue;
    const double mean_m = model.mean_m[i];
    model.spread_m[i] = std::max(model.spread_m[i], static_cast<float>(noise_per_z2 * mean_m * mean_m));
  }
}

/// Gives every unreliable pixel the background of the reliable pixels closest to it in the image:
/// a breadth-first search from the reliable pixels over 8-neighbours, in which a pixel at
/// distance k takes the smallest mean (with its spread) among its neighbours at distance k − 1,
/// up to `radius_px`; farther pixels stay unknown (0). Closest in the image, so that a slanted
/// surface or an object a few pixels away does not lend its depth; the smallest mean among
/// equally close ones, so that a pixel in a thin invalid band at a depth edge (where a camera
/// rarely measures) is foreground only when nearer than both sides. Its own samples are not
/// used: a single valid reading may be a person passing or a glint. Pixels flickering at a depth
/// edge (`flicker`) are filled the same way. With `keep_unseen`, pixels never valid stay unknown
/// and the search does not cross them.
void fill_unreliable(BackgroundModel& model, float min_valid_ratio, int radius_px, bool keep_unseen,
                     const uint8_t* flicker, std::vector<int32_t>& queue, std::vector<uint16_t>& layer) {
  const int width = model.width;
  const int height = model.height;
  const size_t n = model.mean_m.size();
  constexpr uint16_t kUnset = 0xFFFF;
  constexpr uint16_t kUnseen = 0xFFFE;  // never assigned, never crossed
  const int radius = std::clamp(radius_px, 0, kUnseen - 1);
  size_t tail = 0;
  for (size_t i = 0; i < n; ++i) {
    const bool unseen = keep_unseen && model.valid_ratio[i] == 0.0F;
    const bool own = is_reliable(model, i, min_valid_ratio) && flicker[i] == 0;
    layer[i] = own ? 0 : unseen ? kUnseen : kUnset;
    if (layer[i] == 0) continue;
    model.mean_m[i] = 0.0F;
    model.spread_m[i] = 0.0F;
  }
  // Layer 0: the reliable pixels next to an unreliable one.
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      if (layer[i] != 0) continue;
      bool border = false;
      for (int nv = std::max(v - 1, 0); nv <= std::min(v + 1, height - 1) && !border; ++nv) {
        for (int nu = std::max(u - 1, 0); nu <= std::min(u + 1, width - 1); ++nu) {
          border = border || layer[static_cast<size_t>(nv) * width + nu] == kUnset;
        }
      }
      if (border) queue[tail++] = static_cast<int32_t>(i);
    }
  }
  // Layer k occupies queue[begin, end); its pixels' means are final before layer k + 1 reads them.
  size_t begin = 0;
  for (int k = 1; k <= radius && begin < tail; ++k) {
    const size_t end = tail;
    for (size_t q = begin; q < end; ++q) {
      const size_t i = static_cast<size_t>(queue[q]);
      const int u = static_cast<int>(i % static_cast<size_t>(width));
      const int v = static_cast<int>(i / static_cast<size_t>(width));
      for (int nv = std::max(v - 1, 0); nv <= std::min(v + 1, height - 1); ++nv) {
        for (int nu = std::max(u - 1, 0); nu <= std::min(u + 1, width - 1); ++nu) {
          const size_t j = static_cast<size_t>(nv) * width + nu;
          if (layer[j] == kUnset) {
            layer[j] = static_cast<uint16_t>(k);
            queue[tail++] = static_cast<int32_t>(j);
          } else if (layer[j] != k || model.mean_m[i] >= model.mean_m[j]) {
            continue;
          }
          model.mean_m[j] = model.mean_m[i];
          model.spread_m[j] = model.spread_m[i];
        }
      }
    }
    begin = end;
  }
}

}  // namespace

namespace {

using segmentation_detail::distance_to_capsules;

// The nearer of two raw samples, 0 ("no sample") losing to any valid one.
uint16_t nearer_sample(uint16_t a, uint16_t b) {
  const uint16_t a_key = static_cast<uint16_t>(a - 1U);  // 0 wraps to 65535, the farthest
  const uint16_t b_key = static_cast<uint16_t>(b - 1U);
  return static_cast<uint16_t>((a_key < b_key ? a_key : b_key) + 1U);
}

// Clears the moving pixels whose batch mean lies outside `region` (farther than
// max_distance_m from the robot, or outside the workspace) and marks them in `outside`.
// Returns how many were cleared. A pixel that cannot be placed (no mean, a failed
// deprojection) stays moving: only motion known to be far away is forgiven.
size_t keep_motion_near_robot(const BackgroundModel& model, const Intrinsics& intrinsics, const MotionRegion& region,
                              float max_distance_m, const uint16_t* nearest_raw, float depth_scale_m,
                              const uint8_t* flicker, uint8_t* moving, uint8_t* outside) {
  size_t cleared = 0;
  const size_t n = model.mean_m.size();
  const Eigen::Matrix3f R = region.T_base_camera.linear().cast<float>();
  const Eigen::Vector3f t = region.T_base_camera.translation().cast<float>();
  // Near when the pixel's mean or its nearest sample is near: a person crossing a pixel in a
  // few frames barely moves its mean, which stays at the wall behind them.
  const auto near_at = [&](const Eigen::Vector2f& pixel, float z_m) {
    const std::optional<Eigen::Vector3f> p_camera = deproject(intrinsics, pixel, z_m);
    if (!p_camera) return true;  // cannot be placed: not known to be far
    const Eigen::Vector3f p_base = R * *p_camera + t;
    return region.workspace_base.contains(p_base) && distance_to_capsules(*region.robot, p_base) <= max_distance_m;
  };
  for (size_t i = 0; i < n; ++i) {
    outside[i] = 0;
    // Flicker is no motion: it keeps its (filled) background wherever it is.
    if (moving[i] == 0 || flicker[i] != 0 || !(model.mean_m[i] > 0.0F)) continue;
    const Eigen::Vector2f pixel(static_cast<float>(i % static_cast<size_t>(model.width)),
                                static_cast<float>(i / static_cast<size_t>(model.width)));
    if (near_at(pixel, model.mean_m[i])) continue;
    if (nearest_raw[i] != 0 && near_at(pixel, static_cast<float>(nearest_raw[i]) * depth_scale_m)) continue;
    moving[i] = 0;
    outside[i] = 1;
    ++cleared;
  }
  return cleared;
}

}  // namespace

BackgroundLearner::Status BackgroundLearner::add(const Frame& frame, const MotionRegion* region,
                                                 const RobotPixels* robot) {
  if (ready_) return Status::ready;
  const Status status = start_batch(frame.depth.width, frame.depth.height);
  accumulate(frame.depth, robot);
  ++count_;
  if (count_ < std::max(params.frames, 1)) return status;
  return finish_batch(frame, region);
}

// Sizes the buffers for a new image size (the only allocations: the first frame of a size) or
// zeroes the sums for a new batch of the same size.
BackgroundLearner::Status BackgroundLearner::start_batch(int width, int height) {
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  Status status = Status::learning;
  if (width != model_.width || height != model_.height) {
    // A batch in progress mixes two geometries: it cannot be finished, start over.
    if (count_ > 0) {
      message_ = size_changed_message(model_.width, model_.height, width, height);
      status = Status::restarted;
    }
    sum_.assign(n, 0.0);
    sum_sq_.assign(n, 0.0);
    valid_count_.assign(n, 0U);
    nearest_raw_.assign(n, 0);
    farthest_raw_.assign(n, 0);
    model_.width = width;
    model_.height = height;
    model_.mean_m.assign(n, 0.0F);
    model_.spread_m.assign(n, 0.0F);
    model_.valid_ratio.assign(n, 0.0F);
    ratios_.clear();
    ratios_.reserve(n);
    moving_.assign(n, 0);
    eroded_.assign(n, 0);
    wide_.assign(n, 0);
    outside_.assign(n, 0);
    flicker_.assign(n, 0);
    seen_.assign(n, 0);
    fill_queue_.assign(n, 0);
    fill_layer_.assign(n, 0);
    count_ = 0;
  } else if (count_ == 0) {
    std::fill(sum_.begin(), sum_.end(), 0.0);
    std::fill(sum_sq_.begin(), sum_sq_.end(), 0.0);
    std::fill(valid_count_.begin(), valid_count_.end(), 0U);
    std::fill(nearest_raw_.begin(), nearest_raw_.end(), uint16_t{0});
    std::fill(farthest_raw_.begin(), farthest_raw_.end(), uint16_t{0});
  }
  return status;
}

// Adds one frame's raw samples to the batch's sums. Raw units are integers, so the sums stay
// exact in double (65535² · 2^20 < 2^53). The robot's own pixels are no samples, as if invalid.
void BackgroundLearner::accumulate(const DepthImage& depth, const RobotPixels* robot) {
  const size_t n = static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height);
  const uint16_t* raw = depth.pixels.data();
  for (size_t i = 0; i < n; ++i) {
    const uint16_t sample = robot != nullptr && robot->contains(i, raw[i]) ? uint16_t{0} : raw[i];
    const double r = sample;
    sum_[i] += r;
    sum_sq_[i] += r * r;
    valid_count_[i] += sample != 0 ? 1U : 0U;
    nearest_raw_[i] = nearer_sample(nearest_raw_[i], sample);
    farthest_raw_[i] = std::max(farthest_raw_[i], sample);
  }
}

// Turns the completed batch into the model: statistics, noise, then motion, which restarts
// learning when it covers too much; otherwise the model is finished and ready.
BackgroundLearner::Status BackgroundLearner::finish_batch(const Frame& frame, const MotionRegion* region) {
  const DepthImage& depth = frame.depth;
  const size_t n = static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height);
  const BatchSums sums{sum_.data(), sum_sq_.data(), valid_count_.data(), n, count_};
  const int batch_frames = count_;
  count_ = 0;
  write_statistics(sums, depth.depth_scale_m, model_);
  const BatchView batch{model_, nearest_raw_.data(), farthest_raw_.data(), depth.depth_scale_m, params.min_valid_ratio};
  // σ_noise(z) = noise_per_z2 · z²: the stereo model with a baseline, else learnt.
  const bool have_model = frame.stereo_baseline_mm > 0.0F && frame.intrinsics.fx > 0.0F;
  const double cap = params.max_noise_per_z2;
  noise_per_z2_ = have_model
                      ? stereo_depth_sigma_m(1.0, frame.intrinsics.fx, frame.stereo_baseline_mm, params.subpixel_rms_px)
                      : std::min(learnt_noise_per_z2(sums, model_, params.min_valid_ratio, ratios_), cap);
  size_t reliable = find_motion(batch, frame.intrinsics, region);
  if (!have_model) {
    // The median misses a quantising camera's steps (few frames of most pixels read one value):
    // the noise pooled over the pixels that stayed still includes them. Judged again with it.
    const double pooled = std::min(pooled_noise_per_z2(batch, valid_count_.data(), moving_.data(), flicker_.data()), cap);
    if (pooled > noise_per_z2_) {
      noise_per_z2_ = pooled;
      reliable = find_motion(batch, frame.intrinsics, region);
    }
  }
  mark_wide_motion();
  const ObjectMotion motion =
      object_motion(batch, moving_.data(), wide_.data(), frame.intrinsics.fx, min_object_mm, fill_queue_, seen_);
  const double moving_share = reliable == 0 ? 0.0 : static_cast<double>(motion.counted) / static_cast<double>(reliable);
  if (moving_share > static_cast<double>(params.max_moving_share)) {
    message_ = motion_message(moving_share, batch_frames, params.max_moving_share, describe_blob(motion.largest));
    unsettled_ = 0;  // counts the batch that was learnt
    return Status::restarted;
  }
  settle_model(batch, batch_frames, have_model);
  ready_ = true;
  return Status::ready;
}

// Marks wide_ (motion wider than motion_min_width_px) and clears edge flicker from both masks.
// Wide motion is judged before flicker leaves it: flicker in the middle of a wider band of
// change (someone swaying) must not make the band thin.
void BackgroundLearner::mark_wide_motion() {
  erode_motion(moving_.data(), model_.width, model_.height, params.motion_min_width_px, eroded_.data(), wide_.data());
  for (size_t i = 0; i < moving_.size(); ++i) {
    if (flicker_[i] == 0) continue;
    moving_[i] = 0;
    wide_[i] = 0;
  }
}

// Finishes a still batch's model: the noise floor, the background of unreliable and flickering
// pixels, and no background where motion far from the robot never settled.
void BackgroundLearner::settle_model(const BatchView& batch, int batch_frames, bool have_model) {
  // With a baseline the foreground test adds the stereo model itself.
  if (!have_model) apply_noise_floor(model_, noise_per_z2_, params.min_valid_ratio);
  const bool keep_unseen = batch_frames >= params.unseen_min_frames;
  fill_unreliable(model_, params.min_valid_ratio, params.fill_radius_px, keep_unseen, flicker_.data(), fill_queue_,
                  fill_layer_);
  cover_flicker(batch);
  // What moved far from the robot never settled: its background is unknown, not its mean.
  if (unsettled_ > 0) {
    for (size_t i = 0; i < model_.mean_m.size(); ++i) {
      if (outside_[i] == 0) continue;
      model_.mean_m[i] = 0.0F;
      model_.spread_m[i] = 0.0F;
    }
  }
}

size_t BackgroundLearner::find_motion(const BatchView& batch, const Intrinsics& intrinsics, const MotionRegion* region) {
  const double k_noise = params.moving_k_sigma * noise_per_z2_;
  const size_t reliable = mark_moving(model_, params, noise_per_z2_, moving_.data());
  flickering_ = mark_edge_flicker(batch, k_noise, params.moving_min_spread_m, kFlickerRadiusPx, moving_.data(),
                                  flicker_.data());
  const bool gated = region != nullptr && region->robot != nullptr && !region->robot->capsules.empty();
  unsettled_ = gated ? keep_motion_near_robot(model_, intrinsics, *region, params.motion_max_distance_m,
                                              nearest_raw_.data(), batch.depth_scale_m, flicker_.data(), moving_.data(),
                                              outside_.data())
                     : 0;
  if (!gated) std::fill(outside_.begin(), outside_.end(), uint8_t{0});
  return reliable;
}

// A flickering pixel's background is its nearer side (the fill takes the closest side, which
// may be the farther one; its own nearest sample is that side, clear_edge_flicker checked), so
// that a near-side reading is no foreground; its band reaches the farther side too, so that
// neither side's reading is taken for a change of the scene (a loaded background's check
// counts pixels measured farther than mean + k · spread).
void BackgroundLearner::cover_flicker(const BatchView& batch) {
  const double scale = batch.depth_scale_m;
  for (size_t i = 0; i < model_.mean_m.size(); ++i) {
    if (flicker_[i] == 0) continue;
    const float near_m = static_cast<float>(batch.nearest_raw[i] * scale);
    const float far_m = static_cast<float>(batch.farthest_raw[i] * scale);
    float& mean_m = model_.mean_m[i];
    mean_m = mean_m > 0.0F ? std::min(mean_m, near_m) : near_m;
    model_.spread_m[i] = std::max(model_.spread_m[i], (far_m - mean_m) / kFlickerCoverSigmas);
  }
}

void BackgroundLearner::refuse(const std::string& why) {
  // The batch's sums were already used up (count_ is 0 after a batch); the model keeps its
  // buffers, so that learning on does not allocate.
  ready_ = false;
  count_ = 0;
  unsettled_ = 0;
  message_ = why;
}

int BackgroundCheck::add(const BackgroundModel& model, const DepthImage& depth) {
  const size_t n = model.mean_m.size();
  if (depth.pixels.size() != n) return ++seen_;  // the pipeline refuses a size mismatch itself
  const float scale = depth.depth_scale_m;
  for (size_t i = 0; i < n; ++i) {
    const uint16_t raw = depth.pixels[i];
    const float mean = model.mean_m[i];
    if (raw == 0 || !(mean > 0.0F) || !(model.valid_ratio[i] >= min_valid_ratio)) continue;
    const float z = static_cast<float>(raw) * scale;
    const float margin = std::max(k_sigma * model.spread_m[i], min_margin_m);
    ++compared_;
    // NaN in a damaged model fails ">" and so is never a reason to trust it: count it as farther.
    if (!(z - mean <= margin)) ++farther_;
  }
  return ++seen_;
}

}  // namespace hrcsense
