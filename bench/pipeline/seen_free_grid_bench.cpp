// SPDX-License-Identifier: Apache-2.0
// The seen-free grid (seen_free_grid.hpp) at the default spec (3 × 3 × 2 m at 0.05 m: 144 000
// cubes), seen by an 848x480 camera (fx = fy = 424) 5 m above the floor looking down, so that
// every cube is in view (the worst case for the camera's pass):
//   SeenFreeGrid/prepare/144000          the projection, once per pose (not per frame)
//   SeenFreeGrid/mark/848x480            one frame's pass: a person (200 × 300 px at 3.5 m,
//                                        foreground), the arm's envelope (150 × 150 px) with a
//                                        gap left of it, a 60 × 60 px patch without depth and 1 %
//                                        random dropouts over the floor
//   SeenFreeGrid/unite/144000            one camera's bits ORed into the fused grid
//   SeenFreeGrid/unknown_distance/144000 the fused side: that frame's grid against a UR-sized arm
//                                        of 7 capsules standing in the middle of the box
//   SeenFreeGrid/unknown_distance/layout:L the same arm against other unions: 0 every cube free
//                                        (the scan alone), 1 a random 1/27 unknown (the nearest
//                                        next to the arm), 2 only a person-sized box 0.4 × 0.4 ×
//                                        1.8 m unknown, 1 m from the arm (the search goes far)
// Budget (issue H2): the grid ≤ 1 ms per camera frame, and about as much for the fuser.
#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/unknown_space.hpp"

#include <Eigen/Geometry>
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

namespace hrcsense {
namespace {

struct GridScene {
  SeenFreeGridSpec spec;
  Intrinsics intrinsics;
  Pose T_base_camera = Pose::Identity();
  DepthImage depth;
  BackgroundModel background;
  ReliableBackground reliable;
  std::vector<uint8_t> foreground_mask, no_depth_frames;
  std::vector<uint16_t> from_raw, to_raw;
  RobotPixels robot_pixels;
  RobotModel robot;

