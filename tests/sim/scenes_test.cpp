// SPDX-License-Identifier: Apache-2.0
// The shipped scene files (config/*.yaml) do what their comments promise, checked numerically.

#include "../support/scenes.hpp"
#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::scene_path;

#if defined(__SANITIZE_ADDRESS__)
constexpr int64_t kStep = 3;  // sanitizers: every third frame (the closest approach lasts 30)
#else
constexpr int64_t kStep = 1;
#endif

TEST(Scenes, WalkApproachesTheRobotPointTo029Metres) {
  // The truth does not depend on the noise; without it rendering is faster.
  const Config config = load_config(scene_path("walk.yaml"), {"sim.noise=false"});
  const Simulator sim = make_simulator(config);
  ASSERT_EQ(sim.robot.capsules.size(), 1U);
  const double frames_s = static_cast<double>(sim.params.frames) / sim.params.fps;
  EXPECT_GE(frames_s, 10.0);
  EXPECT_LE(frames_s, 15.0);
  EXPECT_NEAR(sim.robot.capsules[0].a.norm(), 1.6F, 0.1F);  // the robot point, ~1.6 m from the camera

  Frame f;
  float min_analytic_m = INFINITY;
  float min_truth_m = INFINITY;
  float start_m = -1.0F;
  float min_depth_m = INFINITY;
  float max_depth_m = 0.0F;
  int64_t first_seen = -1;
  int64_t last_seen = -1;
  // Every frame around the entry (the start distance), every kStep-th elsewhere.
  for (int64_t i = 0; i < sim.params.frames; i += (i >= 100 && i < 140) ? 1 : kStep) {
    sim.render(i, f);
    const GroundTruth& truth = *f.truth;
    for (size_t p = 0; p < truth.labels.size(); ++p) {
      if (truth.labels[p] == kStaticLabel) continue;
      min_depth_m = std::min(min_depth_m, truth.depth_m[p]);
      max_depth_m = std::max(max_depth_m, truth.depth_m[p]);
    }
    ASSERT_EQ(truth.analytic_contact.valid, truth.contact.valid) << "frame " << i;
    if (!truth.analytic_contact.valid) continue;
    if (first_seen < 0) {
      first_seen = i;
      start_m = truth.analytic_contact.distance_m;
    }
    last_seen = i;
    min_analytic_m = std::min(min_analytic_m, truth.analytic_contact.distance_m);
    min_truth_m = std::min(min_truth_m, truth.contact.distance_m);
  }
  std::printf("walk: person in view frames %lld-%lld, start %.3f m, closest %.4f m (pixels %.4f m), depth %.2f-%.2f m\n",
              static_cast<long long>(first_seen), static_cast<long long>(last_seen), start_m, min_analytic_m,
              min_truth_m, min_depth_m, max_depth_m);
  ASSERT_GE(first_seen, 100) << "the person must not appear while the background is learnt";
  EXPECT_LT(first_seen, 130);
  EXPECT_LT(last_seen, sim.params.frames - 30) << "the person leaves the view before the end";
  EXPECT_GE(start_m, 2.5F);
  EXPECT_LE(start_m, 2.7F);
  EXPECT_GE(min_analytic_m, 0.28F);
  EXPECT_LE(min_analytic_m, 0.30F);
  // The rendered pixels reach the closest approach within a pixel's footprint.
  EXPECT_GE(min_truth_m, min_analytic_m - 1e-5F);
  EXPECT_LE(min_truth_m, min_analytic_m + 0.005F);
  EXPECT_GE(min_depth_m, 1.0F);
  EXPECT_LE(max_depth_m, 2.5F);
}

