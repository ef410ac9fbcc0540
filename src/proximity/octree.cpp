// SPDX-License-Identifier: Apache-2.0
// hrcsense — the octree backend: Morton-sorted points, tight node boxes, best-first search.

#include "octree.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrcsense::proximity_detail {
namespace {

// Spreads the low 10 bits of v so that two zero bits follow each (bit i moves to bit 3i).
uint32_t spread_bits(uint32_t v) {
  v &= 0x3FFU;
  v = (v | (v << 16)) & 0x030000FFU;
  v = (v | (v << 8)) & 0x0300F00FU;
  v = (v | (v << 4)) & 0x030C30C3U;
  v = (v | (v << 2)) & 0x09249249U;
  return v;
}

// Cell index along one axis, clamped into [0, cells - 1]; NaN lands in cell 0 (its distance is
// NaN, which never wins, so where it sits does not matter).
uint32_t cell_of(float value, float origin, float inv_cell, float last_cell) {
  float f = (value - origin) * inv_cell;
  f = f > 0.0F ? f : 0.0F;
  f = f < last_cell ? f : last_cell;
  return static_cast<uint32_t>(f);
}

float min_lower_bound_m(const std::vector<CapsuleBound>& capsules, const Box& box) {
  float lb = kInf;
  for (const CapsuleBound& c : capsules) lb = std::min(lb, lower_bound_m(c, box));
  return lb;
}


}  // namespace

// Min-heap on the lower bound (std heaps are max-heaps).
static bool heap_order(const Octree::Entry& a, const Octree::Entry& b) { return a.lower_bound_m > b.lower_bound_m; }

void Octree::build(const float* x, const float* y, const float* z, size_t n, int height) {
  if (height < 1 || height > 10) throw std::invalid_argument("octree height must be 1-10");
  if (n > 0xFFFFFFFFU) throw std::invalid_argument("octree: more than 2^32 points");
  height_ = height;
  nodes_.clear();
  const Box box = bounding_box(x, y, z, n);
  if (n == 0 || !(box.min[0] <= box.max[0])) return;  // empty, or no finite point

  // The cube over the cloud, cut into 2^height cells per axis.
  const float side_m = std::max({box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]});
  const auto cells = static_cast<float>(1U << height);
  const float inv_cell = side_m > 0.0F ? cells / side_m : 0.0F;
  const float last_cell = cells - 1.0F;
  keys_.resize(n);
  order_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    keys_[i] = spread_bits(cell_of(x[i], box.min[0], inv_cell, last_cell)) |
               spread_bits(cell_of(y[i], box.min[1], inv_cell, last_cell)) << 1 |
               spread_bits(cell_of(z[i], box.min[2], inv_cell, last_cell)) << 2;
    order_[i] = static_cast<uint32_t>(i);
  }
  sort_by_key(x, y, z, n);
  nodes_.resize(1);
  build_node(0, 0, static_cast<uint32_t>(n), 0);
}

// LSD radix sort of (key, order) in passes of at most 12 bits (one pass up to height 4); the
// last pass also moves the coordinates into sorted order, which saves a separate gather pass.
void Octree::sort_by_key(const float* x, const float* y, const float* z, size_t n) {
  x_.resize(n);
  y_.resize(n);
  z_.resize(n);
  const int total_bits = 3 * height_;
  const int passes = (total_bits + 11) / 12;
  const int digit_bits = (total_bits + passes - 1) / passes;
  const uint32_t digit_mask = (1U << digit_bits) - 1U;
  keys_scratch_.resize(n);
  order_scratch_.resize(n);
  counts_.resize(size_t{1} << digit_bits);
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * digit_bits;
    std::fill(counts_.begin(), counts_.end(), 0U);
    for (size_t i = 0; i < n; ++i) ++counts_[(keys_[i] >> shift) & digit_mask];
    uint32_t sum = 0;
    for (uint32_t& c : counts_) {
      const uint32_t start = sum;
      sum += c;
      c = start;
    }
    const bool last = pass + 1 == passes;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t slot = counts_[(keys_[i] >> shift) & digit_mask]++;
      keys_scratch_[slot] = keys_[i];
      order_scratch_[slot] = order_[i];
      if (last) {
        const uint32_t original = order_[i];
        x_[slot] = x[original];
        y_[slot] = y[original];
        z_[slot] = z[original];
      }
    }
    keys_.swap(keys_scratch_);
    order_.swap(order_scratch_);
  }
}

