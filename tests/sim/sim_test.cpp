// SPDX-License-Identifier: Apache-2.0
// Tests of the simulated depth camera against hand-computed geometry and its noise model.

#include "hrcsense/camera.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

SceneObject object(std::vector<Shape> shapes, bool is_static) {
  SceneObject o;
  o.name = is_static ? "static" : "moving";
  o.shapes = std::move(shapes);
  o.is_static = is_static;
  return o;
}

Simulator make_sim(bool noise) {
  Simulator sim;
  sim.params.noise = noise;
  return sim;
}

/// The wall z = z_m facing the camera at the origin.
SceneObject wall(float z_m) { return object({Shape::plane({0, 0, z_m}, {0, 0, -1})}, true); }

Capsule robot_point(const Eigen::Vector3f& p) { return Capsule{p, p, 0.0F, 0}; }

size_t pixel_index(const Frame& f, int u, int v) { return static_cast<size_t>(v) * f.depth.width + u; }

size_t count_label(const Frame& f, uint16_t label) {
  size_t n = 0;
  for (const uint16_t l : f.truth->labels) n += l == label ? 1 : 0;
  return n;
}

// The defaults table of docs/SIMULATOR.md ("The sensor model and its defaults"), number for
// number: that table and this check change together, and neither changes to make a test pass.
void expect_documented_defaults(const SimParams& p, const std::string& where) {
  SCOPED_TRACE(where);
  EXPECT_EQ(p.sensor, SimSensor::d435);
  EXPECT_EQ(p.width, 848);  // the table's figures are for 848x480
  EXPECT_EQ(p.height, 480);
  EXPECT_TRUE(p.noise);
  EXPECT_FLOAT_EQ(p.disparity_noise_px, 0.08F);
  EXPECT_FLOAT_EQ(p.disparity_step_px, 1.0F / 32.0F);
  EXPECT_FLOAT_EQ(p.depth_scale_m, 0.001F);  // depth rounded to 1 mm
  EXPECT_FLOAT_EQ(p.baseline_mm, 49.864F);
  EXPECT_TRUE(p.left_band);
  EXPECT_TRUE(p.occlusion_shadows);
  EXPECT_FLOAT_EQ(p.max_disparity_px, 110.0F);
  EXPECT_FLOAT_EQ(p.min_range_m, 0.0F);
  EXPECT_FLOAT_EQ(p.max_range_m, 0.0F);  // no working range: off
  EXPECT_FLOAT_EQ(p.range_dropout, 0.0F);
  EXPECT_FLOAT_EQ(p.range_dropout_start_m, 0.0F);
  EXPECT_FLOAT_EQ(p.edge_jump_px, 1.5F);
  EXPECT_FLOAT_EQ(p.edge_dropout, 0.25F);
  EXPECT_FLOAT_EQ(p.flying_pixels, 0.15F);
  EXPECT_FLOAT_EQ(p.edge_flicker, 0.0F);  // edges fixed per seed
  EXPECT_FLOAT_EQ(p.dark_dropout, 0.6F);
  EXPECT_FLOAT_EQ(p.shiny_dropout, 0.35F);
  EXPECT_FLOAT_EQ(p.low_texture_dropout, 0.5F);
  EXPECT_EQ(p.material_cell_px, 4);
  EXPECT_FLOAT_EQ(p.speckle, 0.002F);
  EXPECT_FLOAT_EQ(p.correlated_noise_px, 0.0F);  // off
  EXPECT_EQ(p.correlated_cell_px, 32);
}

size_t count_valid_pixels(const Frame& f) {
  const auto valid = [](uint16_t raw) { return raw != 0; };
  return static_cast<size_t>(std::count_if(f.depth.pixels.begin(), f.depth.pixels.end(), valid));
}

