// SPDX-License-Identifier: Apache-2.0
// hrcsense — the octree backend: points sorted by leaf cell, node boxes, best-first search.

#include "octree.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrcsense::proximity_detail {
namespace {

// The counting sort cuts the cloud into this many slices with their own counters per cell (see
// sort_by_counting).
constexpr size_t kLanes = 4;

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
// NaN, which never wins, so where it sits does not matter). Converted through int32: SSE2 has
// no unsigned conversion, and the value is at most 1023.
uint32_t cell_of(float value, float origin, float inv_cell, float last_cell) {
  float f = (value - origin) * inv_cell;
  f = f > 0.0F ? f : 0.0F;
  f = f < last_cell ? f : last_cell;
  return static_cast<uint32_t>(static_cast<int32_t>(f));
}

// Morton code of the leaf cell of each of points [0, n).
void morton_keys(const CellGrid& g, const float* x, const float* y, const float* z, size_t n, uint32_t* keys) {
#pragma omp simd
  for (size_t i = 0; i < n; ++i) {
    keys[i] = spread_bits(cell_of(x[i], g.origin[0], g.inv_cell, g.last_cell)) |
              spread_bits(cell_of(y[i], g.origin[1], g.inv_cell, g.last_cell)) << 1 |
              spread_bits(cell_of(z[i], g.origin[2], g.inv_cell, g.last_cell)) << 2;
  }
}

// Plain cell index cx + cy 2^h + cz 4^h (at most 12 bits: height <= 4) of each of points
// [0, n): cheaper than the Morton code, which the counting sort looks up per cell instead.
void cell_keys(const CellGrid& g, int height, const float* x, const float* y, const float* z, size_t n,
               uint16_t* keys) {
#pragma omp simd
  for (size_t i = 0; i < n; ++i) {
    keys[i] = static_cast<uint16_t>(cell_of(x[i], g.origin[0], g.inv_cell, g.last_cell) |
                                    cell_of(y[i], g.origin[1], g.inv_cell, g.last_cell) << height |
                                    cell_of(z[i], g.origin[2], g.inv_cell, g.last_cell) << (2 * height));
  }
}

// Visits points [0, n) as kLanes slices in turn, point by point: visit(lane, i). Consecutive
// visits then update the counters of different slices, which do not wait on each other, while
// within a slice the order is kept (so sorts built on it are stable).
template <typename Visit>
void for_each_in_slices(size_t n, Visit&& visit) {
  size_t begin[kLanes + 1];
  for (size_t lane = 0; lane <= kLanes; ++lane) begin[lane] = lane * n / kLanes;
  const size_t common = begin[1] - begin[0];  // the shortest slice: the first one
  for (size_t j = 0; j < common; ++j) {
    for (size_t lane = 0; lane < kLanes; ++lane) visit(lane, begin[lane] + j);
  }
  for (size_t lane = 0; lane < kLanes; ++lane) {
    for (size_t i = begin[lane] + common; i < begin[lane + 1]; ++i) visit(lane, i);
  }
}

CellGrid make_grid(const Box& box, int height) {
  CellGrid g;
  g.bounds = box;
  const float side_m = std::max({box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]});
  const auto cells = static_cast<float>(1U << height);
  float magnitude_m = 0.0F;
  for (int k = 0; k < 3; ++k) {
    g.origin[k] = box.min[k];
    magnitude_m = std::max({magnitude_m, std::fabs(box.min[k]), std::fabs(box.max[k])});
  }
  g.last_cell = cells - 1.0F;
  if (side_m > 0.0F && std::isfinite(side_m)) {
    g.inv_cell = cells / side_m;
    g.cell_m = side_m / cells;
    // cell_of's roundings (and inv_cell's) put a point a few float steps of side_m outside its
    // cell, and the cell's bounds origin + c * cell_m round on the coordinates' magnitude: up
    // to ~5e-7 (side_m + magnitude_m) measured over heights 1-10. 1e-5 leaves a factor 20 and
    // stays far below a cell (tests/proximity/octree_test.cpp puts points on cell boundaries).
    g.slack_m = 1e-5F * (side_m + magnitude_m);
  }
  return g;
}

// Min-heap on the lower bound (std heaps are max-heaps).
bool heap_order(const Octree::Entry& a, const Octree::Entry& b) { return a.lower_bound_m > b.lower_bound_m; }

}  // namespace

