// SPDX-License-Identifier: Apache-2.0
// Proximity/brute/NxC: exact closest contact of N points against C capsules.

#include "hrcsense/proximity.hpp"

#include <benchmark/benchmark.h>

#include <random>

namespace hrcsense {
namespace {

// A cloud spread like a person 1.5-2.5 m from the camera, and capsules like an arm near it.
void BM_ProximityBrute(benchmark::State& state, int points, int capsules) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> xy(-0.5F, 0.5F);
  std::uniform_real_distribution<float> depth(1.5F, 2.5F);
  PointCloud cloud;
  for (int i = 0; i < points; ++i) cloud.push_back(xy(rng), xy(rng), depth(rng), static_cast<uint32_t>(i));
  RobotModel robot;
  for (int c = 0; c < capsules; ++c) {
    Capsule capsule;
    capsule.a = {-0.8F + 0.1F * static_cast<float>(c), 0.2F, 0.6F};
    capsule.b = capsule.a + Eigen::Vector3f(0.1F, -0.05F, 0.2F);
    capsule.radius_m = 0.06F;
    capsule.link = c;
    robot.capsules.push_back(capsule);
  }
  for (auto _ : state) {
    const Contact contact = closest_contact_brute(cloud, cloud, robot);
    benchmark::DoNotOptimize(contact.distance_m);
  }
  state.SetItemsProcessed(state.iterations() * points * capsules);
}

// Registered by name so that the names read exactly Stage/variant/WxH (no argument suffix).
const auto* const kOne =
    benchmark::RegisterBenchmark("Proximity/brute/100000x1", BM_ProximityBrute, 100000, 1)->Unit(benchmark::kMicrosecond);
const auto* const kEight =
    benchmark::RegisterBenchmark("Proximity/brute/100000x8", BM_ProximityBrute, 100000, 8)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