// Fills nodes_[index] for the sorted range [first, first + count) at `level`, children
// appended as one contiguous run before any of them is filled; returns the node's box.
Box Octree::build_node(uint32_t index, uint32_t first, uint32_t count, int level) {
  nodes_[index].first = first;
  nodes_[index].count = count;
  nodes_[index].children = 0;
  if (level == height_ || count <= kLeafPoints) {
    nodes_[index].box = bounding_box(x_.data() + first, y_.data() + first, z_.data() + first, count);
    return nodes_[index].box;
  }
  // The child octant is the 3-bit digit below this level; keys are sorted, so each octant is
  // a contiguous run found by binary search.
  const int shift = 3 * (height_ - level - 1);
  uint32_t bounds[9];
  const uint32_t* begin = keys_.data() + first;
  const uint32_t* end = begin + count;
  const uint32_t* at = begin;
  for (uint32_t digit = 0; digit < 8; ++digit) {
    bounds[digit] = static_cast<uint32_t>(at - begin);
    at = std::partition_point(at, end, [&](uint32_t key) { return ((key >> shift) & 7U) <= digit; });
  }
  bounds[8] = count;
  uint32_t children = 0;
  for (int d = 0; d < 8; ++d) children += bounds[d + 1] > bounds[d] ? 1 : 0;
  const auto first_child = static_cast<uint32_t>(nodes_.size());
  nodes_[index].first_child = first_child;
  nodes_[index].children = children;
  nodes_.resize(nodes_.size() + children);  // capacity kept across frames
  uint32_t child = first_child;
  Box box;
  for (int d = 0; d < 8; ++d) {
    if (bounds[d + 1] == bounds[d]) continue;
    box.add(build_node(child++, first + bounds[d], bounds[d + 1] - bounds[d], level + 1));
  }
  nodes_[index].box = box;
  return box;
}

void Octree::scan_leaf(const Node& leaf, const std::vector<CapsuleBound>& capsules, float max_radius_m,
                       Best& best) const {
  const float* x = x_.data() + leaf.first;
  const float* y = y_.data() + leaf.first;
  const float* z = z_.data() + leaf.first;
  for (size_t c = 0; c < capsules.size(); ++c) {
    const CapsuleBound& capsule = capsules[c];
    if (prunable(lower_bound_m(capsule, leaf.box), best.distance_m, max_radius_m)) continue;
    const float d2 = min_axis_distance_sq(capsule.segment, x, y, z, leaf.count);
    if (!(d2 < kInf)) continue;
    const float m = surface_distance(capsule.segment, d2);
    if (m > best.distance_m) continue;
    // At or below the best: the lowest original index reaching m in this leaf competes.
    for (uint32_t k = 0; k < leaf.count; ++k) {
      const float d = surface_distance(capsule.segment, axis_distance_sq(capsule.segment, x[k], y[k], z[k]));
      if (d == m) best.offer(m, order_[leaf.first + k], c);
    }
  }
}

Best Octree::closest(const std::vector<CapsuleBound>& capsules) {
  Best best;
  if (nodes_.empty() || capsules.empty()) return best;
  float max_radius_m = 0.0F;
  for (const CapsuleBound& c : capsules) max_radius_m = std::max(max_radius_m, c.segment.radius_m);
  queue_.clear();
  queue_.push_back({min_lower_bound_m(capsules, nodes_[0].box), 0});
  while (!queue_.empty()) {
    std::pop_heap(queue_.begin(), queue_.end(), heap_order);
    const Entry entry = queue_.back();
    queue_.pop_back();
    // Every node left has a bound at least this large: none can hold or tie the best.
    if (prunable(entry.lower_bound_m, best.distance_m, max_radius_m)) break;
    const Node& node = nodes_[entry.node];
    if (node.children == 0) {
      scan_leaf(node, capsules, max_radius_m, best);
      continue;
    }
    for (uint32_t c = node.first_child; c < node.first_child + node.children; ++c) {
      const float lb = min_lower_bound_m(capsules, nodes_[c].box);
      if (prunable(lb, best.distance_m, max_radius_m)) continue;
      queue_.push_back({lb, c});
      std::push_heap(queue_.begin(), queue_.end(), heap_order);
    }
  }
  return best;
}

}  // namespace hrcsense::proximity_detail
