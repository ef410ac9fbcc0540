// SPDX-License-Identifier: Apache-2.0
// The simulator's ray caster (planes by their envelope along rows for pinhole cameras, per
// pixel otherwise; boxes row by row; bounded shapes over their screen rectangles) against a
// plain reference: every shape's exact ray test (sim_geometry.hpp) at every pixel, in the base
// frame, nearest hit wins. Also the colour image's writer against per-pixel colours.

#include "src/sim/sim_color.hpp"
#include "src/sim/sim_geometry.hpp"
#include "src/sim/sim_raycast.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using sim_detail::kNoHit;
using sim_detail::PoseF;

/// The nearest and second-nearest hit of one pixel's ray over all shapes, and the nearest's id.
struct ReferenceHit {
  float z_m = kNoHit;
  float second_z_m = kNoHit;
  uint16_t id = 0;
};

float reference_t(const Shape& s, const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  switch (s.type) {
    case Shape::Type::plane:
      return sim_detail::hit_plane(s, o, d);
    case Shape::Type::box:
      return sim_detail::hit_box(s, o, d);
    case Shape::Type::sphere:
      return sim_detail::hit_sphere(s.point, s.radius_m, o, d);
    case Shape::Type::capsule:
      return sim_detail::hit_capsule(s, o, d);
  }
  return kNoHit;
}

/// Every pixel, every shape: the ray from the camera centre along R·(x, y, 1) (t is Z).
std::vector<ReferenceHit> reference_cast(const std::vector<Shape>& shapes, const std::vector<uint16_t>& ids,
                                         const SimRays& rays, const PoseF& T_base_camera) {
  std::vector<ReferenceHit> out(rays.x.size());
  for (size_t i = 0; i < rays.x.size(); ++i) {
    const Eigen::Vector3f d = T_base_camera.R * Eigen::Vector3f(rays.x[i], rays.y[i], 1.0F);
    for (size_t k = 0; k < shapes.size(); ++k) {
      const float t = reference_t(shapes[k], T_base_camera.t, d);
      if (t < out[i].z_m) {
        out[i].second_z_m = out[i].z_m;
        out[i].z_m = t;
        out[i].id = ids[k];
      } else if (t < out[i].second_z_m) {
        out[i].second_z_m = t;
      }
    }
  }
  return out;
}

bool near(float a, float b, float rel) { return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)); }

/// Casts `shapes` and compares with the reference: the same object and the same depth (to the
/// rounding of the different formulas), except on silhouettes (a reference 4-neighbour sees
/// another object: grazing rays hit or miss by rounding) and where two surfaces meet within
/// rounding.
void expect_matches_reference(const std::vector<Shape>& shapes, const Intrinsics& in, const PoseF& T_base_camera,
                              size_t min_distinct_ids) {
  std::vector<uint16_t> ids(shapes.size());
  for (size_t k = 0; k < shapes.size(); ++k) ids[k] = static_cast<uint16_t>(k + 1);
  SimRays rays;
  sim_detail::ensure_rays(rays, in);
  const size_t n = rays.x.size();
  // Garbage in the buffers: the caster must write every pixel.
  std::vector<float> z_m(n, -7.0F);
  std::vector<uint16_t> hit_ids(n, 999);
  sim_detail::cast_shapes(shapes, ids, rays, T_base_camera, z_m.data(), hit_ids.data());
  const std::vector<ReferenceHit> expected = reference_cast(shapes, ids, rays, T_base_camera);

  // Quadrics lose about half the float digits on grazing rays; 0.1 mm at 1 m still tells
  // surfaces apart.
  constexpr float kRel = 1e-4F;
  const int width = in.width;
  const int height = in.height;
  size_t compared = 0;
  size_t depth_mismatches = 0;
  size_t id_mismatches = 0;
  std::vector<bool> seen(shapes.size() + 1, false);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      const ReferenceHit& e = expected[i];
      seen[e.id] = true;
      const bool silhouette = (u > 0 && expected[i - 1].id != e.id) || (u + 1 < width && expected[i + 1].id != e.id) ||
                              (v > 0 && expected[i - width].id != e.id) ||
                              (v + 1 < height && expected[i + width].id != e.id);
      const bool tie = e.z_m < kNoHit && near(e.z_m, e.second_z_m, kRel);
      if (silhouette || tie) continue;
      ++compared;
      if (hit_ids[i] != e.id && ++id_mismatches <= 5) {
        ADD_FAILURE() << "pixel (" << u << ", " << v << "): id " << hit_ids[i] << " expected " << e.id;
      }
      const bool depth_ok = e.z_m == kNoHit ? z_m[i] == kNoHit : near(z_m[i], e.z_m, kRel);
      if (!depth_ok && ++depth_mismatches <= 5) {
        ADD_FAILURE() << "pixel (" << u << ", " << v << "): Z " << z_m[i] << " expected " << e.z_m;
      }
    }
  }
  EXPECT_EQ(depth_mismatches, 0U);
  EXPECT_EQ(id_mismatches, 0U);
  EXPECT_GT(compared, n * 9 / 10) << "silhouettes and ties should be few";
  size_t distinct = 0;
  for (size_t k = 1; k < seen.size(); ++k) distinct += seen[k] ? 1 : 0;
  EXPECT_GE(distinct, min_distinct_ids) << "the scene should show that many shapes";
}

