// SPDX-License-Identifier: Apache-2.0
// hrcsense proximity — the kd-tree backend on nanoflann; internal to src/proximity/.
#pragma once

#include "capsule_math.hpp"

#include <memory>
#include <vector>

namespace hrcsense::proximity_detail {

/// nanoflann's kd-tree over the SoA cloud (an adaptor, no copy), rebuilt per frame. A single
/// robot point is searched with nanoflann's own query (a result set that applies the shared tie
/// rule); capsules, which nanoflann cannot query, with a best-first traversal of its nodes.
/// nanoflann frees its node pool and allocates it again at every build (docs/PROXIMITY.md).
class KdTree {
 public:
  static constexpr size_t kLeafPoints = 16;  ///< nanoflann's leaf_max_size

  KdTree();
  ~KdTree();
  KdTree(const KdTree&) = delete;
  KdTree& operator=(const KdTree&) = delete;

  /// Builds over `cloud`, which must stay unchanged until the last closest() call.
  void build(const PointCloud& cloud);
  /// Exact best contact (point index into the built cloud) under the shared tie rule.
  Best closest(const std::vector<CapsuleBound>& capsules);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hrcsense::proximity_detail
