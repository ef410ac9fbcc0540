// SPDX-License-Identifier: Apache-2.0
// A camera pose hrcsense is not told (docs/SIMULATOR.md): the simulator renders from its true
// pose (`sim.camera_T_base_camera`, moved by a knock from a frame on), the pipeline keeps the
// told one (camera.T_base_camera). Expectations worked by hand or against a second simulator
// that is given the true pose as its only pose.
#include "common/assembly.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr uint16_t kSphereLabel = 1;  // the only non-static object

// One sphere of radius 0.2 m about (0, 0, 2) m, base frame, in front of a wall at z = 3 m; the
// default camera (identity pose) looks along +z from the origin.
Scene sphere_scene() {
  Scene scene;
  SceneObject wall;
  wall.name = "wall";
  wall.shapes.push_back(Shape::plane({0.0F, 0.0F, 3.0F}, {0.0F, 0.0F, -1.0F}));
  scene.objects.push_back(wall);
  SceneObject sphere;
  sphere.name = "sphere";
  sphere.is_static = false;
  sphere.shapes.push_back(Shape::sphere({0.0F, 0.0F, 2.0F}, 0.2F));
  scene.objects.push_back(sphere);
  return scene;
}

Pose translated(const Eigen::Vector3d& t_m) {
  Pose pose = Pose::Identity();
  pose.translation() = t_m;
  return pose;
}

// The centre of the sphere through the noise-free points of its pixels (camera frame): the
// least-squares solution of 2 p·c − k = |p|² (k = |c|² − r²), exact for points on a sphere.
Eigen::Vector3d sphere_centre_camera(const Frame& frame) {
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  size_t count = 0;
  for (int v = 0; v < frame.intrinsics.height; ++v) {
    for (int u = 0; u < frame.intrinsics.width; ++u) {
      const size_t i = static_cast<size_t>(v) * frame.intrinsics.width + u;
      if (frame.truth->labels[i] != kSphereLabel) continue;
      const std::optional<Eigen::Vector3f> p =
          deproject(frame.intrinsics, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), frame.truth->depth_m[i]);
      if (!p) continue;
      const Eigen::Vector3d pd = p->cast<double>();
      const Eigen::Vector4d row(2.0 * pd.x(), 2.0 * pd.y(), 2.0 * pd.z(), -1.0);
      normal += row * row.transpose();
      rhs += row * pd.squaredNorm();
      ++count;
    }
  }
  EXPECT_GT(count, 1000U) << "the sphere should cover thousands of pixels at 2 m";
  return normal.ldlt().solve(rhs).head<3>();
}

void expect_same_frame(const Frame& a, const Frame& b, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.depth.pixels, b.depth.pixels);
  ASSERT_TRUE(a.truth && b.truth);
  EXPECT_EQ(a.truth->depth_m, b.truth->depth_m);
  EXPECT_EQ(a.truth->labels, b.truth->labels);
  EXPECT_EQ(a.truth->contact.valid, b.truth->contact.valid);
  EXPECT_EQ(a.truth->contact.distance_m, b.truth->contact.distance_m);
  EXPECT_EQ(a.truth->contact.closest_camera, b.truth->contact.closest_camera);
  EXPECT_EQ(a.truth->analytic_contact.closest_camera, b.truth->analytic_contact.closest_camera);
  ASSERT_EQ(a.color.has_value(), b.color.has_value());
  if (a.color) {
    EXPECT_EQ(a.color->rgb, b.color->rgb);
  }
}