TEST(Scenes, ThesisBoxContactIsTheFrontTopLeftVertex) {
  const Config config = load_config(scene_path("thesis-box.yaml"), {"sim.noise=false"});
  const Simulator sim = make_simulator(config);
  ASSERT_GE(sim.params.frames, 400);
  ASSERT_EQ(sim.params.width, 848);
  ASSERT_EQ(sim.params.height, 480);
  ASSERT_TRUE(sim.T_base_camera.isApprox(Pose::Identity()));
  const Eigen::Vector3f vertex(0.5F, 0.0F, 1.0F);
  const Eigen::Vector3f robot_point(-0.5F, -0.5F, 0.5F);
  const float expected_m = (vertex - robot_point).norm();  // sqrt(1.5) = 1.2247 m

  Frame f;
  for (const int64_t i : {int64_t{0}, int64_t{99}}) {
    sim.render(i, f);
    EXPECT_FALSE(f.truth->contact.valid) << "no box while learning, frame " << i;
  }
  for (int64_t i = 100; i < sim.params.frames; i += 50 * kStep) {
    sim.render(i, f);
    const GroundTruth& truth = *f.truth;
    ASSERT_TRUE(truth.contact.valid) << "frame " << i;
    ASSERT_TRUE(truth.analytic_contact.valid) << "frame " << i;
    EXPECT_LT((truth.contact.closest_base - vertex).norm(), 0.003F) << "frame " << i;
    EXPECT_NEAR(truth.contact.distance_m, expected_m, 0.003F) << "frame " << i;
    EXPECT_NEAR(truth.analytic_contact.distance_m, expected_m, 1e-5F) << "frame " << i;
    EXPECT_LT((truth.analytic_contact.closest_base - vertex).norm(), 1e-6F) << "frame " << i;
    EXPECT_LT((truth.analytic_contact.closest_robot_base - robot_point).norm(), 1e-6F) << "frame " << i;
  }
}

constexpr const char* kAllScenes[] = {"walk.yaml", "thesis-box.yaml", "thesis-box-human.yaml", "cell-ur5.yaml",
                                      "clutter.yaml"};

/// Pixels of non-static objects in frame i (labels do not depend on the noise).
size_t moving_pixels(const Simulator& sim, int64_t i, Frame& f) {
  sim.render(i, f);
  return static_cast<size_t>(
      std::count_if(f.truth->labels.begin(), f.truth->labels.end(), [](uint16_t l) { return l != kStaticLabel; }));
}

// Every scene learns an empty cell: no person or object enters during the background frames,
// and afterwards every non-static object of the scene is seen.
TEST(Scenes, EmptyWhileLearningThenPeopleEnter) {
  for (const char* name : kAllScenes) {
    const Config config = load_config(scene_path(name), {"sim.noise=false", "sim.color=false"});
    const Simulator sim = make_simulator(config);
    const int64_t learn = config.pipeline.background.frames;
    ASSERT_GE(learn, 30) << name;
    ASSERT_GT(sim.params.frames, learn + 100) << name;
    Frame f;
    for (int64_t i = 0; i < learn; i += (i + 1 < learn ? 7 * kStep : 1)) {
      EXPECT_EQ(moving_pixels(sim, i, f), 0U) << name << " frame " << i;
    }
    EXPECT_EQ(moving_pixels(sim, learn - 1, f), 0U) << name << " last learning frame";
    size_t moving_objects = 0;
    for (const SceneObject& o : sim.scene.objects) moving_objects += o.is_static ? 0 : 1;
    std::vector<bool> seen(moving_objects + 1, false);
    for (int64_t i = learn; i < sim.params.frames; i += 10 * kStep) {
      sim.render(i, f);
      for (const uint16_t l : f.truth->labels) seen[l] = true;
    }
    for (size_t label = 1; label <= moving_objects; ++label) {
      EXPECT_TRUE(seen[label]) << name << ": non-static object " << label << " never in view";
    }
  }
}

