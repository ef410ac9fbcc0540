// SPDX-License-Identifier: Apache-2.0
// A cell with several cameras (H2; docs/CONFIG.md, "cameras", "cell"): the `cameras:` list is
// read into Config::cameras, `load_config(..., camera)` lays one entry over the top-level keys
// (and --set still wins), bad entries are errors naming the entry's key, `cell.*` and
// `sim.epoch` are read, and configurations without any of them keep their canonical text.
#include "config_test_util.hpp"

#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

// Two simulated cameras over a top-level camera at the origin; `left` has its own rate, seed and
// sensor settings.
const char* const kTwoCameras = R"(source: {type: sim, seed: 7}
sim: {fps: 30, width: 848, height: 480, noise: true}
camera:
  T_base_camera: {translation_m: [0, 0, 0], rotation_rpy_deg: [0, 0, 0]}
cameras:
  - name: front
    T_base_camera: {translation_m: [2.0, 0, 1.5], rotation_rpy_deg: [-120, 0, 90]}
  - name: left
    T_base_camera: {translation_m: [0.5, 2.0, 1.2], rotation_rpy_deg: [-120, 0, 180]}
    fps: 15
    source: {seed: 3}
    sim: {width: 640, height: 480, noise: false, disparity_noise_px: 0.05}
)";

Config load_named(const std::string& path, const std::string& camera, const std::vector<std::string>& sets = {}) {
  return load_config(path, sets, camera);
}

// Expects load_config(path, sets, camera) to fail with every needle in its message.
void expect_camera_error(const std::string& path, const std::string& camera, const std::vector<std::string>& needles) {
  try {
    (void)load_config(path, {}, camera);
    ADD_FAILURE() << "no ConfigError for camera '" << camera << "'";
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    for (const std::string& needle : needles) {
      EXPECT_NE(message.find(needle), std::string::npos) << "'" << needle << "' not in: " << message;
    }
  }
}

TEST(CamerasConfig, ReadsEveryEntryOnEveryLoad) {
  TempDir dir;
  const std::string path = dir.write("cell.yaml", kTwoCameras);
  const Config config = load_config(path, {});
  EXPECT_TRUE(config.camera.empty());
  ASSERT_EQ(config.cameras.size(), 2U);
  const CameraEntry& front = config.cameras[0];
  const CameraEntry& left = config.cameras[1];
  EXPECT_EQ(front.name, "front");
  EXPECT_EQ(left.name, "left");
  EXPECT_EQ(front.source_type, SourceType::sim);
  EXPECT_NEAR(front.T_base_camera.translation().x(), 2.0, 1e-6);
  EXPECT_NEAR(front.T_base_camera.translation().z(), 1.5, 1e-6);
  EXPECT_NEAR(left.T_base_camera.translation().y(), 2.0, 1e-6);
  // fps: the top-level sim.fps by default, the entry's own where it says.
  EXPECT_DOUBLE_EQ(front.fps, 30.0);
  EXPECT_DOUBLE_EQ(left.fps, 15.0);
  // Simulated cameras have intrinsics from their sensor settings: the D435i's at each size.
  ASSERT_TRUE(front.intrinsics.has_value());
  ASSERT_TRUE(left.intrinsics.has_value());
  EXPECT_EQ(front.intrinsics->width, 848);
  EXPECT_EQ(left.intrinsics->width, 640);
  EXPECT_EQ(left.intrinsics->height, 480);
  // Without --camera the top-level keys stand, and no grid is computed.
  EXPECT_NEAR(config.pipeline.T_base_camera.translation().norm(), 0.0, 1e-9);
  EXPECT_FALSE(config.pipeline.seen_free_grid.enabled);
  EXPECT_TRUE(config.cell.grid.enabled);
}