TEST(SimCameraPose, ToldPoseOffByFiveCentimetresMovesTheSphereByThat) {
  Simulator sim;
  sim.params.noise = false;
  sim.params.color = false;
  sim.scene = sphere_scene();
  const Pose told = Pose::Identity();
  // The camera truly stands 5 cm further along base x than hrcsense is told.
  sim.T_base_camera = translated({0.05, 0.0, 0.0});
  Frame frame;
  sim.render(0, frame);

  // By hand: in the true camera frame the sphere's centre is (0 − 0.05, 0, 2 − 0) m, and the
  // told pose (the identity) maps that to the base frame unchanged: 5 cm short along x.
  const Eigen::Vector3d centre_camera = sphere_centre_camera(frame);
  const Eigen::Vector3d centre_told_base = told * centre_camera;
  EXPECT_NEAR(centre_told_base.x(), -0.05, 1e-3);
  EXPECT_NEAR(centre_told_base.y(), 0.0, 1e-3);
  EXPECT_NEAR(centre_told_base.z(), 2.0, 1e-3);
  // Mapped with the true pose, it is where the sphere is.
  const Eigen::Vector3d centre_true_base = sim.T_base_camera * centre_camera;
  EXPECT_NEAR((centre_true_base - Eigen::Vector3d(0.0, 0.0, 2.0)).norm(), 0.0, 1e-3);
}

TEST(SimCameraPose, TruthIsTheTrueGeometry) {
  Simulator sim;
  sim.params.noise = false;
  sim.scene = sphere_scene();
  sim.robot.capsules.push_back(Capsule{{0.0F, 0.0F, 1.0F}, {0.0F, 0.0F, 1.0F}, 0.0F, 0});  // 0.8 m before the sphere
  sim.T_base_camera = translated({0.05, 0.0, 0.0});
  Frame frame;
  sim.render(0, frame);
  const Contact& analytic = frame.truth->analytic_contact;
  ASSERT_TRUE(analytic.valid);
  // Base-frame distances need no camera pose: the sphere's nearest point (0, 0, 1.8) is 0.8 m
  // from the robot point wherever the camera stands.
  EXPECT_NEAR(analytic.distance_m, 0.8F, 1e-5F);
  EXPECT_NEAR((analytic.closest_base - Eigen::Vector3f(0.0F, 0.0F, 1.8F)).norm(), 0.0F, 1e-5F);
  // Its camera-frame point is seen from the true camera: 5 cm to the camera's −x.
  EXPECT_NEAR((analytic.closest_camera - Eigen::Vector3f(-0.05F, 0.0F, 1.8F)).norm(), 0.0F, 1e-5F);
  // The rendered contact is the pixel nearest the robot, at most a pixel's width from there.
  ASSERT_TRUE(frame.truth->contact.valid);
  EXPECT_NEAR(frame.truth->contact.distance_m, 0.8F, 5e-3F);
  EXPECT_NEAR(frame.truth->contact.closest_camera.x(), -0.05F, 5e-3F);
}

// A configuration of the sphere scene seen from 10 cm along base y; `extra` adds sim keys.
Config sphere_config(const std::vector<std::string>& extra) {
  std::vector<std::string> overrides = {
      "sim.frames=4",
      "camera.T_base_camera={translation_m: [0, 0.1, 0], rotation_rpy_deg: [0, 0, 0]}",
      "scene.objects=[{name: wall, static: true, shapes: [{plane: {point: [0, 0, 3], normal: [0, 0, -1]}}]},"
      " {name: sphere, static: false, shapes: [{sphere: {center: [0, 0, 2], radius_m: 0.2}}]}]"};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return load_config("", overrides);
}

TEST(SimCameraPose, WithoutTheKeyTheRenderIsTodaysPixelForPixel) {
  const Config config = sphere_config({});
  EXPECT_FALSE(config.sim_camera_T_base_camera.has_value());
  EXPECT_LT(config.sim_camera_knock.frame, 0);
  // Today's simulator: the told pose is the pose it renders from.
  Simulator today;
  today.params = config.sim;
  today.scene = config.scene;
  today.T_base_camera = config.pipeline.T_base_camera;
  today.robot = fixed_robot_model(config);
  const Simulator assembled = make_simulator(config);
  EXPECT_TRUE(assembled.T_base_camera.isApprox(config.pipeline.T_base_camera, 0.0));
  Frame expected, got;
  for (int64_t i = 0; i < 3; ++i) {
    today.render(i, expected);
    assembled.render(i, got);
    expect_same_frame(got, expected, "frame " + std::to_string(i));
  }
  // The key giving the told pose itself changes nothing either.
  const Simulator same = make_simulator(
      sphere_config({"sim.camera_T_base_camera={translation_m: [0, 0.1, 0], rotation_rpy_deg: [0, 0, 0]}"}));
  today.render(1, expected);
  same.render(1, got);
  expect_same_frame(got, expected, "the told pose given as the true one");
}

