// SPDX-License-Identifier: Apache-2.0
// Test support for the unknown-space tests: one row of `Width` pixels, fx 100 px, ppx 0, a
// baseline of 0.05 m, background at 2 m and always valid, camera at the base origin. The one
// capsule runs along y at x = 0.3, z = 1, radius 0.05: the ray of pixel u is x = 0.01·u·z, so
// its closest approach is near u = 30 / z.
#pragma once

#include "hrcsense/unknown_space.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace hrcsense::test {

inline Capsule capsule(Eigen::Vector3f a, Eigen::Vector3f b, float radius_m) {
  Capsule c;
  c.a = a;
  c.b = b;
  c.radius_m = radius_m;
  return c;
}

template <int Width>
struct UnknownSpaceRow {
  static constexpr int kWidth = Width;
  DepthImage depth;
  Intrinsics in;
  BackgroundModel background;
  std::vector<uint8_t> mask = std::vector<uint8_t>(kWidth, 0);
  std::vector<uint16_t> from = std::vector<uint16_t>(kWidth, 0), to = std::vector<uint16_t>(kWidth, 0);
  std::vector<uint8_t> no_depth_frames;
  RobotModel robot;

  /// Every pixel has been without depth for `frames_without_depth` frames (0: none yet).
  explicit UnknownSpaceRow(uint8_t frames_without_depth) : no_depth_frames(kWidth, frames_without_depth) {
    depth.resize(kWidth, 1);
    depth.depth_scale_m = 0.001F;
    std::fill(depth.pixels.begin(), depth.pixels.end(), 2000);
    in.width = kWidth;
    in.height = 1;
    in.fx = in.fy = 100.0F;
    background.width = kWidth;
    background.height = 1;
    background.mean_m.assign(kWidth, 2.0F);
    background.spread_m.assign(kWidth, 0.005F);
    background.valid_ratio.assign(kWidth, 1.0F);
    robot.capsules.push_back(capsule({0.3F, -1.0F, 1.0F}, {0.3F, 1.0F, 1.0F}, 0.05F));
  }

  UnknownSpace run(bool with_envelope = true) {
    const RobotPixels envelope{from.data(), to.data()};
    return unknown_space(depth, in, background, mask, with_envelope ? &envelope : nullptr, Pose::Identity(), robot,
                         0.05F, no_depth_frames);
  }
};

}  // namespace hrcsense::test