// thesis-box-human: the person stands at least 0.15 m farther from the robot point than the
// box, so the true closest point is the box's front top left vertex in every frame.
TEST(Scenes, ThesisBoxHumanContactIsOnTheBoxInEveryFrame) {
  const Config config = load_config(scene_path("thesis-box-human.yaml"), {"sim.noise=false", "sim.color=false"});
  EXPECT_EQ(config.filters_preset, FilterPreset::thesis);
  const Simulator sim = make_simulator(config);
  Simulator person_only = sim;  // the same scene without the box: the person's own distance
  const auto box_it = std::find_if(person_only.scene.objects.begin(), person_only.scene.objects.end(),
                                   [](const SceneObject& o) { return o.name == "box"; });
  ASSERT_NE(box_it, person_only.scene.objects.end());
  person_only.scene.objects.erase(box_it);
  const Eigen::Vector3f vertex(0.5F, 0.0F, 1.0F);
  const float box_m = (vertex - Eigen::Vector3f(-0.5F, -0.5F, 0.5F)).norm();  // 1.2247 m
  constexpr uint16_t kBoxLabel = 1;  // the first non-static object
  Frame f;
  Frame g;
  size_t person_frames = 0;
  float person_min_m = INFINITY;
  for (int64_t i = 100; i < sim.params.frames; i += kStep) {
    sim.render(i, f);
    const GroundTruth& truth = *f.truth;
    ASSERT_TRUE(truth.contact.valid) << "frame " << i;
    ASSERT_GE(truth.contact.pixel, 0) << "frame " << i;
    EXPECT_EQ(truth.labels[static_cast<size_t>(truth.contact.pixel)], kBoxLabel) << "frame " << i;
    EXPECT_LT((truth.contact.closest_base - vertex).norm(), 0.003F) << "frame " << i;
    EXPECT_LT((truth.analytic_contact.closest_base - vertex).norm(), 1e-5F) << "frame " << i;
    person_only.render(i, g);
    if (!g.truth->analytic_contact.valid) continue;
    ++person_frames;
    person_min_m = std::min(person_min_m, g.truth->analytic_contact.distance_m);
    EXPECT_GE(g.truth->analytic_contact.distance_m, box_m + 0.15F) << "frame " << i;
  }
  std::printf("thesis-box-human: person in view %zu frames, nearest %.3f m (box %.4f m)\n", person_frames,
              person_min_m, box_m);
  EXPECT_GT(person_frames * static_cast<size_t>(kStep), 200U) << "the person is in view from about frame 110";
}

TEST(Scenes, InfoPrintsTheFillRate) {
  const std::string command = std::string(HRCSENSE_CLI) + " info --config " + scene_path("walk.yaml") + " 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  ASSERT_EQ(pclose(pipe), 0) << output;
  const size_t at = output.find("\nfill rate: ");
  ASSERT_NE(at, std::string::npos) << output;
  double percent = 0.0;
  ASSERT_EQ(std::sscanf(output.c_str() + at, "\nfill rate: %lf %%", &percent), 1) << output;
  EXPECT_GE(percent, 70.0);
  EXPECT_LE(percent, 98.0);
  // The same figure as the library's, to the printed digit.
  const Simulator sim = make_simulator(load_config(scene_path("walk.yaml"), {}));
  EXPECT_NEAR(percent, 100.0 * sim_fill_rate(sim, 0, 10), 0.051);
}

