// SPDX-License-Identifier: Apache-2.0
// Tests of the simulator's moving arm (robot.trajectory) on config/cell-ur5-moving.yaml: the
// scene's timeline from the simulator's own truth, the arm's label and motion, the tool speed,
// the truth contact against the arm's searched capsules at each frame's time, and
// truth.contact_label (label_at, source_pixel_of, TruthLabeller).
#include "../support/sanitized.hpp"
#include "../support/scenes.hpp"
#include "common/assembly.hpp"
#include "common/truth_labeller.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

Config moving_cell() {
  return load_config(test::scene_path("cell-ur5-moving.yaml"),
                     {"sim.noise=false", "sim.color=false"});
}

/// The flange (tool) position in the base frame at time t_s, by forward kinematics.
Eigen::Vector3d flange_base(const Config& config, double t_s) {
  const JointAngles q = joints_at(*config.robot_state.trajectory, t_s).q_rad;
  return forward_kinematics(*config.pipeline.robot.arm, q).T_base_link[6].translation();  // DH frame 0 = base
}

size_t count_label(const std::vector<uint16_t>& labels, uint16_t label) {
  return static_cast<size_t>(std::count(labels.begin(), labels.end(), label));
}

uint16_t label_named(const Simulator& sim, const std::string& name) {
  for (uint16_t label = 1; label < 64; ++label) {
    if (sim.label_name(label) == name) return label;
  }
  return kStaticLabel;
}

TEST(MovingArmScene, PersonVisibleInAtLeast150FramesBefore1000AndNotWhileLearning) {
  if (test::kSanitized) GTEST_SKIP() << "1000 rendered frames; the ci build runs it, the simulator runs under the sanitizers in the other sim tests (CI time)";
  const Config config = moving_cell();
  ASSERT_EQ(config.sim.frames, 1000);
  ASSERT_EQ(config.robot_state.source, RobotStateOrigin::sim);
  const Simulator sim = make_simulator(config);
  const uint16_t person = label_named(sim, "person");
  ASSERT_NE(person, kStaticLabel);
  Frame frame;
  int visible = 0;
  int64_t first = -1;
  int64_t last = -1;
  for (int64_t i = 0; i < config.sim.frames; i += 1) {
    sim.render(i, frame);
    if (count_label(frame.truth->labels, person) < 50) continue;
    ++visible;
    if (first < 0) first = i;
    last = i;
  }
  EXPECT_GE(visible, 150);
  EXPECT_GE(first, config.pipeline.background.frames);  // nobody while the background is learnt
  EXPECT_LT(last, 1000);
}

TEST(MovingArmScene, ArmPixelsCarryTheRobotLabelAndMove) {
  const Config config = moving_cell();
  const Simulator sim = make_simulator(config);
  ASSERT_TRUE(sim.arm.has_value());
  EXPECT_EQ(sim.label_name(kRobotLabel), "robot");
  const Intrinsics in = sim.intrinsics();
  Frame a;
  Frame b;
  sim.render(0, a);   // pick pose
  sim.render(24, b);  // 0.8 s: halfway through the swing
  EXPECT_GT(count_label(a.truth->labels, kRobotLabel), 2000u);
  EXPECT_GT(count_label(b.truth->labels, kRobotLabel), 2000u);
  size_t changed = 0;
  for (size_t i = 0; i < a.truth->labels.size(); ++i) {
    changed += (a.truth->labels[i] == kRobotLabel) != (b.truth->labels[i] == kRobotLabel) ? 1 : 0;
  }
  EXPECT_GT(changed, 1000u);
  // The pixel the flange projects to, from the camera pose and forward kinematics, is the arm's
  // (seen from above, the flange's own body covers it).
  for (const int64_t index : {0, 24, 40}) {
    Frame frame;
    sim.render(index, frame);
    const Eigen::Vector3d p_base = flange_base(config, static_cast<double>(index) / 30.0);
    const Eigen::Vector3f p_camera = (config.pipeline.T_base_camera.inverse() * p_base).cast<float>();
    const std::optional<Eigen::Vector2f> uv = project(in, p_camera);
    ASSERT_TRUE(uv.has_value());
    const int u = static_cast<int>(std::lround(uv->x()));
    const int v = static_cast<int>(std::lround(uv->y()));
    ASSERT_TRUE(u >= 0 && u < in.width && v >= 0 && v < in.height) << index;
    EXPECT_EQ(frame.truth->labels[static_cast<size_t>(v) * in.width + u], kRobotLabel) << index;
  }
  // Before the person comes, nothing non-static but the arm: no truth contact.
  EXPECT_FALSE(a.truth->contact.valid);
}

