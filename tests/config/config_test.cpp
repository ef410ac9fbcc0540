// SPDX-License-Identifier: Apache-2.0
// Tests of load_config: defaults, every key family, --set overrides, errors, the camera pose.
#include "../support/scenes.hpp"
#include "config_test_util.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

TEST(Config, DefaultsWithoutFileMatchTheStructDefaults) {
  const Config config = load_config("", {});
  const SimParams sim;
  const PipelineParams pipeline;
  EXPECT_EQ(config.source.type, SourceType::sim);
  EXPECT_FALSE(config.source.pace);
  EXPECT_EQ(config.sim.seed, 1U);
  EXPECT_EQ(config.sim.width, sim.width);
  EXPECT_EQ(config.sim.height, sim.height);
  EXPECT_EQ(config.sim.frames, sim.frames);
  EXPECT_DOUBLE_EQ(config.sim.fps, sim.fps);
  EXPECT_FLOAT_EQ(config.sim.disparity_noise_px, sim.disparity_noise_px);
  EXPECT_TRUE(config.scene.objects.empty());
  EXPECT_EQ(config.filters_preset, FilterPreset::sdk);  // the RealSense Viewer's defaults (issue 4)
  EXPECT_EQ(config.pipeline.filters.order, filter_preset(FilterPreset::sdk).order);
  EXPECT_EQ(config.pipeline.background.frames, 100);
  EXPECT_FLOAT_EQ(config.pipeline.foreground.k_sigma, pipeline.foreground.k_sigma);
  EXPECT_FLOAT_EQ(config.pipeline.safety.slow_distance_m, pipeline.safety.slow_distance_m);
  EXPECT_FLOAT_EQ(config.pipeline.safety.stop_distance_m, pipeline.safety.stop_distance_m);
  ASSERT_EQ(fixed_robot_model(config).capsules.size(), 1U);  // the thesis's robot point, y down
  EXPECT_EQ(fixed_robot_model(config).capsules[0].a, Eigen::Vector3f(-0.5F, -0.5F, 0.5F));
  EXPECT_EQ(config.pipeline.backend, ProximityBackend::brute);
  EXPECT_TRUE(config.pipeline.T_base_camera.isApprox(Pose::Identity()));
  EXPECT_EQ(config.pipeline.robot.base_frame, BaseFrame::base);
  EXPECT_FALSE(config.canonical_yaml.empty());
  const std::string hash = config_hash(config);
  ASSERT_EQ(hash.size(), 16U);
  EXPECT_EQ(hash.find_first_not_of("0123456789abcdef"), std::string::npos);
}

