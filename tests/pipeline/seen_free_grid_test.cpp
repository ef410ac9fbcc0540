// SPDX-License-Identifier: Apache-2.0
// The seen-free grid (seen_free_grid.hpp) on scenes laid out by hand: a 160×120 pinhole camera
// at the base origin looking along base z (fx = fy = 100, principal point (80, 60)) at a flat
// wall 3 m away. A cube centre (x, y, z) falls in pixel (80 + 100·x/z, 60 + 100·y/z); the
// cubes picked below have x/z and y/z multiples of 0.05, so that their pixels are whole
// numbers, far from any rounding boundary. The margin is half a cube's diagonal.

#include "hrcsense/robot.hpp"
#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/unknown_space.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace hrcsense {
namespace {

constexpr int kWidth = 160, kHeight = 120;

Capsule make_capsule(Eigen::Vector3f a, Eigen::Vector3f b, float radius_m) {
  Capsule c;
  c.a = a;
  c.b = b;
  c.radius_m = radius_m;
  return c;
}

// One camera's frame and everything mark_seen_free reads, the wall at 3 m everywhere.
struct Scene {
  Intrinsics intrinsics;
  Pose T_base_camera = Pose::Identity();
  DepthImage depth;
  BackgroundModel background;
  std::vector<uint8_t> foreground_mask;
  std::vector<uint8_t> no_depth_frames;
  std::vector<uint16_t> envelope_from_raw, envelope_to_raw;
  float stereo_baseline_m = 0.0F;

  Scene() {
    intrinsics.width = kWidth;
    intrinsics.height = kHeight;
    intrinsics.fx = intrinsics.fy = 100.0F;
    intrinsics.ppx = 80.0F;
    intrinsics.ppy = 60.0F;
    depth.resize(kWidth, kHeight);
    depth.pixels.assign(depth.pixels.size(), 3000);
    const size_t n = depth.pixels.size();
    background.width = kWidth;
    background.height = kHeight;
    background.mean_m.assign(n, 3.0F);
    background.spread_m.assign(n, 0.005F);
    background.valid_ratio.assign(n, 1.0F);
    foreground_mask.assign(n, 0);
    no_depth_frames.assign(n, 0);
    envelope_from_raw.assign(n, 0);
    envelope_to_raw.assign(n, 0);
  }
  size_t at(int u, int v) const { return static_cast<size_t>(v) * kWidth + static_cast<size_t>(u); }
  // Pixels u in [u0, u1], v in [v0, v1] (inclusive) seen at depth_m in front of the wall.
  void foreground(int u0, int u1, int v0, int v1, uint16_t raw) {
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        depth.pixels[at(u, v)] = raw;
        foreground_mask[at(u, v)] = 1;
      }
    }
  }
  // Pixels without depth for `frames` frames in a row.
  void hole(int u0, int u1, int v0, int v1, uint8_t frames) {
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        depth.pixels[at(u, v)] = 0;
        no_depth_frames[at(u, v)] = frames;
      }
    }
  }
  SeenFreeGrid mark(const SeenFreeGridSpec& spec, bool with_envelope = false) const {
    RobotPixels robot;
    robot.from_raw = envelope_from_raw.data();
    robot.to_raw = envelope_to_raw.data();
    SeenFreeGrid grid;
    mark_seen_free(prepare_seen_free(spec, intrinsics, T_base_camera, UnknownSpaceParams{}.near_m), depth, background,
                   reliable_background(background, UnknownSpaceParams{}.min_valid_ratio), foreground_mask,
                   with_envelope ? &robot : nullptr, stereo_baseline_m, no_depth_frames, UnknownSpaceParams{}, grid);
    return grid;
  }
};

// The grid of the wall tests: cube centres x = −1.0 … 1.0, y = −0.5 … 0.5, z = 1.0 … 3.9 (0.1 m).
SeenFreeGridSpec wall_spec() {
  SeenFreeGridSpec spec;
  spec.enabled = true;
  spec.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(-1.05F, -0.55F, 0.95F), Eigen::Vector3f(1.05F, 0.55F, 3.95F));
  spec.voxel_m = 0.1F;
  return spec;
}

