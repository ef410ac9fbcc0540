// SPDX-License-Identifier: Apache-2.0
// Peer/pcl_*/point/N: what users would otherwise pick, PCL 1.13, on the same person-shaped
// clouds; built only with -DHRCSENSE_WITH_PCL_PEERS=ON (never in CI). Per frame: build + one
// nearest-point query from the robot point. The copy into PCL's cloud type is left out of the
// timing (users of PCL would already hold one), which favours PCL.

#include "hrcsense/sim/person_cloud.hpp"

#include <benchmark/benchmark.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/octree/octree_search.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace hrcsense::bench {
namespace {

constexpr size_t kSizes[] = {100, 1000, 10000, 100000, 1000000};

std::string size_name(size_t n) {
  return n >= 1000000 ? std::to_string(n / 1000000) + "M" : n >= 1000 ? std::to_string(n / 1000) + "k" : std::to_string(n);
}

pcl::PointCloud<pcl::PointXYZ>::Ptr to_pcl(const PointCloud& cloud) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr out(new pcl::PointCloud<pcl::PointXYZ>);
  out->reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) out->push_back(pcl::PointXYZ(cloud.x[i], cloud.y[i], cloud.z[i]));
  return out;
}

pcl::PointXYZ robot_query() {
  const Capsule c = person_cloud_robot_point().capsules[0];
  return {c.a.x(), c.a.y(), c.a.z()};
}

void BM_PclKdtree(benchmark::State& state, size_t n) {
  const auto cloud = to_pcl(person_cloud(n));
  std::vector<int> index(1);
  std::vector<float> d2(1);
  for (auto _ : state) {
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(cloud);
    tree.nearestKSearch(robot_query(), 1, index, d2);
    benchmark::DoNotOptimize(d2[0]);
  }
}

// The leaf size of our octree at height h over this cloud: the bounding cube's side / 2^h.
double leaf_size_m(const PointCloud& cloud, int height) {
  const auto [x0, x1] = std::minmax_element(cloud.x.begin(), cloud.x.end());
  const auto [y0, y1] = std::minmax_element(cloud.y.begin(), cloud.y.end());
  const auto [z0, z1] = std::minmax_element(cloud.z.begin(), cloud.z.end());
  const double side = std::max({*x1 - *x0, *y1 - *y0, *z1 - *z0});
  return side / static_cast<double>(1 << height);
}

// exact: nearestKSearch (k = 1); otherwise approxNearestSearch, PCL's fast approximate query.
void BM_PclOctree(benchmark::State& state, size_t n, bool exact) {
  const PointCloud ours = person_cloud(n);
  const auto cloud = to_pcl(ours);
  const double resolution_m = leaf_size_m(ours, 4);
  std::vector<int> index(1);
  std::vector<float> d2(1);
  double worst_error_m = 0.0;
  const pcl::PointXYZ q = robot_query();
  for (auto _ : state) {
    pcl::octree::OctreePointCloudSearch<pcl::PointXYZ> octree(resolution_m);
    octree.setInputCloud(cloud);
    octree.addPointsFromInputCloud();
    if (exact) {
      octree.nearestKSearch(q, 1, index, d2);
    } else {
      int i = 0;
      float s = 0.0F;
      octree.approxNearestSearch(q, i, s);
      d2[0] = s;
    }
    benchmark::DoNotOptimize(d2[0]);
  }
  // How far the answer is from the exact nearest distance, reported beside the time.
  float best2 = std::numeric_limits<float>::infinity();
  for (const auto& p : cloud->points) {
    best2 = std::min(best2, (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y) + (p.z - q.z) * (p.z - q.z));
  }
  worst_error_m = std::sqrt(static_cast<double>(d2[0])) - std::sqrt(static_cast<double>(best2));
  state.counters["error_m"] = worst_error_m;
}

int register_all() {
  for (size_t n : kSizes) {
    const std::string N = size_name(n);
    benchmark::RegisterBenchmark(("Peer/pcl_kdtree/point/" + N).c_str(), BM_PclKdtree, n)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Peer/pcl_octree_h4/point/" + N).c_str(), BM_PclOctree, n, true)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("Peer/pcl_octree_h4_approx/point/" + N).c_str(), BM_PclOctree, n, false)
        ->Unit(benchmark::kMicrosecond);
  }
  return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace hrcsense::bench
