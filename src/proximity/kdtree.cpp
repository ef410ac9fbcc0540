// SPDX-License-Identifier: Apache-2.0
// hrcsense — the kd-tree backend: nanoflann's tree with nanoflann's point query, and an exact
// best-first capsule traversal of the same nodes.

#include "kdtree.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <array>
#include <utility>

namespace hrcsense::proximity_detail {
// Not in an anonymous namespace: KdTree::Impl holds these types as members.

// nanoflann's dataset interface on the SoA cloud: it reads the caller's arrays in place.
struct CloudAdaptor {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  size_t n = 0;

  size_t kdtree_get_point_count() const { return n; }
  float kdtree_get_pt(size_t i, size_t dim) const { return dim == 0 ? x[i] : (dim == 1 ? y[i] : z[i]); }
  // Our vectorised box instead of nanoflann's per-point, per-dimension loop.
  template <typename BoundingBox>
  bool kdtree_get_bbox(BoundingBox& bb) const {
    const Box box = bounding_box(x, y, z, n);
    for (int k = 0; k < 3; ++k) {
      bb[k].low = box.min[k];
      bb[k].high = box.max[k];
    }
    return true;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>, CloudAdaptor, 3,
                                                 uint32_t>;
using Node = Tree::Node;

// nanoflann's result-set interface for one robot point: every point nanoflann offers is
// re-evaluated with the shared float distance and tie rule, and the search radius it is told
// (worstDist, squared) is the best surface distance plus the radius plus rounding slack, so
// points tied with the best are still offered.
class PointResult {
 public:
  PointResult(const CapsuleBound& capsule, const CloudAdaptor& cloud) : capsule_(capsule), cloud_(cloud) {}
  bool full() const { return true; }
  float worstDist() const { return worst_d2_; }
  bool addPoint(float /*nanoflann_d2*/, uint32_t index) {
    const Segment& s = capsule_.segment;
    const float d = surface_distance(s, point_distance_sq(s, cloud_.x[index], cloud_.y[index], cloud_.z[index]));
    best_.offer(d, index, 0);
    const float reach_m = best_.distance_m + s.radius_m + bound_slack_m(best_.distance_m, s.radius_m);
    worst_d2_ = reach_m * reach_m;
    return true;
  }
  const Best& best() const { return best_; }

 private:
  const CapsuleBound& capsule_;
  const CloudAdaptor& cloud_;
  Best best_;
  float worst_d2_ = kInf;
};

// A queued node with the box nanoflann's splits give it and its lower bound.
struct Entry {
  float lower_bound_m;
  const Node* node;
  Box box;
};

bool entry_heap_order(const Entry& a, const Entry& b) { return a.lower_bound_m > b.lower_bound_m; }

struct KdTree::Impl {
  CloudAdaptor cloud;
  Tree tree{3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(
                          kLeafPoints, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex)};
  bool built = false;
  std::vector<Entry> queue;

  void scan_leaf(const Node& leaf, const Box& box, const std::vector<CapsuleBound>& capsules, float max_radius_m,
                 Best& best) const {
    for (size_t c = 0; c < capsules.size(); ++c) {
      const CapsuleBound& capsule = capsules[c];
      if (prunable(lower_bound_m(capsule, box), best.distance_m, max_radius_m)) continue;
      for (size_t k = leaf.node_type.lr.left; k < leaf.node_type.lr.right; ++k) {
        const uint32_t i = tree.vAcc[k];
        const float d = surface_distance(capsule.segment, axis_distance_sq(capsule.segment, cloud.x[i], cloud.y[i], cloud.z[i]));
        best.offer(d, i, c);
      }
    }
  }

  Best capsule_search(const std::vector<CapsuleBound>& capsules) {
    Best best;
    float max_radius_m = 0.0F;
    for (const CapsuleBound& c : capsules) max_radius_m = std::max(max_radius_m, c.segment.radius_m);
    Box root;
    for (int k = 0; k < 3; ++k) {
      root.min[k] = tree.root_bbox[k].low;
      root.max[k] = tree.root_bbox[k].high;
    }
    queue.clear();
    queue.push_back({min_lower_bound_m(capsules, root), tree.root_node, root});
    while (!queue.empty()) {
      std::pop_heap(queue.begin(), queue.end(), entry_heap_order);
      const Entry entry = queue.back();
      queue.pop_back();
      if (prunable(entry.lower_bound_m, best.distance_m, max_radius_m)) break;  // the rest lie farther
      const Node& node = *entry.node;
      if (node.child1 == nullptr && node.child2 == nullptr) {
        scan_leaf(node, entry.box, capsules, max_radius_m, best);
        continue;
      }
      // nanoflann's split: the low child ends at divlow, the high child starts at divhigh.
      const int axis = node.node_type.sub.divfeat;
      Box low = entry.box;
      low.max[axis] = node.node_type.sub.divlow;
      Box high = entry.box;
      high.min[axis] = node.node_type.sub.divhigh;
      for (const auto& [child, box] : {std::pair{node.child1, low}, std::pair{node.child2, high}}) {
        const float lb = min_lower_bound_m(capsules, box);
        if (prunable(lb, best.distance_m, max_radius_m)) continue;
        queue.push_back({lb, child, box});
        std::push_heap(queue.begin(), queue.end(), entry_heap_order);
      }
    }
    return best;
  }
};

KdTree::KdTree() : impl_(std::make_unique<Impl>()) {}
KdTree::~KdTree() = default;

void KdTree::build(const PointCloud& cloud) {
  impl_->cloud = {cloud.x.data(), cloud.y.data(), cloud.z.data(), cloud.size()};
  impl_->tree.buildIndex();
  impl_->built = cloud.size() > 0;
}

Best KdTree::closest(const std::vector<CapsuleBound>& capsules) {
  if (!impl_->built || capsules.empty()) return {};
  if (capsules.size() == 1 && capsules[0].segment.is_point) {
    const Segment& s = capsules[0].segment;
    const float query[3] = {s.ax, s.ay, s.az};
    PointResult result(capsules[0], impl_->cloud);
    impl_->tree.findNeighbors(result, query, nanoflann::SearchParams());
    return result.best();
  }
  return impl_->capsule_search(capsules);
}

}  // namespace hrcsense::proximity_detail