/// A room seen from a tilted camera: walls, floor and a ceiling that meet in view, a slanted
/// plane, one behind the camera and one through the camera centre (never seen), boxes,
/// spheres and capsules, one of them around the camera's far corner.
std::vector<Shape> room() {
  return {
      Shape::plane({0, 0, 4.0F}, {0, 0, -1}),                  // back wall
      Shape::plane({-1.5F, 0, 0}, {1, 0, 0}),                  // left wall
      Shape::plane({1.2F, 0, 0}, {-1, 0, 0}),                  // right wall
      Shape::plane({0, 1.0F, 0}, {0, -1, 0}),                  // floor
      Shape::plane({0, 0, -1.0F}, {0, 0, 1}),                  // behind the camera
      Shape::plane({0, 0, 0}, {0, 1, 0}),                      // through the camera centre
      Shape::plane({0.5F, 0, 3.0F}, Eigen::Vector3f(-1, 0.3F, -1).normalized()),  // slanted
      Shape::box({-0.6F, 0.2F, 1.5F}, {-0.2F, 1.0F, 2.0F}),
      Shape::box({0.3F, -0.4F, 2.2F}, {0.7F, 0.1F, 2.6F}),
      Shape::sphere({0.0F, -0.2F, 1.2F}, 0.15F),
      Shape::capsule({0.4F, 0.8F, 1.6F}, {0.5F, -0.3F, 1.7F}, 0.08F),
      Shape::capsule({-1.0F, -0.5F, 3.0F}, {-0.2F, -0.6F, 3.5F}, 0.1F),
  };
}

PoseF tilted_camera() {
  PoseF T;
  T.R = (Eigen::AngleAxisf(0.15F, Eigen::Vector3f::UnitX()) * Eigen::AngleAxisf(-0.1F, Eigen::Vector3f::UnitY()) *
         Eigen::AngleAxisf(0.05F, Eigen::Vector3f::UnitZ()))
            .toRotationMatrix();
  T.t = {0.05F, -0.1F, 0.2F};
  return T;
}

TEST(SimRaycast, PinholeCameraMatchesThePerPixelReference) {
  const Intrinsics in = *d435_depth_intrinsics(640, 480);
  ASSERT_TRUE(is_pinhole(in)) << "the row-envelope path is the one under test";
  expect_matches_reference(room(), in, tilted_camera(), 9);
}

TEST(SimRaycast, ColourCameraIntrinsicsMatchThePerPixelReference) {
  const Intrinsics in = *d435_color_intrinsics(424, 240);
  ASSERT_TRUE(is_pinhole(in));
  expect_matches_reference(room(), in, tilted_camera(), 8);
}

TEST(SimRaycast, DistortedCameraMatchesThePerPixelReference) {
  Intrinsics in = *d435_depth_intrinsics(424, 240);
  in.model = Distortion::inverse_brown_conrady;
  in.coeffs = {0.08F, -0.05F, 0.001F, -0.002F, 0.01F};
  ASSERT_FALSE(is_pinhole(in)) << "the per-pixel plane path is the one under test";
  expect_matches_reference(room(), in, tilted_camera(), 9);
}

TEST(SimRaycast, ManyPlanesFallBackToThePerPixelPass) {
  // More planes than one envelope batch holds: parallel walls, the nearest of which hides the
  // rest only partly because a slanted one cuts through them.
  std::vector<Shape> shapes;
  for (int k = 0; k < 20; ++k) shapes.push_back(Shape::plane({0, 0, 2.0F + 0.25F * k}, {0, 0, -1}));
  shapes.push_back(Shape::plane({0.3F, 0, 2.0F}, Eigen::Vector3f(-1, 0, -0.3F).normalized()));
  shapes.push_back(Shape::plane({0, 0.3F, 0}, {0, -1, 0}));
  shapes.push_back(Shape::sphere({0.1F, 0.0F, 1.5F}, 0.1F));
  PoseF T;
  T.R = Eigen::AngleAxisf(0.4F, Eigen::Vector3f::UnitY()).toRotationMatrix();
  expect_matches_reference(shapes, *d435_depth_intrinsics(424, 240), T, 3);
}

TEST(SimRaycast, NothingButEmptinessWithoutShapes) {
  SimRays rays;
  sim_detail::ensure_rays(rays, *d435_depth_intrinsics(424, 240));
  std::vector<float> z_m(rays.x.size(), 1.0F);
  std::vector<uint16_t> ids(rays.x.size(), 3);
  sim_detail::cast_shapes({}, {}, rays, PoseF{}, z_m.data(), ids.data());
  for (size_t i = 0; i < z_m.size(); ++i) {
    ASSERT_EQ(z_m[i], kNoHit) << i;
    ASSERT_EQ(ids[i], 0) << i;
  }
}

TEST(SimRaycast, ColourWriterGivesEachPixelItsObjectsColour) {
  // Few objects (the packed fast path) and more than 256 (the byte-wise one), odd sizes so
  // that the last pixel, which must not write past the image, is exercised.
  for (const size_t objects : {5U, 300U}) {
    std::vector<std::array<uint8_t, 3>> color_of_id(objects + 1);
    for (size_t k = 0; k < color_of_id.size(); ++k) {
      color_of_id[k] = {static_cast<uint8_t>(k * 7), static_cast<uint8_t>(255 - k), static_cast<uint8_t>(k * 13 + 1)};
    }
    const int width = 37;
    const int height = 11;
    std::vector<uint16_t> ids(static_cast<size_t>(width) * height);
    for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<uint16_t>((i * 31 + i / 5) % (objects + 1));
    ColorImage image;
    sim_detail::write_color(ids, color_of_id, width, height, image);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    ASSERT_EQ(image.rgb.size(), ids.size() * 3);
    for (size_t i = 0; i < ids.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(image.rgb[3 * i + c], color_of_id[ids[i]][c]) << "objects " << objects << ", pixel " << i;
      }
    }
  }
}

}  // namespace
}  // namespace hrcsense