TEST(Config, ReadsEveryKeyFamily) {
  TempDir dir;
  const std::string path = dir.write("all.yaml", R"(
source: {type: sim, path: rec/a, pace: true, loop: true, seed: 42, stereo_baseline_mm: 50.5}
sim: {width: 640, height: 480, fps: 15, frames: 77, noise: false, disparity_noise_px: 0.1, baseline_mm: 55}
camera:
  T_base_camera: {translation_m: [0.1, -0.2, 0.3], rotation_rpy_deg: [0, 0, 0]}
filters: {preset: none}
background: {frames: 12, path: bg.bin, moving_k_sigma: 5, moving_min_spread_m: 0.04, max_moving_share: 0.01,
             motion_min_width_px: 5, min_valid_ratio: 0.25, fill_radius_px: 8, unseen_min_frames: 20,
             max_noise_per_z2: 0.02}
foreground:
  k_sigma: 3.5
  min_margin_m: 0.03
  min_object_mm: 25
  workspace_base: {min: [-1, -2, -3], max: [1, 2, 3]}
robot:
  model: points
  points_base: [[1, 2, 3], [4, 5, 6]]
  padding_m: 0.05
  joints_rad: [0, 1, 2, 3, 4, 5]
  base_frame: base_link
proximity: {backend: brute, octree: {height: 6}}
safety: {slow_distance_m: 1.5, stop_distance_m: 0.7, max_frame_age_s: 0.25}
)");
  const Config c = load_config(path, {});
  EXPECT_EQ(c.file, path);
  EXPECT_EQ(c.source.path, "rec/a");
  EXPECT_TRUE(c.source.pace);
  EXPECT_TRUE(c.source.loop);
  EXPECT_EQ(c.sim.seed, 42U);  // source.seed drives the simulator
  EXPECT_FLOAT_EQ(c.source.stereo_baseline_mm, 50.5F);
  EXPECT_EQ(c.sim.width, 640);
  EXPECT_EQ(c.sim.height, 480);
  EXPECT_DOUBLE_EQ(c.sim.fps, 15.0);
  EXPECT_EQ(c.sim.frames, 77);
  EXPECT_FALSE(c.sim.noise);
  EXPECT_FLOAT_EQ(c.sim.disparity_noise_px, 0.1F);
  EXPECT_FLOAT_EQ(c.sim.baseline_mm, 55.0F);
  EXPECT_TRUE(c.pipeline.T_base_camera.translation().isApprox(Eigen::Vector3d(0.1, -0.2, 0.3), 1e-6));
  EXPECT_EQ(c.pipeline.background.frames, 12);
  EXPECT_EQ(c.background_path, "bg.bin");
  EXPECT_FLOAT_EQ(c.pipeline.background.moving_k_sigma, 5.0F);
  EXPECT_FLOAT_EQ(c.pipeline.background.moving_min_spread_m, 0.04F);
  EXPECT_FLOAT_EQ(c.pipeline.background.max_moving_share, 0.01F);
  EXPECT_EQ(c.pipeline.background.motion_min_width_px, 5);
  EXPECT_FLOAT_EQ(c.pipeline.background.min_valid_ratio, 0.25F);
  EXPECT_EQ(c.pipeline.background.fill_radius_px, 8);
  EXPECT_EQ(c.pipeline.background.unseen_min_frames, 20);
  EXPECT_FLOAT_EQ(c.pipeline.background.max_noise_per_z2, 0.02F);
  EXPECT_FLOAT_EQ(c.pipeline.foreground.k_sigma, 3.5F);
  EXPECT_FLOAT_EQ(c.pipeline.foreground.min_margin_m, 0.03F);
  EXPECT_FLOAT_EQ(c.pipeline.foreground.min_object_mm, 25.0F);
  EXPECT_EQ(c.pipeline.foreground.workspace_base.min, Eigen::Vector3f(-1, -2, -3));
  EXPECT_EQ(c.pipeline.foreground.workspace_base.max, Eigen::Vector3f(1, 2, 3));
  ASSERT_EQ(fixed_robot_model(c).capsules.size(), 2U);
  const Capsule second = fixed_robot_model(c).capsules[1];
  EXPECT_EQ(second.a, Eigen::Vector3f(4, 5, 6));
  EXPECT_EQ(second.b, Eigen::Vector3f(4, 5, 6));  // a robot point is a zero-length capsule
  EXPECT_FLOAT_EQ(second.radius_m, 0.05F);
  EXPECT_EQ(second.link, 1);
  EXPECT_EQ(c.robot_state.joints_rad, (JointAngles{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(c.pipeline.robot.base_frame, BaseFrame::base_link);
  EXPECT_EQ(c.pipeline.proximity.octree_height, 6);
  EXPECT_FLOAT_EQ(c.pipeline.safety.slow_distance_m, 1.5F);
  EXPECT_FLOAT_EQ(c.pipeline.safety.stop_distance_m, 0.7F);
  EXPECT_DOUBLE_EQ(c.pipeline.safety.max_frame_age_s, 0.25);
}

TEST(Config, SetOverridesScalarsAndListsInOrder) {
  TempDir dir;
  const std::string path = dir.write("c.yaml", "safety: {slow_distance_m: 2.0, stop_distance_m: 0.5}\n");
  const Config c = load_config(path, {"safety.slow_distance_m=1.25", "robot.points_base=[[0,0,1],[0.5,-1,2]]",
                                      "sim.frames=10", "sim.frames=20", "source.type=bag",
                                      "camera.T_base_camera={translation_m: [1, 2, 3]}"});
  EXPECT_FLOAT_EQ(c.pipeline.safety.slow_distance_m, 1.25F);  // the override wins over the file
  EXPECT_FLOAT_EQ(c.pipeline.safety.stop_distance_m, 0.5F);   // the file's other keys stay
  ASSERT_EQ(fixed_robot_model(c).capsules.size(), 2U);
  EXPECT_EQ(fixed_robot_model(c).capsules[0].a, Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(fixed_robot_model(c).capsules[1].a, Eigen::Vector3f(0.5F, -1, 2));
  EXPECT_EQ(c.sim.frames, 20);  // the last override wins
  EXPECT_EQ(c.source.type, SourceType::bag);
  EXPECT_TRUE(c.pipeline.T_base_camera.translation().isApprox(Eigen::Vector3d(1, 2, 3), 1e-6));
}

TEST(Config, RpyRotationIsRzRyRx) {
  const Config c = load_config("", {"camera.T_base_camera.rotation_rpy_deg=[30, 45, 60]",
                                    "camera.T_base_camera.translation_m=[1, 2, 3]"});
  // Rz(60)·Ry(45)·Rx(30) multiplied out by hand with cos/sin of 30°, 45°, 60°.
  Eigen::Matrix3d expected;
  expected << 0.35355339, -0.57322330, 0.73919892,  //
      0.61237244, 0.73919892, 0.28033009,          //
      -0.70710678, 0.35355339, 0.61237244;
  EXPECT_TRUE(c.pipeline.T_base_camera.linear().isApprox(expected, 1e-6)) << c.pipeline.T_base_camera.linear();
  // A camera-frame point maps into the base frame as R·p + t.
  const Eigen::Vector3d p_base = c.pipeline.T_base_camera * Eigen::Vector3d(1, 0, 0);
  EXPECT_TRUE(p_base.isApprox(Eigen::Vector3d(1.35355339, 2.61237244, 2.29289322), 1e-6)) << p_base;
}

TEST(Config, ReadsSceneObjectsOfEveryShape) {
  TempDir dir;
  const std::string path = dir.write("scene.yaml", R"(
scene:
  objects:
    - name: room
      shapes:
        - plane: {point: [0, 0, 2], normal: [0, 0, -4]}
        - box: {min: [-1, 0, 1], max: [1, 0.1, 1.5]}
    - name: person
      static: false
      first_frame: 10
      last_frame: 50
      path:
        - {t_s: 0.5, offset_m: [0, 0, 0]}
        - {t_s: 1.5, offset_m: [-1, 0, 0.5]}
      shapes:
        - sphere: {center: [0, -0.8, 2.3], radius_m: 0.11}
        - capsule: {a: [0, -0.6, 2.3], b: [0, 0.7, 2.3], radius_m: 0.15}
)");
  const Config c = load_config(path, {});
  ASSERT_EQ(c.scene.objects.size(), 2U);
  const SceneObject& room = c.scene.objects[0];
  EXPECT_EQ(room.name, "room");
  EXPECT_TRUE(room.is_static);  // default
  EXPECT_EQ(room.first_frame, 0);
  EXPECT_EQ(room.last_frame, -1);
  ASSERT_EQ(room.shapes.size(), 2U);
  EXPECT_EQ(room.shapes[0].type, Shape::Type::plane);
  EXPECT_EQ(room.shapes[0].point, Eigen::Vector3f(0, 0, 2));
  EXPECT_TRUE(room.shapes[0].normal.isApprox(Eigen::Vector3f(0, 0, -1)));  // normalised
  EXPECT_EQ(room.shapes[1].type, Shape::Type::box);
  EXPECT_EQ(room.shapes[1].max, Eigen::Vector3f(1, 0.1F, 1.5F));
  const SceneObject& person = c.scene.objects[1];
  EXPECT_FALSE(person.is_static);
  EXPECT_EQ(person.first_frame, 10);
  EXPECT_EQ(person.last_frame, 50);
  ASSERT_EQ(person.path.size(), 2U);
  EXPECT_DOUBLE_EQ(person.path[1].t_s, 1.5);
  EXPECT_EQ(person.path[1].offset_m, Eigen::Vector3f(-1, 0, 0.5F));
  ASSERT_EQ(person.shapes.size(), 2U);
  EXPECT_EQ(person.shapes[0].type, Shape::Type::sphere);
  EXPECT_EQ(person.shapes[0].point, Eigen::Vector3f(0, -0.8F, 2.3F));
  EXPECT_FLOAT_EQ(person.shapes[0].radius_m, 0.11F);
  EXPECT_EQ(person.shapes[1].type, Shape::Type::capsule);
  EXPECT_EQ(person.shapes[1].b, Eigen::Vector3f(0, 0.7F, 2.3F));
  EXPECT_FLOAT_EQ(person.shapes[1].radius_m, 0.15F);
}

TEST(Config, HashFollowsTheEffectiveConfiguration) {
  TempDir dir;
  const std::string a = dir.write("a.yaml", "sim: {frames: 50}\nsafety: {stop_distance_m: 0.4}\n");
  const std::string b = dir.write("b.yaml", "# same, other layout\nsafety:\n  stop_distance_m: 0.40\nsim:\n  frames: 50\n");
  const std::string explicit_default = dir.write("d.yaml", "background: {frames: 100}\n");
  EXPECT_EQ(config_hash(load_config(a, {})), config_hash(load_config(b, {})));
  EXPECT_NE(config_hash(load_config(a, {})), config_hash(load_config(a, {"sim.frames=51"})));
  // Spelling out a default changes nothing in effect, so nothing in the hash.
  EXPECT_EQ(config_hash(load_config(explicit_default, {})), config_hash(load_config("", {})));
  // The canonical YAML is itself a configuration that reads back to the same effect.
  const Config original = load_config(a, {"robot.points_base=[[0.1, 0.2, 0.3]]"});
  const std::string again = dir.write("canonical.yaml", original.canonical_yaml);
  EXPECT_EQ(config_hash(load_config(again, {})), config_hash(original));
}

TEST(Config, MakeSourceBuildsTheSimulator) {
  const Config c = load_config("", {"sim.frames=7", "sim.width=640", "source.seed=9",
                                    "robot.points_base=[[0, 0, 1]]"});
  const Simulator sim = make_simulator(c);
  EXPECT_EQ(sim.params.frames, 7);
  EXPECT_EQ(sim.params.seed, 9U);
  EXPECT_EQ(sim.robot.capsules.size(), 1U);
  const std::unique_ptr<Source> source = make_source(c);
  const SourceInfo info = source->info();
  EXPECT_EQ(info.type, "sim");
  EXPECT_EQ(info.frame_count, 7);
  EXPECT_EQ(info.intrinsics.width, 640);
  EXPECT_EQ(info.intrinsics.height, 480);
}

TEST(Config, ShippedConfigsLoad) {
  for (const char* name : {"/config/walk.yaml", "/config/thesis-box.yaml"}) {
    const std::string path = std::string(HRCSENSE_SOURCE_DIR) + name;
    if (!test::file_exists(path)) GTEST_SKIP() << path << " not written yet";
    const Config c = load_config(path, {});
    EXPECT_EQ(c.source.type, SourceType::sim) << name;
    EXPECT_FALSE(c.scene.objects.empty()) << name;
    EXPECT_FALSE(fixed_robot_model(c).capsules.empty()) << name;
    EXPECT_NO_THROW(make_source(c)) << name;
  }
  const Config box = load_config(test::scene_path("thesis-box.yaml"), {});
  // The thesis's robot point, y down (config/thesis-box.yaml says where it comes from).
  EXPECT_EQ(fixed_robot_model(box).capsules[0].a, Eigen::Vector3f(-0.5F, -0.5F, 0.5F));
}

}  // namespace
}  // namespace hrcsense