  GridScene() {
    spec.enabled = true;
    intrinsics.width = 848;
    intrinsics.height = 480;
    intrinsics.fx = intrinsics.fy = 424.0F;
    intrinsics.ppx = 424.0F;
    intrinsics.ppy = 240.0F;
    // Camera z along base −z, 5 m up: the floor (base z = 0) at 5 m.
    T_base_camera.linear() = Eigen::AngleAxisd(3.141592653589793, Eigen::Vector3d::UnitX()).toRotationMatrix();
    T_base_camera.translation() = Eigen::Vector3d(0, 0, 5);
    depth.resize(848, 480);
    depth.pixels.assign(depth.pixels.size(), 5000);
    const size_t n = depth.pixels.size();
    background.width = 848;
    background.height = 480;
    background.mean_m.assign(n, 5.0F);
    background.spread_m.assign(n, 0.01F);
    background.valid_ratio.assign(n, 1.0F);
    reliable = reliable_background(background, UnknownSpaceParams{}.min_valid_ratio);
    foreground_mask.assign(n, 0);
    no_depth_frames.assign(n, 0);
    from_raw.assign(n, 0);
    to_raw.assign(n, 0);
    const auto at = [](int u, int v) { return static_cast<size_t>(v) * 848U + static_cast<size_t>(u); };
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> share(0.0F, 1.0F);
    for (size_t i = 0; i < n; ++i) {
      if (share(rng) < 0.01F) {
        depth.pixels[i] = 0;
        no_depth_frames[i] = 1;
      }
    }
    for (int v = 100; v < 400; ++v) {
      for (int u = 150; u < 350; ++u) {
        depth.pixels[at(u, v)] = 3500;
        foreground_mask[at(u, v)] = 1;
      }
    }
    for (int v = 170; v < 320; ++v) {
      for (int u = 350; u < 520; ++u) {
        if (u >= 370) {
          from_raw[at(u, v)] = 4000;
          to_raw[at(u, v)] = 4800;
          depth.pixels[at(u, v)] = 4200;
        } else {
          depth.pixels[at(u, v)] = 0;  // the gap left of the arm
          no_depth_frames[at(u, v)] = 10;
        }
      }
    }
    for (int v = 380; v < 440; ++v) {
      for (int u = 600; u < 660; ++u) {
        depth.pixels[at(u, v)] = 0;
        no_depth_frames[at(u, v)] = 10;
      }
    }
    robot_pixels.from_raw = from_raw.data();
    robot_pixels.to_raw = to_raw.data();
    robot_pixels.u0 = 370;
    robot_pixels.u1 = 520;
    robot_pixels.v0 = 170;
    robot_pixels.v1 = 320;
    const auto add = [&](Eigen::Vector3f a, Eigen::Vector3f b, float r) {
      Capsule c;
      c.a = a;
      c.b = b;
      c.radius_m = r;
      robot.capsules.push_back(c);
    };
    add({0, 0, 0}, {0, 0, 0.16F}, 0.12F);
    add({0, 0, 0.16F}, {0, -0.14F, 0.16F}, 0.11F);
    add({0, -0.14F, 0.16F}, {0.3F, -0.14F, 0.5F}, 0.1F);
    add({0.3F, -0.14F, 0.5F}, {0.3F, -0.02F, 0.5F}, 0.09F);
    add({0.3F, -0.02F, 0.5F}, {0.6F, 0.1F, 0.45F}, 0.08F);
    add({0.6F, 0.1F, 0.45F}, {0.6F, 0.2F, 0.45F}, 0.07F);
    add({0.6F, 0.2F, 0.45F}, {0.6F, 0.2F, 0.3F}, 0.07F);
  }
};

const SeenFreeProjection& projection_of(const GridScene& s) {
  static const SeenFreeProjection projection =
      prepare_seen_free(s.spec, s.intrinsics, s.T_base_camera, UnknownSpaceParams{}.near_m);
  return projection;
}

void BM_SeenFreePrepare(benchmark::State& state) {
  const GridScene s;
  for (auto _ : state) {
    SeenFreeProjection p = prepare_seen_free(s.spec, s.intrinsics, s.T_base_camera, UnknownSpaceParams{}.near_m);
    benchmark::DoNotOptimize(p.cubes.data());
  }
}

void BM_SeenFreeMark(benchmark::State& state) {
  const GridScene s;
  const SeenFreeProjection& projection = projection_of(s);
  SeenFreeGrid grid;
  for (auto _ : state) {
    mark_seen_free(projection, s.depth, s.background, s.reliable, s.foreground_mask, &s.robot_pixels, 0.05F,
                   s.no_depth_frames, UnknownSpaceParams{}, grid);
    benchmark::DoNotOptimize(grid.bytes.data());
  }
  state.counters["cubes_in_view"] = static_cast<double>(projection.cubes.size());
}

void BM_SeenFreeUnite(benchmark::State& state) {
  SeenFreeGrid fused, camera;
  fused.reset(144000);
  camera.reset(144000);
  for (auto _ : state) {
    unite(fused, camera);
    benchmark::DoNotOptimize(fused.bytes.data());
  }
}

void BM_SeenFreeUnknownDistance(benchmark::State& state) {
  const GridScene s;
  SeenFreeGrid grid;
  mark_seen_free(projection_of(s), s.depth, s.background, s.reliable, s.foreground_mask, &s.robot_pixels, 0.05F,
                 s.no_depth_frames, UnknownSpaceParams{}, grid);
  size_t unknown = 0;
  for (size_t i = 0; i < grid.cells; ++i) unknown += grid.test(i) ? 0U : 1U;
  float distance_m = 0.0F;
  for (auto _ : state) {
    distance_m = unknown_cells_distance_m(s.spec, grid, s.robot);
    benchmark::DoNotOptimize(distance_m);
  }
  state.counters["unknown_cubes"] = static_cast<double>(unknown);
  state.counters["distance_m"] = distance_m;
}

void BM_SeenFreeUnknownDistanceLayouts(benchmark::State& state) {
  const GridScene s;
  SeenFreeGrid grid;
  grid.reset(s.spec.cell_count());
  std::mt19937 rng(5);
  const Eigen::AlignedBox3f shadow(Eigen::Vector3f(-1.3F, 0.2F, 0.0F), Eigen::Vector3f(-0.9F, 0.6F, 1.8F));
  for (size_t i = 0; i < grid.cells; ++i) {
    const bool unknown = state.range(0) == 1 ? rng() % 27 == 0 : state.range(0) == 2 && shadow.contains(s.spec.centre(i));
    if (!unknown) grid.set(i);
  }
  UnknownDistanceScratch scratch;
  float distance_m = 0.0F;
  for (auto _ : state) {
    distance_m = unknown_cells_distance_m(s.spec, grid, s.robot, scratch);
    benchmark::DoNotOptimize(distance_m);
  }
  state.counters["distance_m"] = distance_m;
}

BENCHMARK(BM_SeenFreePrepare)->Name("SeenFreeGrid/prepare/144000")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeenFreeMark)->Name("SeenFreeGrid/mark/848x480")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeenFreeUnite)->Name("SeenFreeGrid/unite/144000")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeenFreeUnknownDistance)->Name("SeenFreeGrid/unknown_distance/144000")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SeenFreeUnknownDistanceLayouts)->Name("SeenFreeGrid/unknown_distance")->ArgName("layout")->DenseRange(0, 2)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