TEST(Simulator, DefaultsAreTheOnesDocsSimulatorMdPins) {
  expect_documented_defaults(SimParams{}, "SimParams{}");
  expect_documented_defaults(load_config("", {}).sim, "sim.* keys of an empty configuration");
  // What the table's numbers rest on: fx = 418.265 px at 848x480, B = 49.864 mm, s = 0.08 px.
  EXPECT_NEAR(d435_depth_intrinsics(848, 480)->fx, 418.265F, 1e-3F);
  EXPECT_FLOAT_EQ(kD435BaselineMm, 49.864F);
  EXPECT_FLOAT_EQ(kD435SubpixelRmsPx, 0.08F);
  // The minimum range fx·B/110 the table gives per resolution: a wall 3 % nearer has no depth
  // at all, one 3 % farther has depth right of its left band.
  struct Mode {
    int width, height;
    float min_range_m;
  };
  for (const Mode mode : {Mode{848, 480, 0.190F}, Mode{1280, 720, 0.286F}, Mode{424, 240, 0.095F}}) {
    Simulator sim = make_sim(false);
    sim.params.width = mode.width;
    sim.params.height = mode.height;
    Frame f;
    sim.scene.objects = {wall(0.97F * mode.min_range_m)};
    sim.render(0, f);
    EXPECT_EQ(count_valid_pixels(f), 0U) << mode.width << "x" << mode.height;
    sim.scene.objects = {wall(1.03F * mode.min_range_m)};
    sim.render(0, f);
    EXPECT_GT(count_valid_pixels(f), f.depth.pixels.size() / 2) << mode.width << "x" << mode.height;
  }
}

TEST(Simulator, NoiseFreePlaneAtOneMetreReadsExactly1000) {
  Simulator sim = make_sim(false);
  sim.scene.objects.push_back(wall(1.0F));
  Frame f;
  sim.render(0, f);
  ASSERT_EQ(f.depth.width, 848);
  ASSERT_EQ(f.depth.height, 480);
  // The right imager misses the first fx·B/Z = 20.86 columns (u + 0.5 < 20.86: u = 0..20).
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < f.depth.width; ++u) ASSERT_EQ(f.depth.at(u, v), u <= 20 ? 0 : 1000) << u << "," << v;
  }
  for (const float z : f.truth->depth_m) ASSERT_FLOAT_EQ(z, 1.0F);
  EXPECT_EQ(count_label(f, kStaticLabel), f.depth.pixels.size());
  EXPECT_FALSE(f.truth->contact.valid);
  EXPECT_FALSE(f.truth->analytic_contact.valid);
  EXPECT_FLOAT_EQ(f.depth.depth_scale_m, 0.001F);
  EXPECT_FLOAT_EQ(f.stereo_baseline_mm, kD435BaselineMm);
  EXPECT_EQ(f.intrinsics.fx, d435_depth_intrinsics(848, 480)->fx);
}

TEST(Simulator, EmptySceneReadsZero) {
  Simulator sim = make_sim(true);
  Frame f;
  sim.render(0, f);
  for (const uint16_t raw : f.depth.pixels) ASSERT_EQ(raw, 0);
  for (const float z : f.truth->depth_m) ASSERT_EQ(z, 0.0F);
}

TEST(Simulator, RotatedCameraSeesWallAlongItsOpticalAxis) {
  // Camera turned +90° about the base y axis: its optical axis (camera z) is base +x.
  Simulator sim = make_sim(false);
  sim.T_base_camera = Pose(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));
  sim.T_base_camera.translation() = Eigen::Vector3d(-0.5, 0.3, 0.1);
  sim.scene.objects.push_back(object({Shape::plane({1.5F, 0, 0}, {-1, 0, 0})}, true));
  sim.params.left_band = false;  // every pixel, the left band included
  Frame f;
  sim.render(0, f);
  for (const uint16_t raw : f.depth.pixels) ASSERT_EQ(raw, 2000);  // 1.5 − (−0.5)
}

TEST(Simulator, BoxVertexLandsWhereProjectionPredicts) {
  // Camera moved (rotation identity keeps the front face fronto-parallel, so its depth is exact).
  Simulator sim = make_sim(false);
  sim.T_base_camera.translation() = Eigen::Vector3d(0.1, -0.05, -0.3);
  sim.scene.objects.push_back(object({Shape::box({0.2F, 0.1F, 1.2F}, {0.4F, 0.3F, 1.5F})}, false));
  Frame f;
  sim.render(0, f);
  // Front top left vertex in the camera frame: (0.1, 0.15, 1.5).
  const Eigen::Vector2f uv = *project(f.intrinsics, Eigen::Vector3f(0.1F, 0.15F, 1.5F));
  const int u = static_cast<int>(std::ceil(uv.x()));
  const int v = static_cast<int>(std::ceil(uv.y()));
  // First pixel centre inside the front face reads the face's depth; the neighbours up and
  // left see past the vertex (top or left face, farther away, or nothing).
  EXPECT_EQ(f.depth.at(u, v), 1500);
  EXPECT_EQ(f.truth->labels[pixel_index(f, u, v)], 1);
  EXPECT_NE(f.depth.at(u - 1, v), 1500);
  EXPECT_NE(f.depth.at(u, v - 1), 1500);
  EXPECT_GT(f.depth.at(u - 1, v - 1), 1500);
  // The face spans 0.2 m × 0.2 m at 1.5 m: f·0.2/1.5 ≈ 55.8 px on a side.
  const int side_px = static_cast<int>(std::floor(f.intrinsics.fx * 0.2F / 1.5F));
  EXPECT_EQ(f.depth.at(u + side_px - 1, v + side_px - 1), 1500);
}

