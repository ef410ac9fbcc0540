// SPDX-License-Identifier: Apache-2.0
// hrcsense — background learning: per-pixel mean, spread and valid ratio over a still batch.

#include "hrcsense/camera.hpp"
#include "hrcsense/segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hrcsense {
namespace {

// A pixel valid in only part of the batch with a usable mean had something come and go.
constexpr double kFlickerMinRatio = 0.2;
constexpr double kFlickerMaxRatio = 0.8;

std::string size_changed_message(int old_w, int old_h, int new_w, int new_h) {
  char text[160];
  std::snprintf(text, sizeof text,
                "background learning restarted: the depth image size changed from %dx%d to %dx%d",
                old_w, old_h, new_w, new_h);
  return text;
}

std::string motion_message(double moving_share, int frames, double limit_share) {
  char text[240];
  std::snprintf(text, sizeof text,
                "background learning restarted: %.1f %% of pixels changed during the last %d frames "
                "(limit %.1f %%); is something moving in the cell?",
                100.0 * moving_share, frames, 100.0 * limit_share);
  return text;
}

/// The running sums of one learning batch, in raw depth units.
struct BatchSums {
  const double* sum;
  const double* sum_sq;
  const uint32_t* valid_count;
  size_t pixels;
  int frames;
};

/// Writes mean, spread and valid ratio of a complete batch into `model` and returns the share
/// of valid pixels that moved during it (0..1).
double summarise_batch(const BatchSums& sums, const Frame& frame, const BackgroundParams& params,
                       BackgroundModel& model) {
  const size_t n = sums.pixels;
  const double scale_m = frame.depth.depth_scale_m;
  const double frames = sums.frames;
  // σ_model(z) = z² · c; without a baseline there is no noise model, only the absolute floor.
  const bool have_model = frame.stereo_baseline_mm > 0.0F && frame.intrinsics.fx > 0.0F;
  const double c = have_model ? stereo_depth_sigma_m(1.0, frame.intrinsics.fx, frame.stereo_baseline_mm,
                                                     params.subpixel_rms_px)
                              : 0.0;
  const double k_sigma = params.moving_k_sigma;
  const double min_spread_m = params.moving_min_spread_m;

  size_t valid_pixels = 0;
  size_t moving_pixels = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint32_t valid = sums.valid_count[i];
    if (valid == 0) {
      model.mean_m[i] = 0.0F;
      model.spread_m[i] = 0.0F;
      model.valid_ratio[i] = 0.0F;
      continue;
    }
    const double mean_raw = sums.sum[i] / valid;
    const double variance_raw = std::max(0.0, sums.sum_sq[i] / valid - mean_raw * mean_raw);
    const double mean_m = mean_raw * scale_m;
    const double spread_m = std::sqrt(variance_raw) * scale_m;
    const double ratio = valid / frames;
    model.mean_m[i] = static_cast<float>(mean_m);
    model.spread_m[i] = static_cast<float>(spread_m);
    model.valid_ratio[i] = static_cast<float>(ratio);

    const double limit_m = std::max(k_sigma * c * mean_m * mean_m, min_spread_m);
    const bool came_and_went = ratio >= kFlickerMinRatio && ratio <= kFlickerMaxRatio;
    ++valid_pixels;
    moving_pixels += (spread_m > limit_m || came_and_went) ? 1U : 0U;
  }
  return valid_pixels == 0 ? 0.0 : static_cast<double>(moving_pixels) / static_cast<double>(valid_pixels);
}

}  // namespace

BackgroundLearner::Status BackgroundLearner::add(const Frame& frame) {
  if (ready_) return Status::ready;
  const DepthImage& depth = frame.depth;
  const size_t n = static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height);
  Status status = Status::learning;

  const bool new_size = depth.width != model_.width || depth.height != model_.height;
  if (new_size) {
    // A batch in progress mixes two geometries: it cannot be finished, start over.
    if (count_ > 0) {
      message_ = size_changed_message(model_.width, model_.height, depth.width, depth.height);
      status = Status::restarted;
    }
    // The only allocation: the first frame of a size.
    sum_.assign(n, 0.0);
    sum_sq_.assign(n, 0.0);
    valid_count_.assign(n, 0U);
    model_.width = depth.width;
    model_.height = depth.height;
    model_.mean_m.assign(n, 0.0F);
    model_.spread_m.assign(n, 0.0F);
    model_.valid_ratio.assign(n, 0.0F);
    count_ = 0;
  } else if (count_ == 0) {
    std::fill(sum_.begin(), sum_.end(), 0.0);
    std::fill(sum_sq_.begin(), sum_sq_.end(), 0.0);
    std::fill(valid_count_.begin(), valid_count_.end(), 0U);
  }

  // Raw units are integers, so the sums stay exact in double (65535² · 2^20 < 2^53).
  const uint16_t* raw = depth.pixels.data();
  for (size_t i = 0; i < n; ++i) {
    const double r = raw[i];
    sum_[i] += r;
    sum_sq_[i] += r * r;
    valid_count_[i] += raw[i] != 0 ? 1U : 0U;
  }
  ++count_;
  if (count_ < std::max(params.frames, 1)) return status;

  const BatchSums sums{sum_.data(), sum_sq_.data(), valid_count_.data(), n, count_};
  const double moving_share = summarise_batch(sums, frame, params, model_);
  const int batch_frames = count_;
  count_ = 0;
  if (moving_share > static_cast<double>(params.max_moving_share)) {
    message_ = motion_message(moving_share, batch_frames, params.max_moving_share);
    return Status::restarted;
  }
  ready_ = true;
  return Status::ready;
}

}  // namespace hrcsense
