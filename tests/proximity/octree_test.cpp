// SPDX-License-Identifier: Apache-2.0
// The octree's structure (leaves partition the cloud, every box holds its points, leaves are
// cells), repeated searches on one build against a plain scan. That a repeated frame allocates
// nothing is checked in tests/alloc/, whose binary counts allocations.

#include "octree_internal.hpp"

#include "hrcsense/proximity.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace hrcsense::proximity_detail {
namespace {

struct Cloud {
  std::string name;
  std::vector<float> x, y, z;
  size_t size() const { return x.size(); }
  void add(float px, float py, float pz) {
    x.push_back(px);
    y.push_back(py);
    z.push_back(pz);
  }
};

// Clouds that stress the cell arithmetic: spread, clustered, far from the origin, tiny, flat,
// all one point, with NaN and infinite-free outliers.
std::vector<Cloud> test_clouds() {
  std::vector<Cloud> clouds;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  auto make = [&](const char* name, size_t n, float scale, float offset, float flat) {
    Cloud c;
    c.name = name;
    for (size_t i = 0; i < n; ++i) {
      c.add(offset + scale * unit(rng), offset - scale * unit(rng), offset + flat * scale * unit(rng));
    }
    return c;
  };
  clouds.push_back(make("spread", 5000, 2.0F, 0.0F, 1.0F));
  clouds.push_back(make("far_from_origin", 3000, 1.5F, 95.0F, 1.0F));
  clouds.push_back(make("tiny", 2000, 1e-4F, 1.0F, 1.0F));
  clouds.push_back(make("flat", 2000, 1.0F, -0.5F, 0.0F));
  Cloud clustered;
  clustered.name = "clustered";
  for (int blob = 0; blob < 6; ++blob) {
    const float cx = unit(rng) * 3.0F, cy = unit(rng) * 3.0F, cz = unit(rng) * 3.0F;
    for (int i = 0; i < 700; ++i) clustered.add(cx + 0.01F * unit(rng), cy + 0.01F * unit(rng), cz + 0.01F * unit(rng));
  }
  clouds.push_back(clustered);
  Cloud same;
  same.name = "one_point_repeated";
  for (int i = 0; i < 100; ++i) same.add(0.25F, -1.0F, 2.0F);
  clouds.push_back(same);
  Cloud with_nan = make("with_nan", 1500, 1.0F, 0.0F, 1.0F);
  with_nan.name = "with_nan";
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < with_nan.size(); i += 7) (i % 2 ? with_nan.x : with_nan.z)[i] = nan;
  clouds.push_back(with_nan);
  // Points a few float steps either side of the cell boundaries of every height, where the
  // float cell arithmetic puts some of them on the other side (with an origin this small
  // against the side): each must still lie in its leaf's box.
  Cloud boundaries;
  boundaries.name = "on_cell_boundaries";
  const float origin = 0.6F, top = origin + 1.7F, side = top - origin;
  boundaries.add(origin, origin, origin);
  boundaries.add(top, top, top);
  for (int height = 1; height <= 10; ++height) {
    const float cell_m = side / static_cast<float>(1 << height);
    for (int c = 1; c < (1 << height); ++c) {
      float v = origin + static_cast<float>(c) * cell_m;
      for (int step = 0; step < 4; ++step) v = std::nextafter(v, 0.0F);
      for (int step = 0; step < 9; ++step, v = std::nextafter(v, 10.0F)) {
        const float other = origin + side * unit(rng);
        boundaries.add(v, other, origin + side * unit(rng));
        boundaries.add(other, v, v);
      }
    }
  }
  clouds.push_back(boundaries);
  Cloud few = make("few", 5, 1.0F, 0.0F, 1.0F);
  few.name = "few";
  clouds.push_back(few);
  return clouds;
}

bool finite_point(const Cloud& c, uint32_t i) {
  return std::isfinite(c.x[i]) && std::isfinite(c.y[i]) && std::isfinite(c.z[i]);
}

bool inside(const Box& box, const Cloud& c, uint32_t i) {
  return box.min[0] <= c.x[i] && c.x[i] <= box.max[0] && box.min[1] <= c.y[i] && c.y[i] <= box.max[1] &&
         box.min[2] <= c.z[i] && c.z[i] <= box.max[2];
}

bool contains(const Box& outer, const Box& inner) {
  for (int k = 0; k < 3; ++k) {
    if (inner.min[k] < outer.min[k] || inner.max[k] > outer.max[k]) return false;
  }
  return true;
}

