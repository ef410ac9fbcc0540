// SPDX-License-Identifier: Apache-2.0
// Unknown space, a ray segment against many spheres at once (unknown_space_spheres.hpp): the
// SSE2 and plain tests against the same geometry worked in double, and by hand.

#include "src/pipeline/unknown_space_spheres.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace hrcsense {
namespace {

using unknown_space_detail::RaySpan;
using unknown_space_detail::SphereLanes;

// Whether the segment's point nearest the centre lies within reach of the sphere's surface, in
// double; 0 where that is too close to call in float (within 1e-4 of the limit), else ±1.
int within_in_double(const SphereLanes& s, int c, const RaySpan& r, float reach_m) {
  const size_t i = static_cast<size_t>(c);
  const double d[3] = {r.dx, r.dy, r.dz}, w[3] = {s.x[i], s.y[i], s.z[i]};
  const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  const double t = std::clamp((w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd, double{r.z0_m}, double{r.z1_m});
  double sq = 0.0;
  for (int k = 0; k < 3; ++k) sq += (w[k] - t * d[k]) * (w[k] - t * d[k]);
  const double limit = double{s.radius_m[i]} + reach_m;
  if (std::fabs(std::sqrt(sq) - limit) < 1e-4) return 0;
  return std::sqrt(sq) <= limit ? 1 : -1;
}

TEST(UnknownSpaceSpheres, FourAtATimeAndOneByOneAgreeWithTheGeometry) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> pos(-1.5F, 1.5F), radius(0.0F, 0.4F), depth(0.2F, 3.0F);
  int clear = 0;
  for (int trial = 0; trial < 400; ++trial) {
    SphereLanes s;
    s.count = 1 + trial % 13;  // not always a multiple of four
    for (size_t i = 0; i < static_cast<size_t>(s.count); ++i) {
      s.x[i] = pos(rng);
      s.y[i] = pos(rng);
      s.z[i] = 1.5F + pos(rng);
      s.radius_m[i] = radius(rng);
    }
    RaySpan r;
    r.dx = 0.5F * pos(rng);
    r.dy = 0.5F * pos(rng);
    r.dz = 1.0F;
    r.inv_direction_sq = 1.0F / (r.dx * r.dx + r.dy * r.dy + r.dz * r.dz);
    r.z0_m = depth(rng);
    r.z1_m = r.z0_m + depth(rng);
    const float reach_m = 0.3F * radius(rng);
    const uint32_t candidates = trial % 3 == 0 ? 0xFFFFFFFFU : static_cast<uint32_t>(rng());
    const uint32_t plain = unknown_space_detail::spheres_within_plain(s, r, reach_m, candidates);
#if defined(__SSE2__)
    const uint32_t sse2 = unknown_space_detail::spheres_within_sse2(s, r, reach_m, candidates);
#else
    const uint32_t sse2 = plain;
#endif
    for (int c = 0; c < 32; ++c) {
      const uint32_t bit = 1U << c;
      const int expected = c < s.count && (candidates & bit) != 0 ? within_in_double(s, c, r, reach_m) : -1;
      if (expected == 0) continue;
      ++clear;
      EXPECT_EQ((plain & bit) != 0, expected > 0) << "trial " << trial << " sphere " << c;
      EXPECT_EQ((sse2 & bit) != 0, expected > 0) << "trial " << trial << " sphere " << c;
    }
  }
  EXPECT_GT(clear, 400 * 30);  // nearly every lane could be called
}

TEST(UnknownSpaceSpheres, ByHand) {
  // The ray along z from 1 to 2 m; spheres of radius 0.1 centred 0.3 m off it at z = 1.5 (0.2 m
  // from the surface), at z = 2.5 on the axis (0.4 m beyond the end), and one with NaN.
  SphereLanes s;
  s.count = 3;
  s.x = {0.3F, 0.0F, std::nanf("")};
  s.z = {1.5F, 2.5F, 1.5F};
  s.radius_m = {0.1F, 0.1F, 0.1F};
  RaySpan r;
  r.dz = 1.0F;
  r.z0_m = 1.0F;
  r.z1_m = 2.0F;
  EXPECT_EQ(unknown_space_detail::spheres_within(s, r, 0.19F, ~0U), 0b100U);  // NaN is never skipped
  EXPECT_EQ(unknown_space_detail::spheres_within(s, r, 0.21F, ~0U), 0b101U);
  EXPECT_EQ(unknown_space_detail::spheres_within(s, r, 0.41F, ~0U), 0b111U);
  EXPECT_EQ(unknown_space_detail::spheres_within(s, r, 0.41F, 0b010U), 0b010U);
}

}  // namespace
}  // namespace hrcsense
