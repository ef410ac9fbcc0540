// SPDX-License-Identifier: Apache-2.0
// hrcsense — what a calibration sweep showed: the farthest depth per grid sample and the
// keyframes, and each keyframe's arm candidates (calibration.hpp).
#include "hrcsense/calibration.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace hrcsense {
namespace {

// The pixel of grid sample (gx, gy): the middle of its cell.
int grid_pixel(int g, int step) { return g * step + step / 2; }

// Where the arm is, as few points as say it: every link frame's origin (the flange included).
void link_origins(const RobotDescription& arm, const JointAngles& q_rad, std::vector<Eigen::Vector3d>& out) {
  const LinkFrames frames = forward_kinematics(arm, q_rad);
  out.clear();
  for (const Pose& T : frames.T_base_link) out.push_back(T.translation());
}

// The mean and the median of the valid raw depths of the 5×5 pixels about (u, v), and which
// pixel holds the median; all 0 when fewer than half are valid. The mean is the background's
// statistic (its noise a fifth of a pixel's). The median pixel is the point: its depth is as
// quiet as the mean's, it shows what most of the patch shows (at the arm's silhouette a mean
// mixes the arm with what lies behind it), and it is a real pixel with its own ray, so a patch
// on the arm's curved edge gives a point on the surface, not the sample's ray at another
// pixel's depth (1.8 mm and 0.05 degrees of bias on a noise-free sweep).
struct PatchDepth {
  uint16_t mean = 0;
  uint16_t median = 0;
  uint8_t median_at = 0;  ///< the median pixel: (du + 2) + 5 (dv + 2)
};
constexpr int kPatchHalf = 2;
constexpr int kPatchSide = 2 * kPatchHalf + 1;

// The patch's valid depths, each as depth << 8 | its pixel in the patch; returns how many, and
// the count of the patch's pixels inside the image in `inside` and their sum in `sum`.
size_t patch_values(const DepthImage& depth, int u, int v, std::array<uint32_t, kPatchSide * kPatchSide>& values,
                    int& inside, uint32_t& sum) {
  size_t n = 0;
  inside = 0;
  sum = 0;
  for (int dv = -kPatchHalf; dv <= kPatchHalf; ++dv) {
    const int y = v + dv;
    if (y < 0 || y >= depth.height) continue;
    for (int du = -kPatchHalf; du <= kPatchHalf; ++du) {
      const int x = u + du;
      if (x < 0 || x >= depth.width) continue;
      ++inside;
      const uint16_t d = depth.at(x, y);
      if (d == 0) continue;
      values[n++] = static_cast<uint32_t>(d) << 8 |
                    static_cast<uint32_t>((du + kPatchHalf) + kPatchSide * (dv + kPatchHalf));
      sum += d;
    }
  }
  return n;
}

// The mean always (the background's statistic); the median and its pixel only when `median`
// (a keyframe's): the selection is most of a frame's cost.
PatchDepth patch_depth(const DepthImage& depth, int u, int v, bool median) {
  std::array<uint32_t, kPatchSide * kPatchSide> values{};
  int inside = 0;
  uint32_t sum = 0;
  const size_t n = patch_values(depth, u, v, values, inside, sum);
  PatchDepth out;
  if (n == 0 || 2 * static_cast<int>(n) < inside) return out;
  out.mean = static_cast<uint16_t>((sum + static_cast<uint32_t>(n) / 2) / static_cast<uint32_t>(n));
  if (!median) return out;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(values.begin(), middle, values.begin() + static_cast<std::ptrdiff_t>(n));
  out.median = static_cast<uint16_t>(*middle >> 8);
  out.median_at = static_cast<uint8_t>(*middle & 0xFFU);
  return out;
}

}  // namespace

ArmSamples::ArmSamples(const CalibrationParams& params, const Intrinsics& intrinsics, const RobotDescription& arm,
                       BaseFrame base_frame)
    : params_(params), intrinsics_(intrinsics), arm_(arm), base_frame_(base_frame) {
  const int step = std::max(1, params_.grid_px);
  params_.grid_px = step;
  grid_width_ = (intrinsics.width + step - 1) / step;
  grid_height_ = (intrinsics.height + step - 1) / step;
  // The last cell's middle may fall off a size that is not a multiple of the step.
  if (grid_width_ > 0 && grid_pixel(grid_width_ - 1, step) >= intrinsics.width) --grid_width_;
  if (grid_height_ > 0 && grid_pixel(grid_height_ - 1, step) >= intrinsics.height) --grid_height_;
  farthest_.assign(static_cast<size_t>(std::max(0, grid_width_ * grid_height_)), 0);
}