TEST(MovingArmScene, ToolMovesAtAboutOneMetrePerSecond) {
  const Config config = moving_cell();
  // Mid-swing (pick → place from 0.25 s to 1.35 s, back from 1.6 s to 2.7 s), and a cycle later.
  for (const double t_s : {0.5, 0.8, 1.1, 2.0, 2.4, 0.8 + 2.7 * 5}) {
    const double dt_s = 0.01;
    const double speed = (flange_base(config, t_s + dt_s) - flange_base(config, t_s)).norm() / dt_s;
    EXPECT_GT(speed, 0.9) << t_s;
    EXPECT_LT(speed, 1.2) << t_s;
  }
  // At rest at the pick and place poses.
  EXPECT_LT((flange_base(config, 0.2) - flange_base(config, 0.05)).norm(), 1e-9);
  EXPECT_LT((flange_base(config, 1.55) - flange_base(config, 1.4)).norm(), 1e-9);
}

/// Point to capsule surface, double precision, written out here (not the simulator's code).
double capsule_distance(const Eigen::Vector3d& p, const Capsule& c) {
  const Eigen::Vector3d a = c.a.cast<double>();
  const Eigen::Vector3d ab = c.b.cast<double>() - a;
  const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return std::max(0.0, (p - (a + t * ab)).norm() - c.radius_m);
}

TEST(MovingArmScene, TruthContactIsThePersonAgainstTheSearchedArmAtTheFramesTime) {
  const Config config = moving_cell();
  const Simulator sim = make_simulator(config);
  const uint16_t person = label_named(sim, "person");
  const Intrinsics in = sim.intrinsics();
  for (const int64_t index : {250, 263, 300}) {
    Frame frame;
    sim.render(index, frame);
    const JointAngles q = joints_at(*config.robot_state.trajectory, static_cast<double>(index) / 30.0).q_rad;
    const RobotModel searched = robot_model_at(config.pipeline.robot, q);
    double best = std::numeric_limits<double>::infinity();
    for (int v = 0; v < in.height; ++v) {
      for (int u = 0; u < in.width; ++u) {
        const size_t i = static_cast<size_t>(v) * in.width + u;
        if (frame.truth->labels[i] != person) continue;
        const Eigen::Vector3f p_camera = *deproject(in, Eigen::Vector2f(u, v), frame.truth->depth_m[i]);
        const Eigen::Vector3d p_base = config.pipeline.T_base_camera * p_camera.cast<double>();
        for (const Capsule& c : searched.capsules) best = std::min(best, capsule_distance(p_base, c));
      }
    }
    ASSERT_TRUE(frame.truth->contact.valid) << index;
    EXPECT_NEAR(frame.truth->contact.distance_m, best, 1e-4) << index;
    EXPECT_EQ(frame.truth->labels[static_cast<size_t>(frame.truth->contact.pixel)], person) << index;
  }
}

TEST(MovingArmScene, LabelAtAgreesWithTheRenderedLabels) {
  const Config config = moving_cell();
  const Simulator rendering = make_simulator(config);
  const Simulator asking = make_simulator(config);
  for (const int64_t index : {0, 250, 300}) {
    Frame frame;
    rendering.render(index, frame);
    size_t mismatches = 0;
    for (size_t i = 0; i < frame.truth->labels.size(); i += 7) {
      mismatches += asking.label_at(index, static_cast<int>(i)) != frame.truth->labels[i] ? 1 : 0;
    }
    EXPECT_EQ(mismatches, 0u) << index;
  }
  EXPECT_EQ(asking.label_at(0, -1), kStaticLabel);
  EXPECT_EQ(asking.label_name(kStaticLabel), "static");
  EXPECT_EQ(asking.label_name(1), "person");
  EXPECT_EQ(asking.label_name(2), "");
}

Intrinsics decimated_by_two(const Intrinsics& source) {
  Intrinsics filtered = source;  // as the SDK's decimation scales intrinsics
  filtered.width = source.width / 2;
  filtered.height = source.height / 2;
  filtered.fx = source.fx / 2;
  filtered.fy = source.fy / 2;
  filtered.ppx = source.ppx / 2;
  filtered.ppy = source.ppy / 2;
  return filtered;
}