TEST(CamerasConfig, TheSelectedEntryIsLaidOverTheTopLevelKeys) {
  TempDir dir;
  const std::string path = dir.write("cell.yaml", kTwoCameras);
  const Config front = load_named(path, "front");
  EXPECT_EQ(front.camera, "front");
  EXPECT_NEAR(front.pipeline.T_base_camera.translation().x(), 2.0, 1e-6);
  EXPECT_DOUBLE_EQ(front.sim.fps, 30.0);
  EXPECT_EQ(front.sim.seed, 7U);
  EXPECT_EQ(front.sim.width, 848);

  const Config left = load_named(path, "left");
  EXPECT_EQ(left.camera, "left");
  EXPECT_NEAR(left.pipeline.T_base_camera.translation().x(), 0.5, 1e-6);
  EXPECT_NEAR(left.pipeline.T_base_camera.translation().y(), 2.0, 1e-6);
  EXPECT_NEAR(left.pipeline.T_base_camera.translation().z(), 1.2, 1e-6);
  // Yaw 180°: the camera's x axis (rpy -120, 0, 180: roll about x first) points along -x.
  EXPECT_NEAR(left.pipeline.T_base_camera.linear()(0, 0), -1.0, 1e-6);
  EXPECT_DOUBLE_EQ(left.sim.fps, 15.0);
  EXPECT_EQ(left.sim.seed, 3U);  // source.seed from the entry
  EXPECT_EQ(left.sim.width, 640);
  EXPECT_FALSE(left.sim.noise);
  EXPECT_FLOAT_EQ(left.sim.disparity_noise_px, 0.05F);
  // The list itself is the same whichever camera was chosen.
  ASSERT_EQ(left.cameras.size(), 2U);
  EXPECT_DOUBLE_EQ(left.cameras[0].fps, 30.0);
  // The effective configuration (and so the hash) says which camera's keys are in effect.
  EXPECT_NE(front.canonical_yaml, left.canonical_yaml);
  EXPECT_NE(front.canonical_yaml, load_config(path, {}).canonical_yaml);
  EXPECT_NE(config_hash(left), config_hash(front));
  EXPECT_NE(left.canonical_yaml.find("640"), std::string::npos);
}