TEST(Scenes, SensorKeysAndMaterialsAreRead) {
  const Config config = load_config(scene_path("walk.yaml"), {"sim.edge_dropout=0.5", "sim.left_band=false",
                                                              "sim.min_range_m=0.3", "sim.correlated_noise_px=0.02"});
  EXPECT_FLOAT_EQ(config.sim.edge_dropout, 0.5F);
  EXPECT_FALSE(config.sim.left_band);
  EXPECT_FLOAT_EQ(config.sim.min_range_m, 0.3F);
  EXPECT_FLOAT_EQ(config.sim.correlated_noise_px, 0.02F);
  EXPECT_TRUE(config.sim.occlusion_shadows);  // untouched keys keep their defaults
  const auto workbench = std::find_if(config.scene.objects.begin(), config.scene.objects.end(),
                                      [](const SceneObject& o) { return o.name == "workbench"; });
  ASSERT_NE(workbench, config.scene.objects.end());
  EXPECT_TRUE(workbench->material.dark);
  EXPECT_FALSE(workbench->material.shiny);
  // The effective configuration round-trips the material.
  EXPECT_NE(config.canonical_yaml.find("material: [dark]"), std::string::npos);
  const auto error_of = [](const std::vector<std::string>& sets) {
    try {
      load_config("", sets);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of({"sim.edge_dropout=1.5"}).find("sim.edge_dropout"), std::string::npos);
  EXPECT_NE(error_of({"scene.objects=[{shapes: [{sphere: {center: [0,0,1], radius_m: 0.1}}], material: [velvet]}]"})
                .find("scene.objects[0].material"),
            std::string::npos);
}

// cell-ur5: a D435 at its best depth mode, 848x480 (depth and colour), over a UR5 given by
// `robot.model: ur5`, searched as capsules and rendered as a static object.
TEST(Scenes, CellUr5IsAUr5CellSeenAt848x480) {
  const Config config = load_config(scene_path("cell-ur5.yaml"), {"sim.noise=false"});
  const Simulator sim = make_simulator(config);
  Frame f;
  sim.render(0, f);
  EXPECT_EQ(f.depth.width, 848);
  EXPECT_EQ(f.depth.height, 480);
  EXPECT_NEAR(f.intrinsics.fx, 418.265F, 1e-3F);  // the D435i's 848x480 depth intrinsics
  ASSERT_TRUE(f.color);
  EXPECT_EQ(f.color->width, 848);
  EXPECT_EQ(f.color->height, 480);
  EXPECT_EQ(config.robot_model, RobotModelType::ur5);
  EXPECT_GT(sim.robot.capsules.size(), 1U) << "an arm of capsules, not one point";
  const auto robot = std::find_if(sim.scene.objects.begin(), sim.scene.objects.end(),
                                  [](const SceneObject& o) { return o.name == "robot"; });
  ASSERT_NE(robot, sim.scene.objects.end());
  EXPECT_TRUE(robot->is_static);
  EXPECT_GT(robot->shapes.size(), 1U);
}

// clutter: several people at once and the surfaces a D435 loses depth on.
TEST(Scenes, ClutterHasThreeWalkingPeopleADarkAndAShinyObject) {
  const Simulator sim = make_simulator(load_config(scene_path("clutter.yaml"), {}));
  size_t people = 0;
  bool dark = false;
  bool shiny = false;
  for (const SceneObject& o : sim.scene.objects) {
    people += !o.is_static && !o.path.empty() && o.name.rfind("person", 0) == 0 ? 1U : 0U;
    dark = dark || o.material.dark;
    shiny = shiny || o.material.shiny;
  }
  EXPECT_GE(people, 3U);
  EXPECT_TRUE(dark) << "no object with material: [dark]";
  EXPECT_TRUE(shiny) << "no object with material: [shiny]";
}

/// Valid share of a real D435 depth frame (the Depth Quality Tool's fill rate, whole image).
double real_fill_rate(const std::string& file) {
  DepthImage depth;
  read_depth_png(std::string(HRCSENSE_SHARED_DIR) + "/data/librealsense_d435_single_frame/" + file, depth);
  const auto valid = std::count_if(depth.pixels.begin(), depth.pixels.end(), [](uint16_t raw) { return raw != 0; });
  return static_cast<double>(valid) / static_cast<double>(depth.pixels.size());
}

// The shipped scenes lose depth like a real D435 does: between 70 % and 98 % valid over the
// first frames (docs/SIMULATOR.md reports the figures beside the real frame's).
TEST(Scenes, FillRateOfTheShippedScenesIsD435Like) {
  for (const char* name : kAllScenes) {
    const Simulator sim = make_simulator(load_config(scene_path(name), {}));
    const double fill = sim_fill_rate(sim, 0, 3);
    std::printf("%s: fill rate %.1f %%\n", name, 100.0 * fill);
    EXPECT_GE(fill, 0.70) << name;
    EXPECT_LE(fill, 0.98) << name;
  }
}

TEST(Scenes, RealD435FrameFillRate) {
  const std::string dir = std::string(HRCSENSE_SHARED_DIR) + "/data/librealsense_d435_single_frame";
  if (std::FILE* file = std::fopen((dir + "/depth_0.png").c_str(), "rb")) {
    std::fclose(file);
  } else {
    GTEST_SKIP() << dir << " is absent";
  }
  for (const char* frame : {"depth_0.png", "depth_1.png"}) {
    const double fill = real_fill_rate(frame);
    std::printf("real D435 %s: fill rate %.1f %%\n", frame, 100.0 * fill);
    EXPECT_NEAR(fill, 0.93, 0.02) << frame;  // the recording's README: about 93 % valid
  }
}

}  // namespace
}  // namespace hrcsense