TEST(Simulator, SameSeedSameFramesOtherSeedOtherFrames) {
  Simulator a = make_sim(true);
  a.params.seed = 42;
  a.scene.objects.push_back(wall(1.5F));
  Simulator b = a;
  Frame fa, fb, fc;
  a.render(7, fa);
  b.render(2, fb);  // history must not matter
  b.render(7, fb);
  EXPECT_EQ(fa.depth.pixels, fb.depth.pixels);
  a.render(8, fc);
  EXPECT_NE(fa.depth.pixels, fc.depth.pixels);
  Simulator c = a;
  c.params.seed = 43;
  c.render(7, fc);
  EXPECT_NE(fa.depth.pixels, fc.depth.pixels);
  EXPECT_EQ(fa.truth->depth_m, fc.truth->depth_m);  // the truth has no noise
}

TEST(Simulator, TimestampsAreIndexOverFps) {
  Simulator sim = make_sim(false);
  sim.params.width = 424;
  sim.params.height = 240;
  Frame f;
  sim.render(1, f);
  EXPECT_EQ(f.index, 1);
  EXPECT_EQ(f.timestamp_ns, 33'333'333);
  sim.render(2, f);
  EXPECT_EQ(f.timestamp_ns, 66'666'667);
  sim.params.fps = 90.0;
  sim.render(90, f);
  EXPECT_EQ(f.timestamp_ns, 1'000'000'000);
}

TEST(Simulator, LabelsCountNonStaticObjectsInSceneOrder) {
  Simulator sim = make_sim(false);
  sim.scene.objects.push_back(wall(3.0F));
  sim.scene.objects.push_back(object({Shape::sphere({-0.5F, 0, 2}, 0.2F)}, false));
  sim.scene.objects.push_back(object({Shape::box({-0.1F, -0.1F, 2}, {0.1F, 0.1F, 2.2F})}, true));
  sim.scene.objects.push_back(object({Shape::sphere({0.5F, 0, 2}, 0.2F)}, false));
  Frame f;
  sim.render(0, f);
  const auto label_at = [&](float x, float y, float z) {
    const Eigen::Vector2f uv = *project(f.intrinsics, Eigen::Vector3f(x, y, z));
    return f.truth->labels[pixel_index(f, static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())))];
  };
  EXPECT_EQ(label_at(-0.5F, 0, 2), 1);
  EXPECT_EQ(label_at(0.0F, 0, 2), kStaticLabel);  // static box
  EXPECT_EQ(label_at(0.5F, 0, 2), 2);
  EXPECT_EQ(label_at(0.0F, 0.5F, 3), kStaticLabel);  // wall
  // A label belongs to the object, not to the frame: it stays 2 while object 1 is absent.
  sim.scene.objects[1].first_frame = 10;
  sim.render(0, f);
  EXPECT_EQ(count_label(f, 1), 0U);
  EXPECT_EQ(label_at(0.5F, 0, 2), 2);
}

