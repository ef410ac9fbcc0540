// SPDX-License-Identifier: Apache-2.0
// hrcsense proximity — the octree backend: built per frame into reused buffers, searched
// best-first against capsules; internal to src/proximity/.
#pragma once

#include "capsule_math.hpp"

#include <cstdint>
#include <vector>

namespace hrcsense::proximity_detail {

/// The cloud's bounding cube cut into 2^height cells per axis.
struct CellGrid {
  float origin[3] = {0.0F, 0.0F, 0.0F};  ///< the cloud box's minimum corner
  float inv_cell = 0.0F;                 ///< cells per metre; 0 for a cloud of one point (or an infinite one)
  float last_cell = 0.0F;                ///< 2^height - 1
  float cell_m = 0.0F;                   ///< side of a cell
  float slack_m = 0.0F;                  ///< how far float rounding may put a point outside its cell
  Box bounds;                            ///< the cloud's box
};

/// A pointer-free octree over one frame's cloud. Points are sorted by the Morton code of their
/// leaf cell, so every node is a contiguous range of the sorted order; a node with at most
/// kLeafPoints points is not split further.
///
/// Up to height 4 (at most 4096 leaf cells) and with at least one point per cell, the sort is a
/// counting sort of point indices, the node ranges come from the cells' prefix sums, and a leaf
/// starts with its cell's cube as box; its coordinates are gathered into sorted order, and its
/// box made tight, when the search first reaches it (most leaves never are). Otherwise: an LSD
/// radix sort that also moves the coordinates, binary searches for the ranges, and tight boxes
/// throughout.
///
/// closest() reads the cloud passed to build(), which must stay unchanged in between. After the
/// first frame of a given size, build() and closest() do not allocate.
class Octree {
 public:
  static constexpr uint32_t kLeafPoints = 8;
  /// Heights up to this one may be built by the counting sort.
  static constexpr int kMaxCountingHeight = 4;

  /// Builds over points [0, n) with leaves at depth `height` (1-10) of the cloud's bounding cube.
  void build(const float* x, const float* y, const float* z, size_t n, int height);
  /// Exact best contact (point index into the built cloud) under the shared tie rule.
  Best closest(const std::vector<CapsuleBound>& capsules);
  size_t node_count() const { return nodes_.size(); }

  /// A queued node and the lower bound of its distance to the nearest capsule.
  struct Entry {
    float lower_bound_m;
    uint32_t node;
  };

  struct Node {
    Box box;                   ///< holds all the node's points; tight once `gathered`
    uint32_t first = 0;        ///< first point in sorted order
    uint32_t count = 0;
    uint32_t first_child = 0;  ///< children are contiguous in nodes_
    uint32_t children = 0;     ///< 0 for a leaf
    bool gathered = false;     ///< leaf: coordinates in sorted order, box tight
  };
  /// The nodes, nodes_[0] the root; for tests.
  const std::vector<Node>& nodes() const { return nodes_; }
  /// Original index of each point in sorted order; for tests.
  const std::vector<uint32_t>& sorted_order() const { return order_; }

 private:
  void sort_by_counting(const float* x, const float* y, const float* z, size_t n);
  void sort_by_radix(const float* x, const float* y, const float* z, size_t n);
  void octant_bounds(uint32_t first, uint32_t count, int level, uint32_t cell_prefix, uint32_t bounds[9]) const;
  Box build_node(uint32_t index, uint32_t first, uint32_t count, int level, uint32_t cell_prefix);
  Box cell_box(uint32_t morton) const;
  void gather(Node& leaf);
  void scan_leaf(uint32_t index, const std::vector<CapsuleBound>& capsules, float max_radius_m, Best& best);

  int height_ = 0;
  bool counting_ = false;  ///< built by the counting sort (else by the radix sort)
  CellGrid grid_;
  const float* cloud_x_ = nullptr;               ///< the cloud of the last build
  const float* cloud_y_ = nullptr;
  const float* cloud_z_ = nullptr;
  std::vector<uint32_t> counts_;                 ///< points per cell or digit, then write positions
  std::vector<uint32_t> cell_first_;             ///< counting sort: first sorted point per Morton cell, + n
  std::vector<uint16_t> morton_cell_;            ///< counting sort: plain cell index of each Morton code
  std::vector<uint16_t> cell_keys_;              ///< counting sort: plain cell index of each point
  std::vector<uint32_t> keys_, keys_scratch_;    ///< radix sort: Morton code of each point's leaf cell
  std::vector<uint32_t> order_, order_scratch_;  ///< original index of each sorted point
  std::vector<float> x_, y_, z_;                 ///< coordinates in sorted order (gathered leaves only)
  std::vector<Node> nodes_;                      ///< nodes_[0] is the root when not empty
  std::vector<Entry> queue_;                     ///< best-first heap, reused
};

}  // namespace hrcsense::proximity_detail
