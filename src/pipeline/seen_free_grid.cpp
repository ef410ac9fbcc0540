// SPDX-License-Identifier: Apache-2.0
// hrcsense — the seen-free grid of a cell with several cameras (seen_free_grid.hpp).
//
// Camera side: the cube centres are projected once per pose (prepare_seen_free), so that a
// frame costs one pixel lookup per cube in view; most cubes fall on measured background and
// are free at the first test, and only cubes on foreground or gap pixels follow unknown_space()'s
// per-ray rules. Fused side: the robot's distance to the nearest cube no camera saw free, by
// blocks of 4×4×4 cubes and super-blocks of 4×4×4 blocks bounded from below, nearest bound
// first, so that only blocks that can hold a nearer cube are measured cube by cube.

#include "hrcsense/seen_free_grid.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

namespace hrcsense {
namespace {
namespace seen_free {

// A box whose size is a whole number of cubes but computes as 60.000002 cubes in float is 60
// cubes: remainders below this share of a cube are rounding, not a cube more.
constexpr double kRoundingCubes = 1e-3;
// Cube indices are 32 bits in SeenFreeProjection: a box of 2^31 cubes or more (a 256 MB
// bitset, a mistyped voxel size) has no cubes.
constexpr double kMaxCells = 2147483648.0;
// Block edge in cubes for the distance search, and a super-block's edge in blocks (16 cubes).
constexpr int kBlock = 4;
constexpr int kSuper = 4;
// Cubes per read when the grid's rows are scanned for unknown cubes: whole blocks, ≤ 57 bits.
constexpr int kScanCubes = 12 * kBlock;
static_assert(kScanCubes % kBlock == 0 && kScanCubes <= 57, "a scan reads whole blocks into one word");
// A block is skipped only when its lower bound is this much above the best found: far above
// float rounding at cell scale (~1e-6 m), so a skipped block could never hold a nearer cube.
constexpr float kBoundSlack_m = 1e-4F;

// Distance from point p to segment [a, b].
float point_segment_distance(const Eigen::Vector3f& p, const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  const Eigen::Vector3f ab = b - a;
  const float length_sq = ab.squaredNorm();
  const float t = length_sq > 0.0F ? std::clamp((p - a).dot(ab) / length_sq, 0.0F, 1.0F) : 0.0F;
  return (p - (a + t * ab)).norm();
}

// Pixel i of the filtered frame, for one frame's pass.
struct FrameInputs {
  const uint16_t* raw = nullptr;
  float depth_scale_m = 0.001F;
  int width = 0;
  const float* background_m = nullptr;
  const uint8_t* reliable_bits = nullptr;    ///< null: nothing is reliable
  const uint8_t* foreground_mask = nullptr;  ///< null: no foreground
  const uint8_t* no_depth_frames = nullptr;  ///< null: every gap counts at once
  const RobotPixels* robot_pixels = nullptr;
  double fx_b = 0.0;  ///< px·m: the stereo shadow's width is fx·B·(1/z_robot − 1/z_background)
  float margin_m = 0.0F;
  UnknownSpaceParams params;
};

bool in_envelope_rect(const RobotPixels& r, int u, int v) { return u >= r.u0 && u < r.u1 && v >= r.v0 && v < r.v1; }

// unknown_space()'s stereo shadow: pixel (u, v) lies immediately left of the nearest envelope
// pixel to its right in the row, at most fx·B·(1/z_robot − 1/z_background) + 1 px from it.
bool in_robot_shadow(const FrameInputs& in, size_t i, int u, int v, float background_m) {
  const RobotPixels* robot = in.robot_pixels;
  if (robot == nullptr || v < robot->v0 || v >= robot->v1) return false;
  const size_t row_start = i - static_cast<size_t>(u);
  const int end = std::min(in.width, robot->u1);
  for (int right = std::max(u + 1, robot->u0); right < end; ++right) {
    const uint16_t from_raw = robot->from_raw[row_start + static_cast<size_t>(right)];
    if (from_raw == 0) continue;
    const float z_robot_m = static_cast<float>(from_raw) * in.depth_scale_m;
    if (!(background_m > z_robot_m)) return false;
    const double shadow_px = in.fx_b * (1.0 / z_robot_m - 1.0 / background_m);
    return right - u <= static_cast<int>(std::ceil(shadow_px)) + 1;
  }
  return false;
}

// True when depth z_m on the ray of pixel i lies on one of its unknown segments (widened by the
// margin at both ends); the pixel is foreground or has no depth (the caller's fast path took
// the measured background).
bool on_unknown_segment(const FrameInputs& in, size_t i, float z_m) {
  const int u = static_cast<int>(i % static_cast<size_t>(in.width));
  const int v = static_cast<int>(i / static_cast<size_t>(in.width));
  // The robot's own envelope is never unknown (the arm must not freeze itself).
  if (in.robot_pixels != nullptr && in_envelope_rect(*in.robot_pixels, u, v) && in.robot_pixels->from_raw[i] != 0) {
    return false;
  }
  const float background_m = in.background_m[i];
  if (in.raw[i] != 0) {  // foreground: hidden behind it, from its depth to the background
    const float d_m = static_cast<float>(in.raw[i]) * in.depth_scale_m;
    return background_m > d_m && z_m >= d_m - in.margin_m && z_m <= background_m + in.margin_m;
  }
  const bool reliable = in.reliable_bits != nullptr && ((in.reliable_bits[i / 8] >> (i % 8)) & 1U) != 0;
  // No depth where the background was not reliable: taught that way and exempt, as per ray;
  // with no background at all, nothing along the ray was ever seen.
  if (!reliable) return !(background_m > 0.0F);
  if (in_robot_shadow(in, i, u, v, background_m)) return false;
  if (in.no_depth_frames != nullptr && in.no_depth_frames[i] < in.params.min_no_depth_frames) return false;
  return background_m > in.params.near_m && z_m <= background_m + in.margin_m;
}

// Bits of cubes first .. first + count − 1 of one grid row (bit k: cube first + k), set where the
// cube is unknown (bit 0 in the grid); count ≤ 57, so that the bits fit one word after the shift.
uint64_t unknown_bits(const SeenFreeGrid& grid, size_t first, int count) {
  const size_t byte = first / 8;
  const uint8_t* bytes = grid.bytes.data() + byte;
  uint64_t word = 0;
  if (byte + 8 <= grid.bytes.size()) {  // a fixed count: one load
    for (size_t k = 0; k < 8; ++k) word |= uint64_t{bytes[k]} << (8 * k);
  } else {
    for (size_t k = 0; byte + k < grid.bytes.size(); ++k) word |= uint64_t{bytes[k]} << (8 * k);
  }
  return ~(word >> (first % 8)) & ((uint64_t{1} << count) - 1U);
}

// The unknown cubes of one block, bit lx + 4·ly + 16·lz.
struct Block {
  Eigen::Vector3i first = Eigen::Vector3i::Zero();  ///< its first cube's grid coordinates
  uint64_t unknown = 0;
  Eigen::Vector3f centre_base = Eigen::Vector3f::Zero();  ///< the middle of its cube centres
};

Block block_at(const SeenFreeGridSpec& spec, const Eigen::Vector3i& n, const SeenFreeGrid& grid,
               const Eigen::Vector3i& first) {
  Block block;
  block.first = first;
  const Eigen::Vector3i count = (n - first).cwiseMin(kBlock);
  for (int lz = 0; lz < count.z(); ++lz) {
    for (int ly = 0; ly < count.y(); ++ly) {
      const size_t cell = static_cast<size_t>(first.x()) +
                          static_cast<size_t>(n.x()) * (static_cast<size_t>(first.y() + ly) +
                                                        static_cast<size_t>(n.y()) * static_cast<size_t>(first.z() + lz));
      block.unknown |= unknown_bits(grid, cell, count.x()) << (kBlock * ly + kBlock * kBlock * lz);
    }
  }
  const Eigen::Vector3f middle_cubes = first.cast<float>() + 0.5F * count.cast<float>();
  block.centre_base = spec.box_base.min() + spec.voxel_m * middle_cubes;
  return block;
}

// Lower bound of the distance from any cube centre of a block (within radius_m of its centre)
// to capsule c's surface.
float block_bound(const Block& block, const Capsule& c, float radius_m) {
  return std::max(0.0F, point_segment_distance(block.centre_base, c.a, c.b) - c.radius_m - radius_m);
}

// Lower bound of the distance from any point within radius_m of centre_base to the robot's surface.
float robot_bound(const Eigen::Vector3f& centre_base, const RobotModel& robot, float radius_m) {
  float bound = std::numeric_limits<float>::infinity();
  for (const Capsule& c : robot.capsules) {
    bound = std::min(bound, std::max(0.0F, point_segment_distance(centre_base, c.a, c.b) - c.radius_m - radius_m));
  }
  return bound;
}

// Lowers best_m to the distance of the block's unknown cubes outside the capsules. A capsule
// whose bound is above best_m is left out: its surface is farther than best_m from every cube
// of the block, and the cubes lie outside it (the bound is > 0).
void measure_block(const SeenFreeGridSpec& spec, const Block& block, const RobotModel& robot, float radius_m,
                   float& best_m) {
  // The capsules near enough to matter, by index (no allocation on the search's path); a robot
  // of more capsules than fit is measured against all of them.
  constexpr size_t kMaxNear = 64;
  size_t near[kMaxNear];
  const bool all = robot.capsules.size() > kMaxNear;
  size_t capsules = robot.capsules.size();
  if (!all) {
    capsules = 0;
    for (size_t k = 0; k < robot.capsules.size(); ++k) {
      if (block_bound(block, robot.capsules[k], radius_m) <= best_m + kBoundSlack_m) near[capsules++] = k;
    }
  }
  for (uint64_t todo = block.unknown; todo != 0; todo &= todo - 1) {
    const int bit = __builtin_ctzll(todo);
    const Eigen::Vector3i local(bit % kBlock, (bit / kBlock) % kBlock, bit / (kBlock * kBlock));
    const Eigen::Vector3f centre_base =
        spec.box_base.min() + spec.voxel_m * ((block.first + local).cast<float>() + Eigen::Vector3f::Constant(0.5F));
    float cube_m = std::numeric_limits<float>::infinity();
    bool inside = false;
    for (size_t k = 0; k < capsules && !inside; ++k) {
      const Capsule& c = robot.capsules[all ? k : near[k]];
      const float axis_m = point_segment_distance(centre_base, c.a, c.b);
      inside = axis_m < c.radius_m;  // the robot's own volume
      cube_m = std::min(cube_m, std::max(0.0F, axis_m - c.radius_m));
    }
    if (!inside) best_m = std::min(best_m, cube_m);
  }
}

}  // namespace seen_free
}  // namespace

Eigen::Vector3i SeenFreeGridSpec::dims() const {
  if (!(voxel_m > 0.0F) || !std::isfinite(voxel_m) || box_base.isEmpty()) return Eigen::Vector3i::Zero();
  Eigen::Vector3d cubes;
  for (int a = 0; a < 3; ++a) {
    const double size_m = static_cast<double>(box_base.max()[a]) - static_cast<double>(box_base.min()[a]);
    cubes[a] = std::isfinite(size_m) ? std::max(0.0, std::ceil(size_m / voxel_m - seen_free::kRoundingCubes)) : 0.0;
  }
  if (cubes.prod() >= seen_free::kMaxCells) return Eigen::Vector3i::Zero();
  return cubes.cast<int>();
}

size_t SeenFreeGridSpec::cell_count() const {
  if (!enabled) return 0;
  const Eigen::Vector3i n = dims();
  return static_cast<size_t>(n.x()) * static_cast<size_t>(n.y()) * static_cast<size_t>(n.z());
}

Eigen::Vector3f SeenFreeGridSpec::centre(size_t index) const {
  const Eigen::Vector3i n = dims();
  const size_t nx = static_cast<size_t>(std::max(1, n.x())), ny = static_cast<size_t>(std::max(1, n.y()));
  const Eigen::Vector3f cube(static_cast<float>(index % nx), static_cast<float>((index / nx) % ny),
                             static_cast<float>(index / (nx * ny)));
  return box_base.min() + voxel_m * (cube + Eigen::Vector3f::Constant(0.5F));
}

bool SeenFreeProjection::matches(const SeenFreeGridSpec& s, const Intrinsics& in, const Pose& pose,
                                 float near_limit_m) const {
  return s.enabled == spec.enabled && s.box_base.min() == spec.box_base.min() &&
         s.box_base.max() == spec.box_base.max() && s.voxel_m == spec.voxel_m && in.width == intrinsics.width &&
         in.height == intrinsics.height && in.fx == intrinsics.fx && in.fy == intrinsics.fy &&
         in.ppx == intrinsics.ppx && in.ppy == intrinsics.ppy && pose.matrix() == T_base_camera.matrix() &&
         near_limit_m == near_m;
}

SeenFreeProjection prepare_seen_free(const SeenFreeGridSpec& spec, const Intrinsics& intrinsics,
                                     const Pose& T_base_camera, float near_m) {
  SeenFreeProjection p;
  p.spec = spec;
  p.intrinsics = intrinsics;
  p.T_base_camera = T_base_camera;
  p.near_m = near_m;
  p.cell_count = spec.cell_count();
  if (p.cell_count == 0 || intrinsics.width <= 0 || intrinsics.height <= 0) return p;
  const Pose T_camera_base = T_base_camera.inverse();
  const double width = intrinsics.width, height = intrinsics.height;
  for (size_t cell = 0; cell < p.cell_count; ++cell) {
    const Eigen::Vector3d centre_camera = T_camera_base * spec.centre(cell).cast<double>();
    const double z_m = centre_camera.z();
    if (!(z_m >= near_m)) continue;  // behind the camera or too near to be measured
    // The pixel whose centre is nearest: unknown_space()'s ray through (u, v) has x = (u − ppx)/fx.
    const double u = std::floor(intrinsics.fx * centre_camera.x() / z_m + intrinsics.ppx + 0.5);
    const double v = std::floor(intrinsics.fy * centre_camera.y() / z_m + intrinsics.ppy + 0.5);
    if (!(u >= 0.0 && u < width && v >= 0.0 && v < height)) continue;
    p.cubes.push_back({static_cast<uint32_t>(cell), static_cast<uint32_t>(v * width + u), static_cast<float>(z_m)});
  }
  std::sort(p.cubes.begin(), p.cubes.end(), [](const SeenFreeProjection::Cube& a, const SeenFreeProjection::Cube& b) {
    return a.pixel != b.pixel ? a.pixel < b.pixel : a.cell < b.cell;
  });
  return p;
}

float seen_free_margin_m(const SeenFreeGridSpec& spec) { return spec.voxel_m * 0.5F * std::sqrt(3.0F); }

void mark_seen_free(const SeenFreeProjection& projection, const DepthImage& depth, const BackgroundModel& background,
                    const ReliableBackground& reliable, const std::vector<uint8_t>& foreground_mask,
                    const RobotPixels* robot_pixels, float stereo_baseline_m, const std::vector<uint8_t>& no_depth_frames,
                    const UnknownSpaceParams& params, SeenFreeGrid& out) {
  out.reset(projection.cell_count);
  const size_t n = depth.pixels.size();
  if (projection.cubes.empty() || depth.width != projection.intrinsics.width ||
      depth.height != projection.intrinsics.height || n != static_cast<size_t>(depth.width) * depth.height ||
      background.mean_m.size() != n) {
    return;
  }
  seen_free::FrameInputs in;
  in.raw = depth.pixels.data();
  in.depth_scale_m = depth.depth_scale_m;
  in.width = depth.width;
  in.background_m = background.mean_m.data();
  in.reliable_bits = reliable.pixels == n && reliable.bits.size() >= (n + 7) / 8 ? reliable.bits.data() : nullptr;
  in.foreground_mask = foreground_mask.size() == n ? foreground_mask.data() : nullptr;
  in.no_depth_frames = no_depth_frames.size() == n ? no_depth_frames.data() : nullptr;
  in.robot_pixels = robot_pixels;
  in.fx_b = static_cast<double>(projection.intrinsics.fx) * stereo_baseline_m;
  in.margin_m = seen_free_margin_m(projection.spec);
  in.params = params;
  uint8_t* bytes = out.bytes.data();
  for (const SeenFreeProjection::Cube& cube : projection.cubes) {
    const size_t i = cube.pixel;
    // Measured and not foreground: background, or something the foreground does not count; no
    // ray of it is unknown, so neither is any depth along it (in front, at, or behind it).
    const bool measured = in.raw[i] != 0 && (in.foreground_mask == nullptr || in.foreground_mask[i] == 0);
    if (measured || !seen_free::on_unknown_segment(in, i, cube.z_m)) {
      bytes[cube.cell >> 3] = static_cast<uint8_t>(bytes[cube.cell >> 3] | (1U << (cube.cell & 7)));
    }
  }
}

void unite(SeenFreeGrid& into, const SeenFreeGrid& other) {
  if (into.cells != other.cells || into.bytes.size() != other.bytes.size()) {
    throw std::invalid_argument("seen-free grids of different cell counts cannot be united");
  }
  // Through plain pointers: a byte store through the vector could alias its own pointers, which
  // keeps the compiler from vectorising the loop (about 9 instructions a byte instead of < 1).
  uint8_t* to = into.bytes.data();
  const uint8_t* from = other.bytes.data();
  const size_t count = into.bytes.size();
  for (size_t b = 0; b < count; ++b) to[b] = static_cast<uint8_t>(to[b] | from[b]);
}

// Best first, on two levels, so that the blocks measured cube by cube are the few that can hold
// the nearest unknown cube: one scan of the grid's rows marks the blocks holding an unknown cube;
// the super-blocks holding one are taken in the order of their lower bound, and within each its
// blocks in the order of theirs; whatever's bound is above the best found so far is skipped, and
// once a super-block's bound is, so is every later one.
float unknown_cells_distance_m(const SeenFreeGridSpec& spec, const SeenFreeGrid& union_bits, const RobotModel& robot,
                               UnknownDistanceScratch& scratch) {
  using seen_free::kBlock;
  using seen_free::kBoundSlack_m;
  using seen_free::kSuper;
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const size_t cells = spec.cell_count();
  if (cells == 0 || robot.capsules.empty() || union_bits.cells != cells ||
      union_bits.bytes.size() < (cells + 7) / 8) {
    return kNaN;
  }
  const Eigen::Vector3i n = spec.dims();
  const Eigen::Vector3i blocks = (n.array() + kBlock - 1) / kBlock;
  const Eigen::Vector3i supers = (blocks.array() + kSuper - 1) / kSuper;
  const auto block_index = [&](int bx, int by, int bz) {
    return static_cast<size_t>(bx) + static_cast<size_t>(blocks.x()) * (static_cast<size_t>(by) +
                                                                        static_cast<size_t>(blocks.y()) * static_cast<size_t>(bz));
  };

  // The blocks holding an unknown cube, from the rows' bits (a block's cubes of a row are one nibble).
  std::vector<uint8_t>& has_unknown = scratch.block_has_unknown;
  has_unknown.assign(static_cast<size_t>(blocks.prod()), 0);
  for (int z = 0; z < n.z(); ++z) {
    for (int y = 0; y < n.y(); ++y) {
      const size_t row = static_cast<size_t>(n.x()) * (static_cast<size_t>(y) + static_cast<size_t>(n.y()) * static_cast<size_t>(z));
      for (int x0 = 0; x0 < n.x(); x0 += seen_free::kScanCubes) {
        uint64_t bits = seen_free::unknown_bits(union_bits, row + static_cast<size_t>(x0), std::min(seen_free::kScanCubes, n.x() - x0));
        while (bits != 0) {
          const int k = __builtin_ctzll(bits);
          has_unknown[block_index((x0 + k) / kBlock, y / kBlock, z / kBlock)] = 1;
          bits &= ~(((uint64_t{1} << kBlock) - 1U) << (k - k % kBlock));  // the rest of its block
        }
      }
    }
  }

  // The super-blocks holding an unknown cube, by lower bound.
  const float block_radius_m = 0.5F * static_cast<float>(kBlock - 1) * std::sqrt(3.0F) * spec.voxel_m;
  const float super_radius_m = 0.5F * static_cast<float>(kBlock * kSuper - 1) * std::sqrt(3.0F) * spec.voxel_m;
  auto& order = scratch.super_blocks;
  order.clear();
  for (int sz = 0; sz < supers.z(); ++sz) {
    for (int sy = 0; sy < supers.y(); ++sy) {
      for (int sx = 0; sx < supers.x(); ++sx) {
        const Eigen::Vector3i first_block = Eigen::Vector3i(sx, sy, sz) * kSuper;
        const Eigen::Vector3i end_block = (first_block.array() + kSuper).min(blocks.array());
        bool any = false;
        for (int bz = first_block.z(); bz < end_block.z() && !any; ++bz) {
          for (int by = first_block.y(); by < end_block.y() && !any; ++by) {
            for (int bx = first_block.x(); bx < end_block.x() && !any; ++bx) any = has_unknown[block_index(bx, by, bz)] != 0;
          }
        }
        if (!any) continue;
        const Eigen::Vector3i first_cube = first_block * kBlock, end_cube = (end_block * kBlock).cwiseMin(n);
        const Eigen::Vector3f middle_base = spec.box_base.min() + spec.voxel_m * 0.5F * (first_cube + end_cube).cast<float>();
        order.emplace_back(seen_free::robot_bound(middle_base, robot, super_radius_m),
                           static_cast<uint32_t>(sx + supers.x() * (sy + supers.y() * sz)));
      }
    }
  }
  if (order.empty()) return kNaN;  // every cube free
  std::sort(order.begin(), order.end());

  float best_m = std::numeric_limits<float>::infinity();
  struct Candidate {
    float bound_m;
    seen_free::Block block;
  };
  std::array<Candidate, static_cast<size_t>(kSuper * kSuper * kSuper)> candidates;
  for (const auto& [super_bound_m, super_index] : order) {
    if (super_bound_m > best_m + kBoundSlack_m) break;  // and so is every later one
    const int s = static_cast<int>(super_index);
    const Eigen::Vector3i first_block =
        Eigen::Vector3i(s % supers.x(), (s / supers.x()) % supers.y(), s / (supers.x() * supers.y())) * kSuper;
    const Eigen::Vector3i end_block = (first_block.array() + kSuper).min(blocks.array());
    size_t count = 0;
    for (int bz = first_block.z(); bz < end_block.z(); ++bz) {
      for (int by = first_block.y(); by < end_block.y(); ++by) {
        for (int bx = first_block.x(); bx < end_block.x(); ++bx) {
          if (has_unknown[block_index(bx, by, bz)] == 0) continue;
          const seen_free::Block block = seen_free::block_at(spec, n, union_bits, Eigen::Vector3i(bx, by, bz) * kBlock);
          const float bound_m = seen_free::robot_bound(block.centre_base, robot, block_radius_m);
          if (bound_m <= best_m + kBoundSlack_m) candidates[count++] = {bound_m, block};
        }
      }
    }
    std::sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(count),
              [](const Candidate& a, const Candidate& b) { return a.bound_m < b.bound_m; });
    for (size_t c = 0; c < count && candidates[c].bound_m <= best_m + kBoundSlack_m; ++c) {
      seen_free::measure_block(spec, candidates[c].block, robot, block_radius_m, best_m);
    }
  }
  return std::isfinite(best_m) ? best_m : kNaN;
}

float unknown_cells_distance_m(const SeenFreeGridSpec& spec, const SeenFreeGrid& union_bits, const RobotModel& robot) {
  UnknownDistanceScratch scratch;
  return unknown_cells_distance_m(spec, union_bits, robot, scratch);
}

}  // namespace hrcsense