TEST(CamerasConfig, SetOverridesWinOverTheEntry) {
  TempDir dir;
  const std::string path = dir.write("cell.yaml", kTwoCameras);
  const Config left = load_named(path, "left",
                                 {"camera.T_base_camera.translation_m=[0, 0, 3]", "sim.fps=10", "source.seed=11"});
  EXPECT_NEAR(left.pipeline.T_base_camera.translation().z(), 3.0, 1e-6);
  EXPECT_NEAR(left.pipeline.T_base_camera.translation().y(), 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(left.sim.fps, 10.0);
  EXPECT_EQ(left.sim.seed, 11U);
}

TEST(CamerasConfig, ACameraOfACellComputesTheGrid) {
  TempDir dir;
  const std::string path = dir.write("cell.yaml", std::string(kTwoCameras) +
                                                      "cell: {workspace_base: {min: [-1, -1, 0], max: [1, 2, 1.5]}, "
                                                      "voxel_m: 0.1}\n");
  const Config front = load_named(path, "front");
  const SeenFreeGridSpec& grid = front.pipeline.seen_free_grid;
  EXPECT_TRUE(grid.enabled);
  EXPECT_FLOAT_EQ(grid.voxel_m, 0.1F);
  EXPECT_FLOAT_EQ(grid.box_base.min().x(), -1.0F);
  EXPECT_FLOAT_EQ(grid.box_base.max().y(), 2.0F);
  EXPECT_FLOAT_EQ(grid.box_base.max().z(), 1.5F);
  EXPECT_NE(front.canonical_yaml.find("voxel_m: 0.1"), std::string::npos) << front.canonical_yaml;
}

TEST(CamerasConfig, TheGridDefaultsToTheWorkspaceOrThreeByThreeByTwoMetres) {
  TempDir dir;
  const Config plain = load_named(dir.write("plain.yaml", kTwoCameras), "front");
  EXPECT_FLOAT_EQ(plain.pipeline.seen_free_grid.voxel_m, 0.05F);
  EXPECT_FLOAT_EQ(plain.pipeline.seen_free_grid.box_base.min().x(), -1.5F);
  EXPECT_FLOAT_EQ(plain.pipeline.seen_free_grid.box_base.min().z(), 0.0F);
  EXPECT_FLOAT_EQ(plain.pipeline.seen_free_grid.box_base.max().y(), 1.5F);
  EXPECT_FLOAT_EQ(plain.pipeline.seen_free_grid.box_base.max().z(), 2.0F);
  const Config workspace = load_named(
      dir.write("ws.yaml", std::string(kTwoCameras) +
                               "foreground: {workspace_base: {min: [-0.5, -0.6, -0.7], max: [0.8, 0.9, 1.1]}}\n"),
      "left");
  EXPECT_FLOAT_EQ(workspace.pipeline.seen_free_grid.box_base.min().y(), -0.6F);
  EXPECT_FLOAT_EQ(workspace.pipeline.seen_free_grid.box_base.max().z(), 1.1F);
}

TEST(CamerasConfig, BadGridsAreRefused) {
  TempDir dir;
  const std::string path = dir.write("cell.yaml", kTwoCameras);
  expect_config_error(path, {"cell.voxel_m=0.001"}, {"cell.voxel_m"});
  expect_config_error(path, {"cell.voxel_m=0.6"}, {"cell.voxel_m"});
  expect_config_error(path, {"cell.workspace_base.min=[0, 0, 0]", "cell.workspace_base.max=[1, 1, 0]"},
                      {"cell.workspace_base.min", "cell.workspace_base.max"});
  // 100 x 100 x 20 m in 1 cm cubes would be 2e11 cubes.
  expect_config_error(path, {"cell.workspace_base.min=[-50, -50, 0]", "cell.workspace_base.max=[50, 50, 20]",
                             "cell.voxel_m=0.01"},
                      {"cubes", "cell.voxel_m"});
}

TEST(CamerasConfig, TheFusersPriorityIsOffByDefaultAndWithinSchedFifosRange) {
  TempDir dir;
  const std::string path = dir.write("cell.yaml", kTwoCameras);
  EXPECT_EQ(load_config(path, {}).cell.fuser_priority, 0);
  EXPECT_EQ(load_config(path, {"cell.fuser_priority=42"}).cell.fuser_priority, 42);
  EXPECT_EQ(load_config(path, {"cell.fuser_priority=99"}).cell.fuser_priority, 99);
  expect_config_error(path, {"cell.fuser_priority=100"}, {"cell.fuser_priority"});
  expect_config_error(path, {"cell.fuser_priority=-1"}, {"cell.fuser_priority"});
  expect_config_error(path, {"cell.fuser_priority=1.5"}, {"cell.fuser_priority"});
  expect_config_error(path, {"cell.fuser_priority=.nan"}, {"cell.fuser_priority"});
}

TEST(CamerasConfig, UnknownCameraNamesTheEntries) {
  TempDir dir;
  const std::string path = dir.write("cell.yaml", kTwoCameras);
  expect_camera_error(path, "right", {"cell.yaml", "'right'", "front, left"});
  expect_camera_error("", "front", {"no cameras"});
}

TEST(CamerasConfig, BadEntriesNameTheirKey) {
  TempDir dir;
  const std::string pose = "T_base_camera: {translation_m: [0, 0, 1], rotation_rpy_deg: [0, 0, 0]}";
  const auto file = [&](const std::string& entries) { return dir.write("bad.yaml", "cameras:\n" + entries); };
  expect_config_error(file("  - {name: a, " + pose + "}\n  - {name: b, " + pose + ", fov: 87}\n"), {},
                      {"bad.yaml", "cameras[1].fov", "unknown key"});
  expect_config_error(file("  - {name: 2cam, " + pose + "}\n"), {}, {"cameras[0].name", "2cam"});
  expect_config_error(file("  - {name: cam-left, " + pose + "}\n"), {}, {"cameras[0].name", "cam-left"});
  expect_config_error(file("  - {name: a, " + pose + "}\n  - {name: a, " + pose + "}\n"), {},
                      {"cameras[1].name", "unique"});
  expect_config_error(file("  - {" + pose + "}\n"), {}, {"cameras[0]", "name"});
  expect_config_error(file("  - {name: a}\n"), {}, {"cameras[0]", "T_base_camera"});
  expect_config_error(file("  - {name: a, T_base_camera: {translation_m: [0, 0, 1]}}\n"), {},
                      {"cameras[0].T_base_camera", "rotation_rpy_deg"});
  expect_config_error(file("  - {name: a, " + pose + ", fps: 0}\n"), {}, {"cameras[0].fps"});
  expect_config_error(file("  - {name: a, " + pose + ", source: {sead: 3}}\n"), {},
                      {"cameras[0].source.sead", "unknown key"});
  expect_config_error(file("  - {name: a, " + pose + ", sim: {ros2: {namespace: /x}}}\n"), {},
                      {"cameras[0].sim.ros2", "unknown key"});
  // A value an entry lays over the top-level keys is checked as they are, naming the entry.
  expect_config_error(file("  - {name: a, " + pose + "}\n  - {name: b, " + pose + ", sim: {width: 17}}\n"), {},
                      {"cameras[1]", "'b'", "sim.width"});
  expect_config_error(dir.write("empty.yaml", "cameras: []\n"), {}, {"cameras", "non-empty"});
}

TEST(CamerasConfig, ASourceMapReplacesOnlyTheKeysItNames) {
  TempDir dir;
  const std::string path = dir.write(
      "ros.yaml",
      "source: {type: ros2, ros2: {namespace: /top/camera, domain_id: 5}}\n"
      "cameras:\n"
      "  - name: cam_left\n"
      "    T_base_camera: {translation_m: [0, 1, 1], rotation_rpy_deg: [0, 0, 0]}\n"
      "    fps: 15\n"
      "    source: {ros2: {namespace: /cam_left/camera}}\n"
      "  - name: cam_sim\n"
      "    T_base_camera: {translation_m: [0, -1, 1], rotation_rpy_deg: [0, 0, 0]}\n"
      "    source: {type: sim, seed: 4}\n");
  const Config config = load_named(path, "cam_left");
  EXPECT_EQ(config.source.type, SourceType::ros2);
  EXPECT_EQ(config.source.ros2.node_namespace, "/cam_left/camera");
  EXPECT_EQ(config.source.ros2.domain_id, 5);
  ASSERT_EQ(config.cameras.size(), 2U);
  EXPECT_EQ(config.cameras[0].source_type, SourceType::ros2);
  EXPECT_DOUBLE_EQ(config.cameras[0].fps, 15.0);
  EXPECT_FALSE(config.cameras[0].intrinsics.has_value());  // a camera reports its own
  EXPECT_EQ(config.cameras[1].source_type, SourceType::sim);
  EXPECT_TRUE(config.cameras[1].intrinsics.has_value());
  const Config sim = load_named(path, "cam_sim");
  EXPECT_EQ(sim.source.type, SourceType::sim);
  EXPECT_EQ(sim.sim.seed, 4U);
}

TEST(CamerasConfig, ConfigurationsWithoutCamerasKeepTheirCanonicalText) {
  const Config defaults = load_config("", {});
  EXPECT_TRUE(defaults.cameras.empty());
  EXPECT_FALSE(defaults.cell.grid.enabled);
  EXPECT_FALSE(defaults.pipeline.seen_free_grid.enabled);
  EXPECT_FALSE(defaults.sim_epoch_ns.has_value());
  const std::filesystem::path folder = std::filesystem::path(HRCSENSE_SOURCE_DIR) / "config";
  int without = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".yaml") continue;
    const Config shipped = load_config(entry.path().string(), {});
    if (!shipped.cameras.empty()) continue;
    SCOPED_TRACE(entry.path().filename().string());
    const YAML::Node canonical = YAML::Load(shipped.canonical_yaml);
    EXPECT_FALSE(canonical["cameras"].IsDefined());
    EXPECT_FALSE(canonical["cell"].IsDefined());
    EXPECT_FALSE(canonical["sim"]["epoch"].IsDefined());
    ++without;
  }
  EXPECT_GT(without, 0);
  // A cell key given alone is in effect and in the text.
  EXPECT_NE(load_config("", {"cell.voxel_m=0.1"}).canonical_yaml.find("voxel_m"), std::string::npos);
}

