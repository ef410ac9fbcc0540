// SPDX-License-Identifier: Apache-2.0
// hrcsense — the learnt background against a reference taught with the cell empty: whoever
// stood still while the background was learnt is nearer than the reference there.
//
// Why the foreground test itself: the learnt background is turned into a depth frame and run
// through a ForegroundExtractor prepared against the reference, so "nearer" means exactly what
// it means for a person in a running cell (the margin max(k·spread, k·σ_model(z), min_margin_m),
// blobs split at depth jumps), and a blob is as large as the speckle rule would measure it.

#include "hrcsense/segmentation.hpp"

#include "capsule_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hrcsense {
namespace {

using segmentation_detail::distance_to_capsules;

// The learnt background's means as raw depth; unknown (0, NaN) stays 0, "no data".
void background_as_frame(const BackgroundModel& learnt, const Frame& like, Frame& out) {
  out.index = like.index;
  out.timestamp_ns = like.timestamp_ns;
  out.intrinsics = like.intrinsics;
  out.stereo_baseline_mm = like.stereo_baseline_mm;
  out.depth.depth_scale_m = like.depth.depth_scale_m;
  out.depth.resize(learnt.width, learnt.height);
  const float per_raw = 1.0F / like.depth.depth_scale_m;
  for (size_t i = 0; i < learnt.mean_m.size(); ++i) {
    const float raw = learnt.mean_m[i] * per_raw;
    out.depth.pixels[i] = raw > 0.5F ? static_cast<uint16_t>(std::min(raw + 0.5F, 65535.0F)) : uint16_t{0};
  }
}

// One 8-connected blob of `mask` == 1 around `seed`, marked 2 as it is visited.
struct BlobSummary {
  size_t pixels = 0;
  double raw_sum = 0.0;
  int u_min = 0, u_max = 0, v_min = 0, v_max = 0;
  float distance_m = std::numeric_limits<float>::infinity();
};

BlobSummary label_blob(std::vector<uint8_t>& mask, const DepthImage& depth, const std::vector<float>& distance_m,
                       size_t seed, std::vector<int32_t>& queue) {
  const int width = depth.width;
  const int height = depth.height;
  BlobSummary blob;
  blob.u_min = blob.u_max = static_cast<int>(seed % static_cast<size_t>(width));
  blob.v_min = blob.v_max = static_cast<int>(seed / static_cast<size_t>(width));
  size_t tail = 0;
  queue[tail++] = static_cast<int32_t>(seed);
  mask[seed] = 2;
  for (size_t head = 0; head < tail; ++head) {
    const size_t i = static_cast<size_t>(queue[head]);
    const int u = static_cast<int>(i % static_cast<size_t>(width));
    const int v = static_cast<int>(i / static_cast<size_t>(width));
    ++blob.pixels;
    blob.raw_sum += depth.pixels[i];
    blob.u_min = std::min(blob.u_min, u);
    blob.u_max = std::max(blob.u_max, u);
    blob.v_min = std::min(blob.v_min, v);
    blob.v_max = std::max(blob.v_max, v);
    // NaN (no distance known) never lowers the minimum; the caller handles "no robot".
    if (distance_m[i] < blob.distance_m) blob.distance_m = distance_m[i];
    for (int nv = std::max(v - 1, 0); nv <= std::min(v + 1, height - 1); ++nv) {
      for (int nu = std::max(u - 1, 0); nu <= std::min(u + 1, width - 1); ++nu) {
        const size_t j = static_cast<size_t>(nv) * static_cast<size_t>(width) + static_cast<size_t>(nu);
        if (mask[j] != 1) continue;
        mask[j] = 2;
        queue[tail++] = static_cast<int32_t>(j);
      }
    }
  }
  return blob;
}

}  // namespace

void ReferenceCheck::set_reference(BackgroundModel reference) {
  reference_ = std::move(reference);
  has_reference_ = true;
  extractor_.clear_background();  // its tables belong to the previous reference
}

ReferenceFinding ReferenceCheck::compare(const BackgroundModel& learnt, const Frame& frame, const Pose& T_base_camera,
                                         const RobotModel& robot_poses, const RobotPixels* robot) {
  ReferenceFinding finding;
  const size_t n = reference_.mean_m.size();
  if (!has_reference_ || learnt.width != reference_.width || learnt.height != reference_.height ||
      learnt.mean_m.size() != n || frame.depth.width != reference_.width || frame.depth.height != reference_.height) {
    return finding;
  }
  background_as_frame(learnt, frame, learnt_frame_);
  // The foreground test with blobs kept from the detection size up, and no workspace: where the
  // reference is unknown nothing is compared (an empty box contains no point).
  ForegroundParams params = foreground;
  params.min_object_mm = detection_mm;
  params.workspace_base.min = Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity());
  params.workspace_base.max = Eigen::Vector3f::Constant(-std::numeric_limits<float>::infinity());
  extractor_.params = params;
  if (!extractor_.prepared_for(learnt_frame_)) {
    extractor_.set_background(reference_, learnt_frame_.intrinsics.fx, learnt_frame_.stereo_baseline_mm,
                              learnt_frame_.depth.depth_scale_m);
  }
  if (!extractor_.extract(learnt_frame_, T_base_camera, nearer_, robot)) return finding;

  // Each nearer pixel's distance to the robot over every pose given; NaN without a pose.
  const bool have_robot = !robot_poses.capsules.empty();
  distance_m_.assign(n, std::numeric_limits<float>::quiet_NaN());
  const PointCloud& points = nearer_.points_base;
  for (size_t k = 0; k < points.size() && have_robot; ++k) {
    distance_m_[points.pixel[k]] = distance_to_capsules(robot_poses, {points.x[k], points.y[k], points.z[k]});
  }

  queue_.resize(n);
  std::vector<uint8_t>& mask = nearer_.mask;
  const double mm_per_raw_px = 2.0 / std::sqrt(kPi) * 1000.0 * frame.depth.depth_scale_m / frame.intrinsics.fx;
  for (size_t i = 0; i < n; ++i) {
    if (mask[i] != 1) continue;
    const BlobSummary blob = label_blob(mask, learnt_frame_.depth, distance_m_, i, queue_);
    const bool near = !have_robot || blob.distance_m <= max_distance_m;
    if (!near) continue;
    ++finding.blobs;
    const float distance = have_robot ? blob.distance_m : std::numeric_limits<float>::quiet_NaN();
    // The nearest to the robot is reported; without a robot, the largest.
    const bool better = !finding.found || (have_robot ? distance < finding.distance_m : blob.pixels > finding.pixels);
    if (!better) continue;
    finding.found = true;
    finding.u_min = blob.u_min;
    finding.u_max = blob.u_max;
    finding.v_min = blob.v_min;
    finding.v_max = blob.v_max;
    finding.pixels = blob.pixels;
    const double mean_raw = blob.raw_sum / static_cast<double>(blob.pixels);
    finding.depth_m = static_cast<float>(mean_raw * frame.depth.depth_scale_m);
    finding.size_mm = static_cast<float>(mean_raw * std::sqrt(static_cast<double>(blob.pixels)) * mm_per_raw_px);
    finding.distance_m = distance;
  }
  return finding;
}

}  // namespace hrcsense