// The cube whose centre is (x, y, z) in the base frame.
size_t cell_at(const SeenFreeGridSpec& spec, float x, float y, float z) {
  const Eigen::Vector3i n = spec.dims();
  const Eigen::Vector3f cube = (Eigen::Vector3f(x, y, z) - spec.box_base.min()) / spec.voxel_m;
  const auto index = [](float c) { return static_cast<size_t>(std::lround(c - 0.5F)); };
  const size_t cell = index(cube.x()) + static_cast<size_t>(n.x()) * (index(cube.y()) + static_cast<size_t>(n.y()) * index(cube.z()));
  EXPECT_LT((spec.centre(cell) - Eigen::Vector3f(x, y, z)).norm(), 1e-5F);
  return cell;
}

bool seen_free(const SeenFreeGridSpec& spec, const SeenFreeGrid& grid, float x, float y, float z) {
  return grid.test(cell_at(spec, x, y, z));
}

// Brute force: every unknown cube outside the capsules, against every capsule.
float brute_distance_m(const SeenFreeGridSpec& spec, const SeenFreeGrid& grid, const RobotModel& robot) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t cell = 0; cell < spec.cell_count(); ++cell) {
    if (grid.test(cell)) continue;
    const Eigen::Vector3d p = spec.centre(cell).cast<double>();
    double cube = std::numeric_limits<double>::infinity();
    bool inside = false;
    for (const Capsule& c : robot.capsules) {
      const Eigen::Vector3d a = c.a.cast<double>(), ab = c.b.cast<double>() - a;
      const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
      const double axis = (p - (a + t * ab)).norm();
      inside = inside || axis < c.radius_m;
      cube = std::min(cube, std::max(0.0, axis - c.radius_m));
    }
    if (!inside) best = std::min(best, cube);
  }
  return std::isfinite(best) ? static_cast<float>(best) : std::numeric_limits<float>::quiet_NaN();
}

TEST(SeenFreeGrid, SpecCutsTheBoxIntoCubes) {
  SeenFreeGridSpec spec;  // the default: 3 × 3 × 2 m from (−1.5, −1.5, 0) at 0.05 m
  EXPECT_EQ(spec.dims(), Eigen::Vector3i(60, 60, 40));
  EXPECT_EQ(spec.cell_count(), 0U);  // disabled
  spec.enabled = true;
  EXPECT_EQ(spec.cell_count(), 144000U);
  EXPECT_TRUE(spec.centre(0).isApprox(Eigen::Vector3f(-1.475F, -1.475F, 0.025F)));
  EXPECT_TRUE(spec.centre(1).isApprox(Eigen::Vector3f(-1.425F, -1.475F, 0.025F)));   // x fastest
  EXPECT_TRUE(spec.centre(60).isApprox(Eigen::Vector3f(-1.475F, -1.425F, 0.025F)));  // then y
  EXPECT_TRUE(spec.centre(3600).isApprox(Eigen::Vector3f(-1.475F, -1.475F, 0.075F)));
  EXPECT_TRUE(spec.centre(143999).isApprox(Eigen::Vector3f(1.475F, 1.475F, 1.975F)));
  // A remainder is a cube more: 1.02 m at 0.05 is 21 cubes.
  spec.box_base = Eigen::AlignedBox3f(Eigen::Vector3f::Zero(), Eigen::Vector3f(1.02F, 1.0F, 0.05F));
  EXPECT_EQ(spec.dims(), Eigen::Vector3i(21, 20, 1));
  spec.voxel_m = 0.0F;
  EXPECT_EQ(spec.cell_count(), 0U);
  EXPECT_NEAR(seen_free_margin_m(wall_spec()), 0.1 * std::sqrt(3.0) / 2.0, 1e-7);
}