void Octree::build(const float* x, const float* y, const float* z, size_t n, int height) {
  if (height < 1 || height > 10) throw std::invalid_argument("octree height must be 1-10");
  if (n > 0xFFFFFFFFU) throw std::invalid_argument("octree: more than 2^32 points");
  height_ = height;
  nodes_.clear();
  cloud_x_ = x;
  cloud_y_ = y;
  cloud_z_ = z;
  const Box box = bounding_box(x, y, z, n);
  if (n == 0 || !(box.min[0] <= box.max[0])) return;  // empty, or no finite point
  grid_ = make_grid(box, height);
  order_.resize(n);
  x_.resize(n);
  y_.resize(n);
  z_.resize(n);
  // Below one point per cell the counting sort's pass over all cells costs more than the sort.
  counting_ = height <= kMaxCountingHeight && n >= (size_t{1} << (3 * height));
  if (counting_) {
    sort_by_counting(x, y, z, n);
  } else {
    sort_by_radix(x, y, z, n);
  }
  nodes_.resize(1);
  build_node(0, 0, static_cast<uint32_t>(n), 0, 0);
}

// Counting sort of point indices by leaf cell: one pass computes each point's cell, a second
// counts the points per cell, prefix sums over the cells in Morton order give each cell its
// range, a third writes the original indices there. The coordinates are not moved: at 10^6
// points that gather costs more than everything else, and the search needs only the leaves it
// reaches (gather()). The cloud is cut into kLanes slices with their own counters per cell,
// counted and placed in turn point by point, so that the counter updates of consecutive points
// (usually the same cell) do not wait on each other; the lower slice comes first within a cell,
// so the order is stable.
void Octree::sort_by_counting(const float* x, const float* y, const float* z, size_t n) {
  const size_t cells = size_t{1} << (3 * height_);
  if (morton_cell_.size() != cells) {
    morton_cell_.resize(cells);
    const uint32_t mask = (1U << height_) - 1U;
    for (uint32_t cell = 0; cell < cells; ++cell) {
      const uint32_t morton = spread_bits(cell & mask) | spread_bits((cell >> height_) & mask) << 1 |
                              spread_bits(cell >> (2 * height_)) << 2;
      morton_cell_[morton] = static_cast<uint16_t>(cell);
    }
  }
  cell_keys_.resize(n);
  uint16_t* keys = cell_keys_.data();
  cell_keys(grid_, height_, x, y, z, n, keys);

  counts_.assign(kLanes * cells, 0U);
  uint32_t* counts = counts_.data();
  for_each_in_slices(n, [=](size_t lane, size_t i) { ++counts[lane * cells + keys[i]]; });
  cell_first_.resize(cells + 1);
  uint32_t sum = 0;
  for (size_t morton = 0; morton < cells; ++morton) {
    cell_first_[morton] = sum;
    for (size_t lane = 0; lane < kLanes; ++lane) {
      uint32_t& count = counts[lane * cells + morton_cell_[morton]];
      const uint32_t lane_count = count;
      count = sum;  // from here on: where the slice's next point in this cell goes
      sum += lane_count;
    }
  }
  cell_first_[cells] = sum;
  uint32_t* order = order_.data();
  for_each_in_slices(n, [=](size_t lane, size_t i) { order[counts[lane * cells + keys[i]]++] = static_cast<uint32_t>(i); });
}