// Walks the tree from `index` and checks ranges, boxes, leaf depth and the stable order.
void check_node(const Octree& tree, const Cloud& cloud, uint32_t index, int level, int height,
                const Box& cloud_box, const std::string& where) {
  const Octree::Node& node = tree.nodes()[index];
  const std::vector<uint32_t>& order = tree.sorted_order();
  if (node.children == 0) {
    EXPECT_TRUE(level == height || node.count <= Octree::kLeafPoints) << where << " leaf at level " << level;
    for (uint32_t k = node.first; k < node.first + node.count; ++k) {
      // One cell: the sort is stable (a small leaf higher up spans several cells).
      if (k > node.first && level == height) {
        EXPECT_LT(order[k - 1], order[k]) << where << ": order within a cell";
      }
      if (finite_point(cloud, order[k])) {
        EXPECT_TRUE(inside(node.box, cloud, order[k])) << where << " point " << order[k];
      }
    }
    if (!node.gathered) {
      // A leaf not yet reached by a search has its cell's cube as box, widened by at most a
      // rounding slack far below a cell.
      float side_m = 0.0F, magnitude_m = 0.0F;
      for (int k = 0; k < 3; ++k) {
        side_m = std::max(side_m, cloud_box.max[k] - cloud_box.min[k]);
        magnitude_m = std::max({magnitude_m, std::fabs(cloud_box.min[k]), std::fabs(cloud_box.max[k])});
      }
      const float cell_m = side_m / static_cast<float>(1 << height);
      for (int k = 0; k < 3; ++k) {
        EXPECT_LE(node.box.max[k] - node.box.min[k], cell_m + 1e-4F * (side_m + magnitude_m)) << where;
      }
    }
    return;
  }
  uint32_t next = node.first;
  for (uint32_t c = node.first_child; c < node.first_child + node.children; ++c) {
    const Octree::Node& child = tree.nodes()[c];
    EXPECT_EQ(child.first, next) << where << ": children cover the range in order";
    EXPECT_GT(child.count, 0U) << where;
    EXPECT_TRUE(contains(node.box, child.box)) << where;
    next = child.first + child.count;
    check_node(tree, cloud, c, level + 1, height, cloud_box, where);
  }
  EXPECT_EQ(next, node.first + node.count) << where;
}

Box box_of(const Cloud& c) {
  Box box;
  for (size_t i = 0; i < c.size(); ++i) {
    if (!finite_point(c, static_cast<uint32_t>(i))) continue;
    const float p[3] = {c.x[i], c.y[i], c.z[i]};
    for (int k = 0; k < 3; ++k) {
      box.min[k] = std::min(box.min[k], p[k]);
      box.max[k] = std::max(box.max[k], p[k]);
    }
  }
  return box;
}

// The library's brute force over the same points (point index carried as the pixel).
Contact brute_contact(const Cloud& c, const RobotModel& robot) {
  PointCloud cloud;
  for (size_t i = 0; i < c.size(); ++i) cloud.push_back(c.x[i], c.y[i], c.z[i], static_cast<uint32_t>(i));
  return closest_contact_brute(cloud, PointCloud{}, robot);
}

std::vector<CapsuleBound> bounds_of(const RobotModel& robot) {
  std::vector<CapsuleBound> bounds;
  prepare_bounds(robot, bounds);
  return bounds;
}

TEST(Octree, LeavesPartitionTheCloudAndEveryBoxHoldsItsPoints) {
  for (const Cloud& cloud : test_clouds()) {
    for (int height = 1; height <= 10; ++height) {
      const std::string where = cloud.name + " h" + std::to_string(height);
      Octree tree;
      tree.build(cloud.x.data(), cloud.y.data(), cloud.z.data(), cloud.size(), height);
      ASSERT_FALSE(tree.nodes().empty()) << where;
      EXPECT_EQ(tree.nodes()[0].first, 0U);
      EXPECT_EQ(tree.nodes()[0].count, cloud.size()) << where;
      // The sorted order is a permutation of the cloud.
      std::vector<int> seen(cloud.size(), 0);
      for (uint32_t i : tree.sorted_order()) ++seen[i];
      for (size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i], 1) << where << " index " << i;
      check_node(tree, cloud, 0, 0, height, box_of(cloud), where);
    }
  }
}

TEST(Octree, EmptyAndAllNanCloudsHaveNoNodes) {
  Octree tree;
  tree.build(nullptr, nullptr, nullptr, 0, 4);
  EXPECT_EQ(tree.node_count(), 0U);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> v(10, nan);
  tree.build(v.data(), v.data(), v.data(), v.size(), 4);
  EXPECT_EQ(tree.node_count(), 0U);
  RobotModel robot;
  robot.capsules.push_back(Capsule{});
  EXPECT_FALSE(tree.closest(bounds_of(robot)).found());
}

TEST(Octree, RepeatedSearchesOnOneBuildMatchAPlainScan) {
  // Leaves are gathered (and their boxes made tight) by the first search that reaches them;
  // later searches from elsewhere must see the same tree.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(-1.5F, 3.0F);
  std::uniform_real_distribution<float> radius(0.0F, 0.2F);
  for (const Cloud& cloud : test_clouds()) {
    for (int height : {1, 3, 4, 5, 8}) {
      Octree tree;
      tree.build(cloud.x.data(), cloud.y.data(), cloud.z.data(), cloud.size(), height);
      for (int query = 0; query < 12; ++query) {
        RobotModel robot;
        const int count = query % 3 == 0 ? 1 : 4;
        for (int k = 0; k < count; ++k) {
          Capsule c;
          c.a = {coord(rng), coord(rng), coord(rng)};
          c.b = query % 2 ? c.a : Eigen::Vector3f(coord(rng), coord(rng), coord(rng));
          c.radius_m = radius(rng);
          c.link = k;
          robot.capsules.push_back(c);
        }
        const Contact expected = brute_contact(cloud, robot);
        const Best got = tree.closest(bounds_of(robot));
        const std::string where = cloud.name + " h" + std::to_string(height) + " query " + std::to_string(query);
        ASSERT_TRUE(expected.valid) << where;
        ASSERT_TRUE(got.found()) << where;
        EXPECT_EQ(got.distance_m, expected.distance_m) << where;
        EXPECT_EQ(static_cast<int>(got.point), expected.pixel) << where;
        EXPECT_EQ(static_cast<int>(got.capsule), expected.robot_link) << where;
      }
      check_node(tree, cloud, 0, 0, height, box_of(cloud), cloud.name + " after searches");
    }
  }
}

}  // namespace
}  // namespace hrcsense::proximity_detail