TEST(SeenFreeGrid, AWallFreesItsFrontAndBackAndTheFrustumBoundsIt) {
  const Scene scene;
  const SeenFreeGridSpec spec = wall_spec();
  const SeenFreeGrid grid = scene.mark(spec);
  ASSERT_EQ(grid.cells, 21U * 11U * 30U);
  EXPECT_TRUE(seen_free(spec, grid, 0.0F, 0.0F, 1.5F));  // in front of the wall
  EXPECT_TRUE(seen_free(spec, grid, 0.5F, 0.0F, 2.9F));
  EXPECT_TRUE(seen_free(spec, grid, 0.5F, 0.0F, 3.0F));  // at it: a measured surface is no unknown ray
  EXPECT_TRUE(seen_free(spec, grid, 0.5F, 0.0F, 3.5F));  // behind it: static, nobody stands there
  // Out of the frustum: at z = 1 the image spans x/z in [−0.805, 0.795).
  EXPECT_FALSE(seen_free(spec, grid, -1.0F, 0.0F, 1.0F));
  EXPECT_FALSE(seen_free(spec, grid, 0.8F, 0.0F, 1.0F));
  EXPECT_TRUE(seen_free(spec, grid, 0.7F, 0.0F, 1.0F));
  EXPECT_TRUE(seen_free(spec, grid, -1.0F, 0.0F, 2.0F));  // u = 30 at z = 2
  EXPECT_TRUE(seen_free(spec, grid, 0.0F, -0.5F, 1.0F));  // v = 10: in view
}

TEST(SeenFreeGrid, ForegroundHidesTheCubesBehindIt) {
  Scene scene;
  scene.foreground(75, 85, 55, 65, 2000);  // something at 2 m around the optical axis
  const SeenFreeGridSpec spec = wall_spec();
  const SeenFreeGrid grid = scene.mark(spec);
  // Unknown from 2 − 0.0866 m to 3 + 0.0866 m along pixel (80, 60).
  EXPECT_TRUE(seen_free(spec, grid, 0.0F, 0.0F, 1.5F));
  EXPECT_TRUE(seen_free(spec, grid, 0.0F, 0.0F, 1.9F));  // 1.9 < 1.913: wholly in front
  EXPECT_FALSE(seen_free(spec, grid, 0.0F, 0.0F, 2.0F));
  EXPECT_FALSE(seen_free(spec, grid, 0.0F, 0.0F, 2.5F));
  EXPECT_FALSE(seen_free(spec, grid, 0.0F, 0.0F, 3.0F));
  EXPECT_TRUE(seen_free(spec, grid, 0.0F, 0.0F, 3.1F));  // 3.1 > 3.087: inside the wall
  EXPECT_FALSE(seen_free(spec, grid, 0.1F, 0.1F, 2.0F));  // pixel (85, 65), the box's corner
  EXPECT_TRUE(seen_free(spec, grid, 0.2F, 0.0F, 2.0F));   // pixel (90, 60): the wall
}

TEST(SeenFreeGrid, AGapOverAReliableBackgroundIsUnknownUpToIt) {
  Scene scene;
  scene.hole(57, 63, 47, 53, 5);  // pixel (60, 50): x/z = −0.2, y/z = −0.1
  const SeenFreeGridSpec spec = wall_spec();
  const SeenFreeGrid grid = scene.mark(spec);
  EXPECT_FALSE(seen_free(spec, grid, -0.2F, -0.1F, 1.0F));
  EXPECT_FALSE(seen_free(spec, grid, -0.4F, -0.2F, 2.0F));
  EXPECT_FALSE(seen_free(spec, grid, -0.6F, -0.3F, 3.0F));  // at the background, within the margin
  EXPECT_TRUE(seen_free(spec, grid, -0.6F, 0.0F, 3.0F));    // pixel (60, 60): the wall
  // A fresh gap is the sensor's dropout: free, as per ray.
  scene.hole(57, 63, 47, 53, 2);
  EXPECT_TRUE(seen_free(spec, scene.mark(spec), -0.4F, -0.2F, 2.0F));
  // Over a background that was never reliable: exempt, as per ray ...
  scene.hole(57, 63, 47, 53, 5);
  for (int v = 47; v <= 53; ++v) {
    for (int u = 57; u <= 63; ++u) scene.background.valid_ratio[scene.at(u, v)] = 0.5F;
  }
  EXPECT_TRUE(seen_free(spec, scene.mark(spec), -0.4F, -0.2F, 2.0F));
  // ... but with no background at all nothing along the ray was ever seen.
  for (int v = 47; v <= 53; ++v) {
    for (int u = 57; u <= 63; ++u) scene.background.mean_m[scene.at(u, v)] = 0.0F;
  }
  const SeenFreeGrid never_seen = scene.mark(spec);
  EXPECT_FALSE(seen_free(spec, never_seen, -0.4F, -0.2F, 2.0F));
  EXPECT_FALSE(seen_free(spec, never_seen, -0.6F, -0.3F, 3.0F));
}

