// SPDX-License-Identifier: Apache-2.0
// hrcsense proximity — the octree backend: built per frame into reused buffers, searched
// best-first against capsules; internal to src/proximity/.
#pragma once

#include "capsule_math.hpp"

#include <cstdint>
#include <vector>

namespace hrcsense::proximity_detail {

/// A pointer-free octree over one frame's cloud. Points are sorted by the Morton code of their
/// leaf cell (a radix sort), so every node is a contiguous range of the sorted copy; a node with
/// at most kLeafPoints points is not split further. After the first frame of a given size,
/// build() and closest() do not allocate.
class Octree {
 public:
  static constexpr uint32_t kLeafPoints = 8;

  /// Builds over points [0, n) with leaves at depth `height` (1-10) of the cloud's bounding cube.
  void build(const float* x, const float* y, const float* z, size_t n, int height);
  /// Exact best contact (point index into the built cloud) under the shared tie rule.
  Best closest(const std::vector<CapsuleBound>& capsules);
  size_t node_count() const { return nodes_.size(); }

 public:
  /// A queued node and the lower bound of its distance to the nearest capsule.
  struct Entry {
    float lower_bound_m;
    uint32_t node;
  };

 private:
  struct Node {
    Box box;                   ///< tight box of the node's points
    uint32_t first = 0;        ///< first point in sorted order
    uint32_t count = 0;
    uint32_t first_child = 0;  ///< children are contiguous in nodes_
    uint32_t children = 0;     ///< 0 for a leaf
  };
  void sort_by_key(const float* x, const float* y, const float* z, size_t n);
  Box build_node(uint32_t index, uint32_t first, uint32_t count, int level);
  void scan_leaf(const Node& leaf, const std::vector<CapsuleBound>& capsules, float max_radius_m, Best& best) const;

  int height_ = 0;
  std::vector<uint32_t> keys_, keys_scratch_;    ///< Morton code of each point's leaf cell
  std::vector<uint32_t> order_, order_scratch_;  ///< original index of each sorted point
  std::vector<uint32_t> counts_;                 ///< radix sort buckets
  std::vector<float> x_, y_, z_;                 ///< coordinates in sorted order
  std::vector<Node> nodes_;                      ///< nodes_[0] is the root when not empty
  std::vector<Entry> queue_;                     ///< best-first heap, reused
};

}  // namespace hrcsense::proximity_detail