TEST(SimCameraPose, TheAssemblyRendersFromTheTruePoseAndThePipelineKeepsTheTold) {
  const Config config =
      sphere_config({"sim.camera_T_base_camera={translation_m: [0.05, 0.1, 0], rotation_rpy_deg: [0, 0, 0]}"});
  EXPECT_TRUE(config.pipeline.T_base_camera.isApprox(translated({0.0, 0.1, 0.0}), 1e-6));
  const Simulator sim = make_simulator(config);
  EXPECT_TRUE(sim.T_base_camera.isApprox(translated({0.05, 0.1, 0.0}), 1e-6));
  // A simulator given the true pose as its only pose renders the same frames ...
  Simulator only_true;
  only_true.params = config.sim;
  only_true.scene = config.scene;
  only_true.robot = fixed_robot_model(config);
  only_true.T_base_camera = translated({0.05, 0.1, 0.0});
  Frame expected, got;
  only_true.render(2, expected);
  sim.render(2, got);
  expect_same_frame(got, expected, "true pose");
  // ... and one given the told pose does not.
  only_true.T_base_camera = config.pipeline.T_base_camera;
  only_true.render(2, expected);
  EXPECT_NE(got.truth->depth_m, expected.truth->depth_m);
}

TEST(SimCameraPose, AKnockMovesThePoseFromItsFrameOn) {
  Simulator sim;  // noise on: the noise draws are per frame index, so equality is exact
  sim.scene = sphere_scene();
  sim.robot.capsules.push_back(Capsule{{0.0F, 0.0F, 1.0F}, {0.0F, 0.0F, 1.0F}, 0.0F, 0});
  sim.T_base_camera = translated({0.0, 0.0, 0.0});
  Pose knocked = translated({0.03, -0.02, 0.01});
  knocked.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix();  // about 3 degrees
  constexpr int64_t kKnockFrame = 3;

  Simulator unknocked = sim;
  Simulator knocked_only = sim;
  knocked_only.T_base_camera = knocked;
  sim.camera_knock = SimCameraKnock{kKnockFrame, knocked};

  Frame expected, got;
  for (int64_t i = 0; i < 6; ++i) {
    const Simulator& reference = i < kKnockFrame ? unknocked : knocked_only;
    reference.render(i, expected);
    sim.render(i, got);
    expect_same_frame(got, expected, "frame " + std::to_string(i));
    EXPECT_TRUE(sim.T_base_camera_at(i).isApprox(reference.T_base_camera, 0.0));
    // hit_at casts from the same pose as render().
    const int centre = expected.intrinsics.height / 2 * expected.intrinsics.width + expected.intrinsics.width / 2;
    EXPECT_EQ(sim.hit_at(i, centre).z_m, reference.hit_at(i, centre).z_m);
  }
  // The knock is a real change of the image: the frame before and the frame of the knock differ.
  unknocked.render(kKnockFrame, expected);
  sim.render(kKnockFrame, got);
  EXPECT_NE(got.truth->depth_m, expected.truth->depth_m);
}

TEST(SimCameraPose, AKnockFromTheConfiguration) {
  const Config config = sphere_config({"sim.camera_knock_frame=2",
                                       "sim.camera_knock_T_base_camera={translation_m: [0.02, 0.1, 0], "
                                       "rotation_rpy_deg: [0, 0, 5]}"});
  const Simulator sim = make_simulator(config);
  EXPECT_EQ(sim.camera_knock.frame, 2);
  EXPECT_TRUE(sim.T_base_camera_at(1).isApprox(config.pipeline.T_base_camera));
  EXPECT_TRUE(sim.T_base_camera_at(2).isApprox(config.sim_camera_knock.T_base_camera));
  EXPECT_NEAR(sim.T_base_camera_at(2).translation().x(), 0.02, 1e-6);
}

}  // namespace
}  // namespace hrcsense