TEST(SeenFreeGrid, TheRobotsEnvelopeAndItsStereoShadowAreNeverUnknown) {
  Scene scene;
  // The arm at 1.0–1.2 m over columns 101–120 (its pixels lost their depth), a gap left of it.
  for (int v = 40; v <= 80; ++v) {
    for (int u = 101; u <= 120; ++u) {
      scene.envelope_from_raw[scene.at(u, v)] = 1000;
      scene.envelope_to_raw[scene.at(u, v)] = 1200;
    }
  }
  scene.hole(90, 120, 40, 80, 5);
  scene.stereo_baseline_m = 0.05F;  // shadow: 100·0.05·(1/1 − 1/3) = 3.3 → 4 + 1 = 5 px, columns 96–100
  const SeenFreeGridSpec spec = wall_spec();
  const SeenFreeGrid grid = scene.mark(spec, true);
  EXPECT_TRUE(seen_free(spec, grid, 0.3F, 0.0F, 1.0F));   // column 110: the envelope
  EXPECT_TRUE(seen_free(spec, grid, 0.4F, 0.0F, 1.0F));   // column 120
  EXPECT_TRUE(seen_free(spec, grid, 0.2F, 0.0F, 1.0F));   // column 100: shadow
  EXPECT_TRUE(seen_free(spec, grid, 0.4F, 0.0F, 2.0F));   // column 100 farther along
  EXPECT_FALSE(seen_free(spec, grid, 0.3F, 0.0F, 2.0F));  // column 95: 6 px from the arm
  EXPECT_FALSE(seen_free(spec, grid, 0.2F, 0.0F, 2.0F));  // column 90
  // Without the envelope every one of them is an ordinary gap.
  const SeenFreeGrid without = scene.mark(spec, false);
  EXPECT_FALSE(seen_free(spec, without, 0.3F, 0.0F, 1.0F));
  EXPECT_FALSE(seen_free(spec, without, 0.2F, 0.0F, 1.0F));
}