TEST(Simulator, WaypointPathInterpolatesAndHoldsAtTheEnds) {
  Simulator sim = make_sim(false);
  sim.params.fps = 10.0;
  const Eigen::Vector3f p(0.0F, 0.0F, 0.5F);
  sim.robot.capsules.push_back(robot_point(p));
  SceneObject ball = object({Shape::sphere({-0.4F, 0.1F, 2.0F}, 0.1F)}, false);
  ball.path = {{1.0, {0, 0, 0}}, {2.0, {0.8F, 0, 0}}, {3.0, {0.8F, -0.2F, 0}}};
  sim.scene.objects.push_back(ball);
  const auto expect_centre = [&](int64_t index, const Eigen::Vector3f& centre) {
    Frame f;
    sim.render(index, f);
    const Contact& c = f.truth->analytic_contact;
    ASSERT_TRUE(c.valid) << "frame " << index;
    EXPECT_NEAR(c.distance_m, (centre - p).norm() - 0.1F, 1e-5) << "frame " << index;
    // The ray through the centre meets the sphere r before the centre along the ray, so at
    // depth z·(1 − r/|c|).
    const Eigen::Vector2f uv = *project(f.intrinsics, centre);
    const size_t i = pixel_index(f, static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())));
    EXPECT_EQ(f.truth->labels[i], 1) << "frame " << index;
    EXPECT_NEAR(f.truth->depth_m[i], centre.z() * (1.0F - 0.1F / centre.norm()), 1e-3) << "frame " << index;
  };
  expect_centre(0, {-0.4F, 0.1F, 2.0F});   // t = 0 s: held at the first waypoint
  expect_centre(15, {0.0F, 0.1F, 2.0F});   // t = 1.5 s: halfway along the first leg
  expect_centre(25, {0.4F, 0.0F, 2.0F});   // t = 2.5 s: halfway along the second leg
  expect_centre(100, {0.4F, -0.1F, 2.0F});  // t = 10 s: held at the last waypoint
}

TEST(Simulator, ObjectsExistFromFirstToLastFrame) {
  Simulator sim = make_sim(false);
  sim.robot.capsules.push_back(robot_point({0, 0, 0.5F}));
  SceneObject ball = object({Shape::sphere({0, 0, 2}, 0.2F)}, false);
  ball.first_frame = 5;
  ball.last_frame = 7;
  sim.scene.objects.push_back(ball);
  Frame f;
  for (const int64_t index : {0, 4, 5, 7, 8}) {
    sim.render(index, f);
    const bool present = index >= 5 && index <= 7;
    EXPECT_EQ(count_label(f, 1) > 0, present) << "frame " << index;
    EXPECT_EQ(f.truth->contact.valid, present) << "frame " << index;
    EXPECT_EQ(f.truth->analytic_contact.valid, present) << "frame " << index;
  }
  sim.scene.objects[0].last_frame = -1;
  sim.render(100000, f);
  EXPECT_GT(count_label(f, 1), 0U);
}

TEST(Simulator, SphereContactMatchesAnalyticDistance) {
  Simulator sim = make_sim(true);  // the truth is noise-free whatever the depth noise
  const Eigen::Vector3f p(0.05F, -0.1F, 0.4F);
  const Eigen::Vector3f c(0.1F, 0.05F, 1.5F);
  const float r = 0.2F;
  sim.robot.capsules.push_back(robot_point(p));
  sim.scene.objects.push_back(wall(3.0F));
  sim.scene.objects.push_back(object({Shape::sphere(c, r)}, false));
  Frame f;
  sim.render(0, f);
  const double expected_m = (c.cast<double>() - p.cast<double>()).norm() - r;
  const Contact& analytic = f.truth->analytic_contact;
  ASSERT_TRUE(analytic.valid);
  EXPECT_NEAR(analytic.distance_m, expected_m, 1e-6);
  const Eigen::Vector3f on_sphere = c + r * (p - c).normalized();
  EXPECT_LT((analytic.closest_base - on_sphere).norm(), 1e-5F);
  EXPECT_LT((analytic.closest_robot_base - p).norm(), 1e-6F);
  EXPECT_LT((analytic.closest_camera - on_sphere).norm(), 1e-5F);  // camera at the base origin
  // Rendered pixels lie on the surface, so they are never closer than the analytic minimum and
  // the nearest one is within a pixel's footprint at ~1.3 m (≈ 3 mm).
  const Contact& truth = f.truth->contact;
  ASSERT_TRUE(truth.valid);
  EXPECT_GE(truth.distance_m, expected_m - 1e-5);
  EXPECT_LE(truth.distance_m, expected_m + 0.003);
  EXPECT_LT((truth.closest_base - on_sphere).norm(), 0.004F);
  EXPECT_EQ(f.truth->labels[static_cast<size_t>(truth.pixel)], 1);
}