TEST(CamerasConfig, SimEpochIsSecondsSinceTheUnixEpoch) {
  const Config config = load_config("", {"sim.epoch=1700000000.25"});
  ASSERT_TRUE(config.sim_epoch_ns.has_value());
  EXPECT_EQ(*config.sim_epoch_ns, 1'700'000'000'250'000'000LL);
  EXPECT_NE(config.canonical_yaml.find("epoch"), std::string::npos);
  EXPECT_EQ(*load_config("", {"sim.epoch=0"}).sim_epoch_ns, 0);
  expect_config_error("", {"sim.epoch=-1"}, {"sim.epoch"});
  expect_config_error("", {"sim.epoch=.nan"}, {"sim.epoch"});
  expect_config_error("", {"sim.epoch=.inf"}, {"sim.epoch"});
  expect_config_error("", {"sim.epoch=soon"}, {"sim.epoch"});
}

TEST(CamerasConfig, TheThreeCameraCellLoadsForEachCamera) {
  const std::string path = (std::filesystem::path(HRCSENSE_SOURCE_DIR) / "config" / "cell-ur5-3cam.yaml").string();
  const Config plain = load_config(path, {});
  ASSERT_EQ(plain.cameras.size(), 3U);
  EXPECT_EQ(plain.robot_model, RobotModelType::ur5);
  EXPECT_EQ(plain.pipeline.safety.mode, SafetyParams::Mode::ssm);
  EXPECT_EQ(plain.pipeline.background.frames, 100);
  // A run without --camera measures as the first camera.
  EXPECT_TRUE(plain.pipeline.T_base_camera.isApprox(plain.cameras[0].T_base_camera, 1e-9));
  std::vector<Pose> poses;
  for (const CameraEntry& entry : plain.cameras) {
    SCOPED_TRACE(entry.name);
    const Config one = load_named(path, entry.name);
    EXPECT_EQ(one.camera, entry.name);
    EXPECT_TRUE(one.pipeline.T_base_camera.isApprox(entry.T_base_camera, 1e-9));
    EXPECT_TRUE(one.pipeline.seen_free_grid.enabled);
    EXPECT_DOUBLE_EQ(entry.fps, 30.0);
    ASSERT_TRUE(entry.intrinsics.has_value());
    EXPECT_EQ(entry.intrinsics->width, 848);
    EXPECT_EQ(entry.intrinsics->height, 480);
    // Each camera looks down at the table's centre (0.3, 0, 0): its optical axis (z) passes
    // within 5 cm of it.
    const Eigen::Vector3d origin = one.pipeline.T_base_camera.translation();
    const Eigen::Vector3d axis = one.pipeline.T_base_camera.linear().col(2);
    const Eigen::Vector3d to_centre = Eigen::Vector3d(0.3, 0.0, 0.0) - origin;
    EXPECT_LT((to_centre - to_centre.dot(axis) * axis).norm(), 0.05);
    for (const Pose& other : poses) EXPECT_GT((other.translation() - origin).norm(), 1.5);
    poses.push_back(one.pipeline.T_base_camera);
  }
}

TEST(CamerasConfig, TheEmptyCellDiffersOnlyInThePerson) {
  const std::filesystem::path folder = std::filesystem::path(HRCSENSE_SOURCE_DIR) / "config";
  const Config full = load_config((folder / "cell-ur5-3cam.yaml").string(), {});
  const Config empty = load_config((folder / "cell-ur5-3cam-empty.yaml").string(), {});
  YAML::Node full_text = YAML::Load(full.canonical_yaml);
  const YAML::Node empty_text = YAML::Load(empty.canonical_yaml);
  // Take the person out of the full cell's effective configuration: what remains is the empty cell's.
  YAML::Node objects(YAML::NodeType::Sequence);
  int people = 0;
  for (const YAML::Node& object : full_text["scene"]["objects"]) {
    if (object["name"].as<std::string>() == "person") {
      ++people;
      continue;
    }
    objects.push_back(object);
  }
  EXPECT_EQ(people, 1);
  full_text["scene"]["objects"] = objects;
  YAML::Emitter full_out;
  full_out << full_text;
  YAML::Emitter empty_out;
  empty_out << empty_text;
  EXPECT_EQ(std::string(full_out.c_str()), std::string(empty_out.c_str()));
}

}  // namespace
}  // namespace hrcsense