TEST(SeenFreeGrid, DistanceToAHandPlacedCube) {
  SeenFreeGridSpec spec;
  spec.enabled = true;
  spec.box_base = Eigen::AlignedBox3f(Eigen::Vector3f::Zero(), Eigen::Vector3f(1.0F, 1.0F, 1.0F));
  spec.voxel_m = 0.1F;  // centres 0.05 … 0.95
  RobotModel robot;
  robot.capsules.push_back(make_capsule({0.05F, 0.05F, 0.05F}, {0.05F, 0.05F, 0.95F}, 0.1F));
  SeenFreeGrid grid;
  grid.reset(spec.cell_count());
  for (size_t i = 0; i < grid.cells; ++i) grid.set(i);
  EXPECT_TRUE(std::isnan(unknown_cells_distance_m(spec, grid, robot)));  // every cube free
  // A cube on the capsule's axis is the robot's own: left out.
  SeenFreeGrid inside;
  inside.reset(spec.cell_count());
  for (size_t i = 0; i < inside.cells; ++i) inside.set(i);
  const size_t axis_cell = cell_at(spec, 0.05F, 0.05F, 0.35F);
  inside.bytes[axis_cell / 8] = static_cast<uint8_t>(inside.bytes[axis_cell / 8] & ~(1U << (axis_cell % 8)));
  EXPECT_TRUE(std::isnan(unknown_cells_distance_m(spec, inside, robot)));
  // (0.55, 0.15, 0.35) is √(0.5² + 0.1²) from the axis: 0.5099 − 0.1.
  const size_t cell = cell_at(spec, 0.55F, 0.15F, 0.35F);
  inside.bytes[cell / 8] = static_cast<uint8_t>(inside.bytes[cell / 8] & ~(1U << (cell % 8)));
  EXPECT_NEAR(unknown_cells_distance_m(spec, inside, robot), std::sqrt(0.26) - 0.1, 1e-6);
  // Without capsules, or for a grid of another size, there is no distance.
  EXPECT_TRUE(std::isnan(unknown_cells_distance_m(spec, inside, RobotModel{})));
  SeenFreeGrid other_size;
  other_size.reset(10);
  EXPECT_TRUE(std::isnan(unknown_cells_distance_m(spec, other_size, robot)));
}

TEST(SeenFreeGrid, DistanceMatchesBruteForceOnRandomGrids) {
  SeenFreeGridSpec spec;
  spec.enabled = true;
  spec.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(-1.0F, -0.8F, 0.0F), Eigen::Vector3f(1.0F, 0.9F, 1.3F));
  spec.voxel_m = 0.07F;  // 29 × 25 × 19: partial blocks on every axis
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coord(-1.2F, 1.2F), radius(0.0F, 0.2F), share(0.0F, 1.0F);
  for (int trial = 0; trial < 40; ++trial) {
    RobotModel robot;
    const int capsules = 1 + trial % 8;
    for (int c = 0; c < capsules; ++c) {
      robot.capsules.push_back(make_capsule({coord(rng), coord(rng), coord(rng) + 0.6F},
                                            {coord(rng), coord(rng), coord(rng) + 0.6F}, radius(rng)));
    }
    const float free_share = trial < 10 ? 0.5F : 0.999F;  // dense unknown, then a few cubes
    SeenFreeGrid grid;
    grid.reset(spec.cell_count());
    for (size_t i = 0; i < grid.cells; ++i) {
      if (share(rng) < free_share) grid.set(i);
    }
    const float expected = brute_distance_m(spec, grid, robot);
    const float fast = unknown_cells_distance_m(spec, grid, robot);
    if (std::isnan(expected)) {
      EXPECT_TRUE(std::isnan(fast)) << trial;
    } else {
      EXPECT_NEAR(fast, expected, 1e-5) << trial;
    }
  }
}