TEST(Simulator, AnalyticContactOfCapsulesAndBoxes) {
  Simulator sim = make_sim(false);
  sim.robot.capsules.push_back(Capsule{{0, -1, 1.5F}, {0, 1, 1.5F}, 0.05F, 3});
  // A horizontal capsule 0.5 m behind a vertical robot capsule: 0.5 − 0.1 − 0.05.
  sim.scene.objects.push_back(object({Shape::capsule({-0.5F, 0, 2}, {0.5F, 0, 2}, 0.1F)}, false));
  Frame f;
  sim.render(0, f);
  ASSERT_TRUE(f.truth->analytic_contact.valid);
  EXPECT_NEAR(f.truth->analytic_contact.distance_m, 0.35, 1e-6);
  EXPECT_EQ(f.truth->analytic_contact.robot_link, 3);
  EXPECT_LT((f.truth->analytic_contact.closest_base - Eigen::Vector3f(0, 0, 1.9F)).norm(), 1e-6F);

  // A box against a robot segment parallel to its top front edge (y = 0.1, z = 1.9).
  sim.robot.capsules = {Capsule{{-1, 0.5F, 1.5F}, {1, 0.5F, 1.5F}, 0.02F, 0}};
  sim.scene.objects = {object({Shape::box({-0.1F, -0.1F, 1.9F}, {0.1F, 0.1F, 2.1F})}, false)};
  sim.render(0, f);
  ASSERT_TRUE(f.truth->analytic_contact.valid);
  EXPECT_NEAR(f.truth->analytic_contact.distance_m, std::sqrt(0.32) - 0.02, 1e-5);
  EXPECT_NEAR(f.truth->analytic_contact.closest_base.y(), 0.1F, 1e-6);
  EXPECT_NEAR(f.truth->analytic_contact.closest_base.z(), 1.9F, 1e-6);
  // The robot segment crosses the box: distance 0.
  sim.robot.capsules = {Capsule{{-1, 0, 2}, {1, 0, 2}, 0.0F, 0}};
  sim.render(0, f);
  EXPECT_EQ(f.truth->analytic_contact.distance_m, 0.0F);
}

TEST(Simulator, RenderingAgainReusesBuffers) {
  Simulator sim = make_sim(true);
  sim.robot.capsules.push_back(robot_point({0, 0, 0.5F}));
  sim.scene.objects.push_back(wall(2.0F));
  sim.scene.objects.push_back(object({Shape::sphere({0, 0, 1.5F}, 0.3F)}, false));
  Frame f;
  sim.render(0, f);
  const uint16_t* depth = f.depth.pixels.data();
  const float* truth_depth = f.truth->depth_m.data();
  const float* cloud = sim.scratch.points_base.x.data();
  sim.render(1, f);
  EXPECT_EQ(f.depth.pixels.data(), depth);
  EXPECT_EQ(f.truth->depth_m.data(), truth_depth);
  EXPECT_EQ(sim.scratch.points_base.x.data(), cloud);
}

TEST(Simulator, UnsupportedResolutionThrows) {
  Simulator sim;
  sim.params.width = 100;
  Frame f;
  EXPECT_THROW(sim.render(0, f), std::invalid_argument);
}

TEST(SimSource, EndsAfterFramesFrames) {
  Simulator sim = make_sim(true);
  sim.params.width = 424;
  sim.params.height = 240;
  sim.params.frames = 3;
  sim.params.fps = 15.0;
  sim.scene.objects.push_back(wall(1.0F));
  SimSource source(sim);
  const SourceInfo info = source.info();
  EXPECT_EQ(info.type, "sim");
  EXPECT_FALSE(info.description.empty());
  EXPECT_EQ(info.frame_count, 3);
  EXPECT_EQ(info.nominal_fps, 15.0);
  EXPECT_EQ(info.intrinsics.width, 424);
  EXPECT_FLOAT_EQ(info.stereo_baseline_mm, kD435BaselineMm);
  Frame f;
  for (int64_t i = 0; i < 3; ++i) {
    ASSERT_EQ(source.next(f), Source::Status::frame);
    EXPECT_EQ(f.index, i);
  }
  EXPECT_EQ(source.next(f), Source::Status::end);
  EXPECT_EQ(source.next(f), Source::Status::end);
}

}  // namespace
}  // namespace hrcsense