bool ArmSamples::add(int64_t frame_index, const DepthImage& depth, const JointAngles& q_rad, float stereo_baseline_mm) {
  if (depth.width != intrinsics_.width || depth.height != intrinsics_.height) {
    throw std::invalid_argument("calibration: frame " + std::to_string(frame_index) + " is " +
                                std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                                ", the source said " + std::to_string(intrinsics_.width) + "x" +
                                std::to_string(intrinsics_.height));
  }
  ++frames_;
  depth_scale_m_ = depth.depth_scale_m;
  baseline_mm_ = stereo_baseline_mm > 0.0F ? stereo_baseline_mm : kD435BaselineMm;
  // A keyframe when some link origin or the flange moved far enough since the last one.
  std::vector<Eigen::Vector3d> origins;
  link_origins(arm_, q_rad, origins);
  double moved_m = keyframes_.empty() ? params_.keyframe_motion_m : 0.0;
  for (size_t i = 0; i < origins.size() && i < last_key_origins_base_.size(); ++i) {
    moved_m = std::max(moved_m, (origins[i] - last_key_origins_base_[i]).norm());
  }
  const bool keyframe = moved_m >= params_.keyframe_motion_m;
  const int step = params_.grid_px;
  std::vector<uint16_t> grid(keyframe ? farthest_.size() : 0);
  std::vector<uint8_t> grid_at(keyframe ? farthest_.size() : 0);
  for (int gy = 0; gy < grid_height_; ++gy) {
    for (int gx = 0; gx < grid_width_; ++gx) {
      const size_t i = static_cast<size_t>(gy) * static_cast<size_t>(grid_width_) + static_cast<size_t>(gx);
      const PatchDepth patch = patch_depth(depth, grid_pixel(gx, step), grid_pixel(gy, step), keyframe);
      if (keyframe) {
        grid[i] = patch.median;
        grid_at[i] = patch.median_at;
      }
      if (patch.mean > farthest_[i]) {
        if (farthest_[i] != 0 && patch.mean - farthest_[i] > margin_raw(farthest_[i])) ++background_changes_;
        farthest_[i] = patch.mean;
      }
    }
  }
  if (!keyframe) return false;
  last_key_origins_base_ = origins;
  if (static_cast<int>(keyframes_.size()) >= std::max(2, params_.max_keyframes)) {
    // Full: every second keyframe goes, so that those kept still span the whole sweep.
    size_t kept = 0;
    for (size_t i = 0; i < keyframes_.size(); i += 2) keyframes_[kept++] = std::move(keyframes_[i]);
    keyframes_.resize(kept);
  }
  keyframes_.push_back(ArmKeyframe{frame_index, q_rad, std::move(grid), std::move(grid_at)});
  return true;
}

int ArmSamples::noise_raw(uint16_t depth_raw, double sigmas) const {
  const double z_m = static_cast<double>(depth_raw) * static_cast<double>(depth_scale_m_);
  const double sigma_m = stereo_depth_sigma_m(z_m, intrinsics_.fx, baseline_mm_, kD435SubpixelRmsPx);
  return static_cast<int>(sigmas * sigma_m / static_cast<double>(depth_scale_m_));
}

int ArmSamples::margin_raw(uint16_t farthest_raw) const {
  // A 5×5 mean's or median's noise is about a fifth of one pixel's (independent pixels): 6 σ of
  // it. A test of a single noisy pixel against a margin would keep the arm's pixels that noise
  // brought nearer and drop those it took farther: a bias towards the camera.
  const auto floor_raw = static_cast<int>(params_.candidate_margin_m / depth_scale_m_);
  return std::max(floor_raw, noise_raw(farthest_raw, 6.0 / 5.0));
}

int64_t ArmSamples::take_background_changes() {
  const int64_t changes = background_changes_;
  background_changes_ = 0;
  return changes;
}

std::vector<Eigen::Vector3f> arm_candidates(const ArmSamples& samples, const ArmKeyframe& keyframe) {
  std::vector<Eigen::Vector3f> points_camera;
  const float scale = samples.depth_scale_m();
  const int step = samples.params().grid_px;
  const std::vector<uint16_t>& farthest = samples.farthest();
  for (int gy = 0; gy < samples.grid_height(); ++gy) {
    for (int gx = 0; gx < samples.grid_width(); ++gx) {
      const size_t i = static_cast<size_t>(gy) * static_cast<size_t>(samples.grid_width()) + static_cast<size_t>(gx);
      // Most of the patch must stand off the background (its median does): beside the arm's
      // silhouette a patch that is mostly background is not taken for the arm.
      const uint16_t d = keyframe.depth_grid[i];
      if (d == 0 || farthest[i] - d <= samples.margin_raw(farthest[i])) continue;
      const int at = keyframe.median_at[i];
      const Eigen::Vector2f pixel(static_cast<float>(grid_pixel(gx, step) + at % 5 - 2),
                                  static_cast<float>(grid_pixel(gy, step) + at / 5 - 2));
      if (const auto p = deproject(samples.intrinsics(), pixel, static_cast<float>(d) * scale)) {
        points_camera.push_back(*p);
      }
    }
  }
  return points_camera;
}

float distance_to_shapes(const std::vector<Capsule>& shapes, const Eigen::Vector3f& point_base,
                         Eigen::Vector3f& normal_base) {
  float best = std::numeric_limits<float>::infinity();
  for (const Capsule& c : shapes) {
    const Eigen::Vector3f e = c.b - c.a;
    const float ee = e.squaredNorm();
    const float t = ee > 0.0F ? std::clamp((point_base - c.a).dot(e) / ee, 0.0F, 1.0F) : 0.0F;
    const Eigen::Vector3f off = point_base - (c.a + t * e);
    const float norm = off.norm();
    const float d = norm - c.radius_m;
    if (d < best) {
      best = d;
      normal_base = norm > 1e-9F ? Eigen::Vector3f(off / norm) : Eigen::Vector3f::UnitZ();
    }
  }
  return best;
}

}  // namespace hrcsense