// A UR5 (padded 0.05 m) in random poses over grids where a few boxes of space (people,
// shelves, shadows) and scattered cubes are unknown, one box always around the robot's base so
// that some unknown cubes lie inside its capsules; the box spans partial blocks and partial
// super-blocks on every axis. The search must agree with every cube measured.
TEST(SeenFreeGrid, DistanceMatchesBruteForceForAnArmInRandomPoses) {
  SeenFreeGridSpec spec;
  spec.enabled = true;
  spec.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(-1.3F, -1.1F, -0.2F), Eigen::Vector3f(1.25F, 1.35F, 1.6F));
  spec.voxel_m = 0.07F;  // 37 × 35 × 26 cubes
  RobotParams params;
  params.arm = builtin_robot(BuiltinArm::ur5);
  params.padding_m = 0.05;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-3.14, 3.14);
  std::uniform_real_distribution<float> coord(-1.3F, 1.4F), size(0.05F, 0.6F), share(0.0F, 1.0F);
  for (int trial = 0; trial < 24; ++trial) {
    JointAngles q_rad{};
    for (double& q : q_rad) q = angle(rng);
    const RobotModel robot = robot_model_at(params, q_rad);
    std::vector<Eigen::AlignedBox3f> unknown_boxes = {
        Eigen::AlignedBox3f(Eigen::Vector3f(-0.2F, -0.2F, -0.2F), Eigen::Vector3f(0.2F, 0.2F, 0.3F))};
    for (int b = 0; b < trial % 4; ++b) {
      const Eigen::Vector3f corner(coord(rng), coord(rng), coord(rng));
      unknown_boxes.emplace_back(corner, corner + Eigen::Vector3f(size(rng), size(rng), size(rng)));
    }
    const float scattered = trial % 3 == 0 ? 0.0F : trial % 3 == 1 ? 1e-4F : 1e-2F;
    SeenFreeGrid grid;
    grid.reset(spec.cell_count());
    for (size_t cell = 0; cell < grid.cells; ++cell) {
      const Eigen::Vector3f centre = spec.centre(cell);
      bool unknown = share(rng) < scattered;
      for (const Eigen::AlignedBox3f& box : unknown_boxes) unknown = unknown || box.contains(centre);
      if (!unknown) grid.set(cell);
    }
    const float expected = brute_distance_m(spec, grid, robot);
    ASSERT_FALSE(std::isnan(expected)) << trial;  // the base box reaches out of the base capsule
    EXPECT_NEAR(unknown_cells_distance_m(spec, grid, robot), expected, 1e-5) << trial;
  }
}

TEST(SeenFreeGrid, UniteIsAnOrAndRefusesAnotherSize) {
  SeenFreeGrid a, b;
  a.reset(20);
  b.reset(20);
  a.set(3);
  b.set(17);
  unite(a, b);
  for (size_t i = 0; i < 20; ++i) EXPECT_EQ(a.test(i), i == 3 || i == 17) << i;
  SeenFreeGrid c;
  c.reset(21);
  EXPECT_THROW(unite(a, c), std::invalid_argument);
}

// Two cameras at the same pose, each with something at 2 m hiding a different part of the
// wall, and the same patch without depth: the union frees what each hides from the other, and
// only the patch both miss stays unknown.
TEST(SeenFreeGrid, TheUnionFreesWhatAnotherCameraSees) {
  SeenFreeGridSpec spec;
  spec.enabled = true;  // centres x −0.4 … 0.4, y −0.2 … 0.2, z 1.5 … 3.9: all in both views
  spec.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(-0.45F, -0.25F, 1.45F), Eigen::Vector3f(0.45F, 0.25F, 3.95F));
  spec.voxel_m = 0.1F;
  Scene a, b;
  a.foreground(75, 85, 55, 65, 2000);   // x/z, y/z within ±0.05
  b.foreground(95, 105, 55, 65, 2000);  // x/z in [0.15, 0.25]
  a.hole(57, 63, 47, 53, 5);
  b.hole(57, 63, 47, 53, 5);
  const SeenFreeGrid grid_a = a.mark(spec), grid_b = b.mark(spec);
  // A capsule along y at x = 0, z = 2.5 from y = 0.3 (radius 0.05): camera a's nearest hidden
  // cube is (0, 0.1, 2.5), pixel (80, 64): 0.3 − 0.1 − 0.05 = 0.15 m.
  RobotModel robot;
  robot.capsules.push_back(make_capsule({0.0F, 0.3F, 2.5F}, {0.0F, 1.0F, 2.5F}, 0.05F));
  const float distance_a = unknown_cells_distance_m(spec, grid_a, robot);
  EXPECT_NEAR(distance_a, 0.15, 1e-5);
  SeenFreeGrid fused = grid_a;
  unite(fused, grid_b);
  for (size_t cell = 0; cell < fused.cells; ++cell) {
    EXPECT_EQ(fused.test(cell), grid_a.test(cell) || grid_b.test(cell));
  }
  EXPECT_FALSE(seen_free(spec, grid_a, 0.0F, 0.0F, 2.5F));
  EXPECT_FALSE(seen_free(spec, grid_b, 0.4F, 0.0F, 2.0F));  // pixel (100, 60): hidden from b
  EXPECT_TRUE(seen_free(spec, fused, 0.0F, 0.0F, 2.5F));
  EXPECT_TRUE(seen_free(spec, fused, 0.4F, 0.0F, 2.0F));
  EXPECT_FALSE(seen_free(spec, fused, -0.4F, -0.2F, 2.0F));  // the patch neither camera sees
  // What is left is the patch: (−0.4, −0.2, 2.0) is nearest, √(0.4² + 0.5² + 0.5²) − 0.05.
  const float distance_fused = unknown_cells_distance_m(spec, fused, robot);
  EXPECT_GT(distance_fused, distance_a);
  EXPECT_NEAR(distance_fused, brute_distance_m(spec, fused, robot), 1e-5);
}