// LSD radix sort of (Morton key, order) in passes of at most 12 bits (fewer for small clouds);
// the last pass also moves
// the coordinates into sorted order, which saves a separate gather pass.
void Octree::sort_by_radix(const float* x, const float* y, const float* z, size_t n) {
  keys_.resize(n);
  morton_keys(grid_, x, y, z, n, keys_.data());
  for (size_t i = 0; i < n; ++i) order_[i] = static_cast<uint32_t>(i);
  // Digits of about log2(n) bits: one pass over 4096 counters costs more than two passes over
  // 64 when there are only a hundred points.
  const int total_bits = 3 * height_;
  int log2_n = 0;
  while ((size_t{1} << log2_n) < n) ++log2_n;
  const int max_digit_bits = std::clamp(log2_n, 4, 12);
  const int passes = (total_bits + max_digit_bits - 1) / max_digit_bits;
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

// Where each of the 8 child octants of a node starts within its range [first, first + count),
// and bounds[8] = count. Counting sort: straight from the cells' first positions (the node at
// `level` with Morton prefix p covers the cells from p << 3 * (height - level) on); radix sort:
// binary search on the sorted keys.
void Octree::octant_bounds(uint32_t first, uint32_t count, int level, uint32_t cell_prefix, uint32_t bounds[9]) const {
  const int shift = 3 * (height_ - level - 1);
  bounds[8] = count;
  if (counting_) {
    for (uint32_t digit = 0; digit < 8; ++digit) bounds[digit] = cell_first_[(cell_prefix * 8 + digit) << shift] - first;
    return;
  }
  const uint32_t* begin = keys_.data() + first;
  const uint32_t* end = begin + count;
  const uint32_t* at = begin;
  for (uint32_t digit = 0; digit < 8; ++digit) {
    bounds[digit] = static_cast<uint32_t>(at - begin);
    at = std::partition_point(at, end, [&](uint32_t key) { return ((key >> shift) & 7U) <= digit; });
  }
}

// Fills nodes_[index] for the sorted range [first, first + count) at `level` (Morton prefix
// `cell_prefix`), children appended as one contiguous run before any of them is filled;
// returns the node's box.
Box Octree::build_node(uint32_t index, uint32_t first, uint32_t count, int level, uint32_t cell_prefix) {
  Node& node = nodes_[index];
  node.first = first;
  node.count = count;
  node.children = 0;
  node.gathered = !counting_;  // the radix sort moved every coordinate
  if (level == height_ || count <= kLeafPoints) {
    if (node.gathered) {
      node.box = bounding_box(x_.data() + first, y_.data() + first, z_.data() + first, count);
    } else if (count <= kLeafPoints) {
      gather(node);  // a few points: their box is cheaper than the cube's
    } else {
      node.box = cell_box(cell_prefix);
    }
    return node.box;
  }
  uint32_t bounds[9];
  octant_bounds(first, count, level, cell_prefix, bounds);
  uint32_t children = 0;
  for (int d = 0; d < 8; ++d) children += bounds[d + 1] > bounds[d] ? 1 : 0;
  const auto first_child = static_cast<uint32_t>(nodes_.size());
  node.first_child = first_child;
  node.children = children;
  nodes_.resize(nodes_.size() + children);  // capacity kept across frames; `node` is stale from here
  uint32_t child = first_child;
  Box box;
  for (uint32_t d = 0; d < 8; ++d) {
    if (bounds[d + 1] == bounds[d]) continue;
    box.add(build_node(child++, first + bounds[d], bounds[d + 1] - bounds[d], level + 1, cell_prefix * 8 + d));
  }
  nodes_[index].box = box;
  return box;
}

// The leaf cell with this Morton code as a box that holds every point cell_of put in it: its
// cube widened by the grid's rounding slack, cut to the cloud's box (which also closes the
// outer cells, where cell_of clamps).
Box Octree::cell_box(uint32_t morton) const {
  const uint32_t cell = morton_cell_[morton];
  const uint32_t mask = (1U << height_) - 1U;
  const uint32_t index[3] = {cell & mask, (cell >> height_) & mask, cell >> (2 * height_)};
  Box box = grid_.bounds;
  if (grid_.inv_cell == 0.0F) return box;  // every point is in cell 0
  for (int k = 0; k < 3; ++k) {
    const auto c = static_cast<float>(index[k]);
    if (index[k] > 0) box.min[k] = std::max(box.min[k], grid_.origin[k] + c * grid_.cell_m - grid_.slack_m);
    if (index[k] < mask) box.max[k] = std::min(box.max[k], grid_.origin[k] + (c + 1.0F) * grid_.cell_m + grid_.slack_m);
  }
  return box;
}

// Moves a leaf's coordinates into sorted order and makes its box tight.
void Octree::gather(Node& leaf) {
  float x0 = kInf, y0 = kInf, z0 = kInf, x1 = -kInf, y1 = -kInf, z1 = -kInf;
  for (uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) {
    const uint32_t i = order_[k];
    const float x = cloud_x_[i], y = cloud_y_[i], z = cloud_z_[i];
    x_[k] = x;
    y_[k] = y;
    z_[k] = z;
    x0 = x < x0 ? x : x0;  // the NaN-skipping comparisons of bounding_box
    y0 = y < y0 ? y : y0;
    z0 = z < z0 ? z : z0;
    x1 = x > x1 ? x : x1;
    y1 = y > y1 ? y : y1;
    z1 = z > z1 ? z : z1;
  }
  leaf.box.min[0] = x0, leaf.box.min[1] = y0, leaf.box.min[2] = z0;
  leaf.box.max[0] = x1, leaf.box.max[1] = y1, leaf.box.max[2] = z1;
  leaf.gathered = true;
}

void Octree::scan_leaf(uint32_t index, const std::vector<CapsuleBound>& capsules, float max_radius_m, Best& best) {
  Node& leaf = nodes_[index];
  if (!leaf.gathered) gather(leaf);
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
      scan_leaf(entry.node, capsules, max_radius_m, best);
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
