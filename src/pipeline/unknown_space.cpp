// SPDX-License-Identifier: Apache-2.0
// hrcsense — unknown space near the robot (unknown_space.hpp).

#include "hrcsense/unknown_space.hpp"

#include <algorithm>
#include <cmath>

namespace hrcsense {
namespace {

// Squared distance between segments [p0, p1] and [q0, q1]: the closest pair's parameters
// clamped to [0, 1] (the usual two-step clamp), in double so that nearly parallel segments
// stay exact enough.
double segment_segment_distance_sq(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                                   const Eigen::Vector3d& q1) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 1e-18 && e <= 1e-18) return r.squaredNorm();
  if (a <= 1e-18) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 1e-18) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-18 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p0 + s * d1) - (q0 + t * d2)).squaredNorm();
}

}  // namespace

RaySegment ray_segment(const Intrinsics& in, const Pose& T_base_camera, int u, int v, float z0_m, float z1_m) {
  const double x = (static_cast<double>(u) - in.ppx) / in.fx;
  const double y = (static_cast<double>(v) - in.ppy) / in.fy;
  const Eigen::Vector3d ray(x, y, 1.0);
  RaySegment segment;
  segment.from_base = (T_base_camera * (ray * z0_m)).cast<float>();
  segment.to_base = (T_base_camera * (ray * z1_m)).cast<float>();
  return segment;
}

float segment_capsule_distance(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, const RobotModel& robot) {
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d a = p0.cast<double>(), b = p1.cast<double>();
  for (const Capsule& capsule : robot.capsules) {
    const double d = std::sqrt(segment_segment_distance_sq(a, b, capsule.a.cast<double>(), capsule.b.cast<double>()));
    best = std::min(best, std::max(0.0, d - capsule.radius_m));
  }
  return static_cast<float>(best);
}

void count_no_depth_frames(const DepthImage& depth, std::vector<uint8_t>& no_depth_frames) {
  if (no_depth_frames.size() != depth.pixels.size()) no_depth_frames.assign(depth.pixels.size(), 0);
  for (size_t i = 0; i < depth.pixels.size(); ++i) {
    const uint8_t frames = no_depth_frames[i];
    no_depth_frames[i] = depth.pixels[i] != 0 ? 0 : static_cast<uint8_t>(frames < 255 ? frames + 1 : 255);
  }
}

UnknownSpace unknown_space(const DepthImage& depth, const Intrinsics& intrinsics, const BackgroundModel& background,
                           const std::vector<uint8_t>& foreground_mask, const RobotPixels* robot_pixels,
                           const Pose& T_base_camera, const RobotModel& robot, float stereo_baseline_m,
                           const std::vector<uint8_t>& no_depth_frames, const UnknownSpaceParams& params) {
  const float near_m = params.near_m;
  const float min_valid_ratio = params.min_valid_ratio;
  const int min_no_depth_frames = params.min_no_depth_frames;
  UnknownSpace out;
  const size_t n = depth.pixels.size();
  if (background.mean_m.size() != n || depth.width <= 0 || robot.capsules.empty()) return out;
  const bool have_mask = foreground_mask.size() == n;
  const double fx_b = static_cast<double>(intrinsics.fx) * stereo_baseline_m;  // px·m: shadow width = fx·B·(1/z_fg − 1/z_bg)
  float best = std::numeric_limits<float>::infinity();
  for (int v = 0; v < depth.height; ++v) {
    // Right to left, remembering the nearest envelope pixel to the right: the robot's stereo
    // shadow lies immediately left of it (docs/SAFETY.md).
    int envelope_u = -1;
    float envelope_z = 0.0F;
    for (int u = depth.width - 1; u >= 0; --u) {
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(depth.width) + static_cast<size_t>(u);
      if (robot_pixels != nullptr && robot_pixels->from_raw[i] != 0) {  // the arm and its edges
        envelope_u = u;
        envelope_z = static_cast<float>(robot_pixels->from_raw[i]) * depth.depth_scale_m;
        continue;
      }
      const uint16_t raw = depth.pixels[i];
      const float bg = background.mean_m[i];
      float z0 = 0.0F;
      if (raw == 0) {
        // No depth now is news only where depth was always there while learning; where it came
        // and went (a far wall, a shiny table) it was unknown when the cell was taught.
        if (!(bg > 0.0F) || !(background.valid_ratio.size() == n && background.valid_ratio[i] >= min_valid_ratio)) {
          ++out.never_valid_pixels;
          continue;
        }
        if (envelope_u >= 0 && envelope_z > 0.0F && bg > envelope_z) {
          const double shadow_px = fx_b * (1.0 / envelope_z - 1.0 / bg);
          if (envelope_u - u <= static_cast<int>(std::ceil(shadow_px)) + 1) {
            ++out.robot_shadow_pixels;
            continue;
          }
        }
        // A pixel that only just lost its depth is most likely the sensor's random dropout (a
        // far wall loses 1-4 % of its pixels each frame); what stays without depth is unknown.
        if (no_depth_frames.size() == n && no_depth_frames[i] < min_no_depth_frames) {
          ++out.dropout_pixels;
          continue;
        }
        ++out.no_depth_pixels;
        z0 = near_m;
      } else if (have_mask && foreground_mask[i] != 0) {
        ++out.hidden_pixels;
        z0 = static_cast<float>(raw) * depth.depth_scale_m;
      } else {
        continue;
      }
      if (!(bg > z0)) continue;  // nothing hidden behind it
      const RaySegment s = ray_segment(intrinsics, T_base_camera, u, v, z0, bg);
      best = std::min(best, segment_capsule_distance(s.from_base, s.to_base, robot));
    }
  }
  if (std::isfinite(best)) out.distance_m = best;
  return out;
}

}  // namespace hrcsense