TEST(SourceBlockOf, MapsADecimatedPixelToItsBlock) {
  const Intrinsics source = *d435_depth_intrinsics(848, 480);
  const Intrinsics filtered = decimated_by_two(source);
  const auto expect_block = [&](int pixel, const Intrinsics& from, int u0, int u1, int v0, int v1) {
    const SourceBlock b = source_block_of(pixel, from, source);
    EXPECT_EQ(b.u_begin, u0) << pixel;
    EXPECT_EQ(b.u_end, u1) << pixel;
    EXPECT_EQ(b.v_begin, v0) << pixel;
    EXPECT_EQ(b.v_end, v1) << pixel;
  };
  expect_block(5 * 424 + 10, filtered, 20, 22, 10, 12);
  expect_block(239 * 424 + 423, filtered, 846, 848, 478, 480);  // the last one, clamped to the image
  expect_block(0, filtered, 0, 2, 0, 2);
  expect_block(1234, source, 1234 % 848, 1234 % 848 + 1, 1, 2);  // equal sizes: the pixel itself
  EXPECT_TRUE(source_block_of(-1, filtered, source).empty());
  EXPECT_TRUE(source_block_of(424 * 240, filtered, source).empty());
}

std::string label_text(const char* label) { return label != nullptr ? label : "(null)"; }

TEST(TruthLabeller, NamesTheObjectUnderTheMeasuredContact) {
  const Config config = moving_cell();
  const Simulator sim = make_simulator(config);
  Frame frame;
  sim.render(250, frame);
  const Intrinsics in = sim.intrinsics();
  RunHeader header;
  header.source.intrinsics = in;
  header.filters.intrinsics = in;
  const TruthLabeller labeller(make_simulator(config), header);
  FrameResult result;
  result.frame = 250;
  result.truth = frame.truth->contact;
  // One pixel of each kind in the rendered labels stands in for the measured contact.
  for (const uint16_t label : {kStaticLabel, kRobotLabel, uint16_t{1}}) {
    const auto it = std::find(frame.truth->labels.begin(), frame.truth->labels.end(), label);
    ASSERT_NE(it, frame.truth->labels.end());
    result.contact.valid = true;
    result.contact.pixel = static_cast<int>(it - frame.truth->labels.begin());
    EXPECT_EQ(label_text(labeller.contact_label(result)), label == kStaticLabel ? "static" : label == kRobotLabel ? "robot" : "person");
  }
  result.contact.valid = false;  // no measured contact: no label
  EXPECT_EQ(label_text(labeller.contact_label(result)), "(null)");
}

// A decimated pixel on the edge between the arm and a person: its label is that of the block's
// source pixel whose true depth is nearest the measured one, whichever pixel comes first.
TEST(TruthLabeller, OnAnEdgeNamesTheSurfaceAtTheMeasuredDepth) {
  const Config config = moving_cell();
  const Simulator sim = make_simulator(config);
  const Intrinsics in = sim.intrinsics();
  const Intrinsics filtered = decimated_by_two(in);
  RunHeader header;
  header.source.intrinsics = in;
  header.filters.intrinsics = filtered;
  const TruthLabeller labeller(make_simulator(config), header);
  int edges = 0;
  for (const int64_t index : {250, 283, 300}) {
    Frame frame;
    sim.render(index, frame);
    const GroundTruth& truth = *frame.truth;
    for (int v = 0; v + 1 < in.height && edges < 40; v += 2) {
      for (int u = 0; u + 1 < in.width && edges < 40; u += 2) {
        // The block's person and robot pixels, their true depths.
        float person_z = 0, robot_z = 0;
        for (const int i : {v * in.width + u, v * in.width + u + 1, (v + 1) * in.width + u, (v + 1) * in.width + u + 1}) {
          if (truth.labels[static_cast<size_t>(i)] == 1) person_z = truth.depth_m[static_cast<size_t>(i)];
          if (truth.labels[static_cast<size_t>(i)] == kRobotLabel) robot_z = truth.depth_m[static_cast<size_t>(i)];
        }
        if (person_z <= 0 || robot_z <= 0 || std::abs(person_z - robot_z) < 0.02F) continue;
        ++edges;
        FrameResult result;
        result.frame = index;
        result.truth = truth.contact;
        result.contact.valid = true;
        result.contact.pixel = (v / 2) * filtered.width + u / 2;
        result.contact.closest_camera.z() = person_z + 0.003F;  // measured with a little noise
        EXPECT_EQ(label_text(labeller.contact_label(result)), "person") << index << " " << u << "," << v;
        result.contact.closest_camera.z() = robot_z - 0.003F;
        EXPECT_EQ(label_text(labeller.contact_label(result)), "robot") << index << " " << u << "," << v;
      }
    }
  }
  EXPECT_GT(edges, 5) << "the frames should show the hand beside the arm";
}

}  // namespace
}  // namespace hrcsense
