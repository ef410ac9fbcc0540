// SPDX-License-Identifier: Apache-2.0
// Proximity/<backend>/<robot>/N: one frame's exact search (build + query) over a person-shaped
// cloud of N points; Peer/nanoflann/point/N: nanoflann used directly; and the build and query
// halves of the trees, for the crossover against brute force (docs/PROXIMITY.md).

#include "hrcsense/sim/person_cloud.hpp"

#include "src/proximity/brute.hpp"
#include "src/proximity/kdtree.hpp"
#include "src/proximity/octree.hpp"
#include "hrcsense/proximity.hpp"

#include <benchmark/benchmark.h>
#include <nanoflann.hpp>

#include <string>

namespace hrcsense::bench {
namespace {

constexpr size_t kSizes[] = {100, 1000, 10000, 100000, 1000000};

std::string size_name(size_t n) {
  return n >= 1000000 ? std::to_string(n / 1000000) + "M" : n >= 1000 ? std::to_string(n / 1000) + "k" : std::to_string(n);
}

RobotModel robot_named(const std::string& robot) {
  return robot == "point" ? person_cloud_robot_point() : person_cloud_robot_arm8();
}

void BM_Search(benchmark::State& state, ProximityBackend backend, ProximityParams params, std::string robot_name,
               size_t n) {
  const PointCloud cloud = person_cloud(n);
  const RobotModel robot = robot_named(robot_name);
  ProximitySearch search(backend, params);
  for (auto _ : state) {
    const Contact contact = search.closest(cloud, cloud, robot);
    benchmark::DoNotOptimize(contact.distance_m);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}

// nanoflann as a user would call it: adaptor, build, one nearest-neighbour query.
struct Adaptor {
  const PointCloud* cloud;
  size_t kdtree_get_point_count() const { return cloud->size(); }
  float kdtree_get_pt(size_t i, size_t dim) const {
    return dim == 0 ? cloud->x[i] : (dim == 1 ? cloud->y[i] : cloud->z[i]);
  }
  template <typename BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bb*/) const {
    return false;
  }
};

void BM_PeerNanoflann(benchmark::State& state, size_t n) {
  const PointCloud cloud = person_cloud(n);
  const Capsule robot = person_cloud_robot_point().capsules[0];
  const float query[3] = {robot.a.x(), robot.a.y(), robot.a.z()};
  Adaptor adaptor{&cloud};
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Adaptor>, Adaptor, 3, uint32_t>;
  Tree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex));
  for (auto _ : state) {
    tree.buildIndex();
    uint32_t index = 0;
    float d2 = 0.0F;
    tree.knnSearch(query, 1, &index, &d2);
    benchmark::DoNotOptimize(d2);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}

// The two halves of a tree frame, to find how many queries a rebuilt tree needs to pay off.
void BM_OctreeBuild(benchmark::State& state, int height, size_t n) {
  const PointCloud cloud = person_cloud(n);
  proximity_detail::Octree octree;
  for (auto _ : state) {
    octree.build(cloud.x.data(), cloud.y.data(), cloud.z.data(), n, height);
    benchmark::DoNotOptimize(octree.node_count());
  }
}

// Repeated queries on one build. Up to height 4 a leaf's coordinates are gathered by the first
// query that reaches it, so this is the later queries' cost; the first query of a frame is in
// Proximity/octree_*/ (build + query).
void BM_OctreeQuery(benchmark::State& state, int height, std::string robot_name, size_t n) {
  const PointCloud cloud = person_cloud(n);
  std::vector<proximity_detail::CapsuleBound> capsules;
  proximity_detail::prepare_bounds(robot_named(robot_name), capsules);
  proximity_detail::Octree octree;
  octree.build(cloud.x.data(), cloud.y.data(), cloud.z.data(), n, height);
  for (auto _ : state) benchmark::DoNotOptimize(octree.closest(capsules).distance_m);
}

void BM_KdtreeBuild(benchmark::State& state, size_t n) {
  const PointCloud cloud = person_cloud(n);
  proximity_detail::KdTree tree;
  for (auto _ : state) {
    tree.build(cloud);
    benchmark::ClobberMemory();
  }
}

void BM_KdtreeQuery(benchmark::State& state, std::string robot_name, size_t n) {
  const PointCloud cloud = person_cloud(n);
  std::vector<proximity_detail::CapsuleBound> capsules;
  proximity_detail::prepare_bounds(robot_named(robot_name), capsules);
  proximity_detail::KdTree tree;
  tree.build(cloud);
  for (auto _ : state) benchmark::DoNotOptimize(tree.closest(capsules).distance_m);
}

// Registered by name so that the names read exactly Stage/variant/N.
int register_all() {
  struct Variant {
    const char* name;
    ProximityBackend backend;
    ProximityParams params;
  };
  const Variant variants[] = {{"brute", ProximityBackend::brute, {8, 1}},
                              {"brute_2threads", ProximityBackend::brute, {8, 2}},
                              {"kdtree", ProximityBackend::kdtree, {8, 1}},
                              {"octree_h4", ProximityBackend::octree, {4, 1}},
                              {"octree_h8", ProximityBackend::octree, {8, 1}},
                              {"auto", ProximityBackend::automatic, {8, 1}}};
  for (const char* robot : {"point", "capsules8"}) {
    for (const Variant& v : variants) {
      for (size_t n : kSizes) {
        const std::string name = std::string("Proximity/") + v.name + "/" + robot + "/" + size_name(n);
        benchmark::RegisterBenchmark(name.c_str(), BM_Search, v.backend, v.params, std::string(robot), n)
            ->Unit(benchmark::kMicrosecond);
      }
    }
  }
  for (size_t n : kSizes) {
    const std::string N = size_name(n);
    benchmark::RegisterBenchmark(("Peer/nanoflann/point/" + N).c_str(), BM_PeerNanoflann, n)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("ProximityPart/octree_h4_build/" + N).c_str(), BM_OctreeBuild, 4, n)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("ProximityPart/octree_h8_build/" + N).c_str(), BM_OctreeBuild, 8, n)
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("ProximityPart/kdtree_build/" + N).c_str(), BM_KdtreeBuild, n)->Unit(benchmark::kMicrosecond);
    for (const char* robot : {"point", "capsules8"}) {
      benchmark::RegisterBenchmark(("ProximityPart/octree_h4_query_" + std::string(robot) + "/" + N).c_str(),
                                   BM_OctreeQuery, 4, std::string(robot), n)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("ProximityPart/octree_h8_query_" + std::string(robot) + "/" + N).c_str(),
                                   BM_OctreeQuery, 8, std::string(robot), n)
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("ProximityPart/kdtree_query_" + std::string(robot) + "/" + N).c_str(),
                                   BM_KdtreeQuery, std::string(robot), n)
          ->Unit(benchmark::kMicrosecond);
    }
  }
  return 0;
}

const int kRegistered = register_all();

}  // namespace
}  // namespace hrcsense::bench