// One camera alone: the grid's unknown distance is never nearer the robot than unknown_space()'s
// per-ray distance, less a tolerance. A cube centre c called unknown lies in pixel p's unknown
// segment [z0, z1] widened by the margin m at both ends (z0 = near_m for a gap, not widened:
// nearer cubes are out of view). Its point P on p's segment at the clamped depth is at most
//   z·½·√(1/fx² + 1/fy²)   (c is within half a pixel of p's centre ray, at depth z)
// + m·|(x_p, y_p, 1)|      (the widening, along the ray)
// from c, and the capsules' surface distance moves by at most |c − P|. So the grid's distance is
// ≥ the per-ray one less those two, plus float rounding (1e-4 m). Cubes out of view would be
// unknown with no per-ray counterpart: the box lies inside the frustum, beyond near_m.
TEST(SeenFreeGrid, OneCameraIsNeverNearerThanItsRays) {
  SeenFreeGridSpec spec;
  spec.enabled = true;
  spec.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(-0.6F, -0.4F, 0.8F), Eigen::Vector3f(0.6F, 0.4F, 3.6F));
  spec.voxel_m = 0.05F;
  const float margin_m = seen_free_margin_m(spec);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> column(0, kWidth - 20), row(0, kHeight - 20), size(3, 18);
  std::uniform_int_distribution<int> raw(900, 2800);
  std::uniform_real_distribution<float> x(-0.6F, 0.6F), y(-0.4F, 0.4F), z(0.8F, 3.6F);
  int finite = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Scene scene;
    for (int k = 0; k < 3; ++k) {
      const int u = column(rng), v = row(rng);
      scene.foreground(u, u + size(rng), v, v + size(rng), static_cast<uint16_t>(raw(rng)));
      const int hu = column(rng), hv = row(rng);
      scene.hole(hu, hu + size(rng), hv, hv + size(rng), 5);
    }
    RobotModel robot;
    for (int c = 0; c < 4; ++c) robot.capsules.push_back(make_capsule({x(rng), y(rng), z(rng)}, {x(rng), y(rng), z(rng)}, 0.06F));
    const UnknownSpace rays = unknown_space(scene.depth, scene.intrinsics, scene.background, scene.foreground_mask,
                                            nullptr, scene.T_base_camera, robot, 0.0F, scene.no_depth_frames);
    const float grid_m = unknown_cells_distance_m(spec, scene.mark(spec), robot);
    ASSERT_FALSE(std::isnan(rays.distance_m)) << trial;
    if (std::isnan(grid_m)) continue;  // nothing unknown inside the box: nothing nearer
    ++finite;
    const float z_max_m = spec.box_base.max().z();
    const float half_pixel_m = z_max_m * 0.5F * std::hypot(1.0F / scene.intrinsics.fx, 1.0F / scene.intrinsics.fy);
    const float corner_ray = std::hypot(std::hypot(80.0F / 100.0F, 60.0F / 100.0F), 1.0F);
    EXPECT_GE(grid_m, rays.distance_m - (half_pixel_m + margin_m * corner_ray + 1e-4F)) << trial;
  }
  EXPECT_GT(finite, 10);
}

}  // namespace
}  // namespace hrcsense
