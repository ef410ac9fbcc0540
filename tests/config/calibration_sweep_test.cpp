// SPDX-License-Identifier: Apache-2.0
// The calibration sweep of config/calibration/ (docs/CALIBRATION.md): the simulated cell
// ur5-sweep.yaml, the URScript program ur5-sweep.script and the ROS 2 JointTrajectory
// ur5-sweep-trajectory.yaml play the same poses. Each test reads the files itself, so each
// property is checked on its own: the three files agree; every pose is within the UR5's joint
// limits; no joint and no point of the arm moves too fast; the arm stays above the table top and
// clear of the tray at and between the waypoints; load_config accepts the cell.
//
// Between two waypoints all three move along the same straight line in joint space: the
// simulator interpolates linearly, movej is linear in joint space, and the ROS controller's
// cubic between two points at rest is q0 + (q1 − q0)·(3τ² − 2τ³) for every joint. So the
// positions checked along the YAML's lines hold for all three; only the speeds differ.
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense::calibration_sweep_test {

constexpr double kSweepPi = 3.14159265358979323846;
constexpr double kSweepMaxJointSpeedRadS = 0.35;  // the sweep's limit for any joint
constexpr double kSweepMaxPointSpeedMps = 0.25;   // ...and for any point of the arm
constexpr double kSweepMinHeightM = 0.05;         // link origins and flange above the table top (z = 0)
constexpr double kSweepTrayClearanceM = 0.05;     // the arm's capsules this far from the tray at least
constexpr int kSweepStepsBetweenWaypoints = 10;   // interpolated points checked between two waypoints
// The ROS controller's cubic from rest to rest peaks at 1.5 times the move's mean speed.
constexpr double kSweepCubicPeakFactor = 1.5;

std::string sweep_path(const std::string& name) {
  return std::string(HRCSENSE_SOURCE_DIR) + "/config/calibration/" + name;
}

struct SweepWaypoint {
  double t_s = 0.0;
  JointAngles q{};
};

JointAngles sweep_joints(const YAML::Node& list, const std::string& where) {
  JointAngles q{};
  EXPECT_TRUE(list.IsSequence() && list.size() == q.size()) << where << ": expected 6 joint values";
  if (!list.IsSequence() || list.size() != q.size()) return q;
  for (size_t j = 0; j < q.size(); ++j) q[j] = list[j].as<double>();
  return q;
}

// ur5-sweep.yaml's robot.trajectory.waypoints, read with yaml-cpp (not with hrcsense's reader).
std::vector<SweepWaypoint> sweep_config_waypoints() {
  const YAML::Node root = YAML::LoadFile(sweep_path("ur5-sweep.yaml"));
  const YAML::Node trajectory = root["robot"]["trajectory"];
  std::vector<SweepWaypoint> waypoints;
  for (const YAML::Node& node : trajectory["waypoints"]) {
    SweepWaypoint w;
    w.t_s = node["t_s"].as<double>();
    w.q = sweep_joints(node["joints_rad"], "ur5-sweep.yaml waypoint " + std::to_string(waypoints.size()));
    waypoints.push_back(w);
  }
  return waypoints;
}

// The poses of a list of waypoints that holds each pose between two waypoints, and how long.
struct SweepHeldPose {
  JointAngles q{};
  double hold_s = 0.0;
};

std::vector<SweepHeldPose> sweep_held_poses(const std::vector<SweepWaypoint>& waypoints) {
  std::vector<SweepHeldPose> poses;
  EXPECT_EQ(waypoints.size() % 2, 0U) << "every pose is held: two waypoints with the same joints";
  for (size_t i = 0; i + 1 < waypoints.size(); i += 2) {
    EXPECT_EQ(waypoints[i].q, waypoints[i + 1].q) << "waypoints " << i << " and " << i + 1 << " hold one pose";
    poses.push_back({waypoints[i].q, waypoints[i + 1].t_s - waypoints[i].t_s});
  }
  return poses;
}

// One statement of ur5-sweep.script that moves or waits.
struct SweepScriptStep {
  bool is_move = false;
  JointAngles q{};        // movej's target
  double a = 0.0;         // movej's a (rad/s²)
  double v = 0.0;         // movej's v (rad/s)
  double sleep_s = 0.0;   // sleep's time
};

std::string sweep_trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  const size_t last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

// A number at `text[at]`, and where it ends; fails the test when there is none.
double sweep_number(const std::string& text, size_t& at) {
  const char* begin = text.c_str() + at;
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  EXPECT_NE(end, begin) << "expected a number at '" << text.substr(at) << "'";
  at += static_cast<size_t>(end - begin);
  return value;
}

// Parses `movej([q1, ..., q6], a=A, v=V)` and `sleep(T)`; other lines (comments, textmsg, def,
// end) are skipped. A statement the parser does not know that moves the arm fails the test.
std::vector<SweepScriptStep> sweep_script_steps(std::vector<std::string>* lines_out = nullptr) {
  std::ifstream in(sweep_path("ur5-sweep.script"));
  EXPECT_TRUE(in.good()) << "cannot read ur5-sweep.script";
  std::vector<SweepScriptStep> steps;
  std::string line;
  while (std::getline(in, line)) {
    if (lines_out != nullptr) lines_out->push_back(line);
    const std::string text = sweep_trim(line);
    if (text.empty() || text[0] == '#') continue;
    if (text.rfind("movej(", 0) == 0) {
      SweepScriptStep step;
      step.is_move = true;
      size_t at = text.find('[');
      EXPECT_NE(at, std::string::npos) << text;
      if (at == std::string::npos) continue;
      ++at;
      for (size_t j = 0; j < step.q.size(); ++j) {
        step.q[j] = sweep_number(text, at);
        const char expected = j + 1 < step.q.size() ? ',' : ']';
        EXPECT_EQ(text[at], expected) << text;
        ++at;
      }
      const size_t a_at = text.find("a=", at);
      const size_t v_at = text.find("v=", at);
      EXPECT_NE(a_at, std::string::npos) << "movej without a=: " << text;
      EXPECT_NE(v_at, std::string::npos) << "movej without v=: " << text;
      if (a_at == std::string::npos || v_at == std::string::npos) continue;
      size_t number_at = a_at + 2;
      step.a = sweep_number(text, number_at);
      number_at = v_at + 2;
      step.v = sweep_number(text, number_at);
      EXPECT_EQ(text.find("t=", at), std::string::npos) << "a movej with t= ignores v: " << text;
      steps.push_back(step);
    } else if (text.rfind("sleep(", 0) == 0) {
      SweepScriptStep step;
      size_t at = 6;
      step.sleep_s = sweep_number(text, at);
      steps.push_back(step);
    } else {
      for (const char* motion : {"movel", "movep", "movec", "servoj", "speedj", "speedl"}) {
        EXPECT_EQ(text.find(motion), std::string::npos) << "a motion the test does not follow: " << text;
      }
    }
  }
  return steps;
}

// ur5-sweep-trajectory.yaml's points, read with yaml-cpp; t_s is time_from_start.
struct SweepRosPoint {
  double t_s = 0.0;
  JointAngles q{};
  JointAngles qd{};
};

std::vector<SweepRosPoint> sweep_ros_points(std::vector<std::string>* joint_names = nullptr) {
  const YAML::Node root = YAML::LoadFile(sweep_path("ur5-sweep-trajectory.yaml"));
  if (joint_names != nullptr) {
    for (const YAML::Node& name : root["joint_names"]) joint_names->push_back(name.as<std::string>());
  }
  std::vector<SweepRosPoint> points;
  for (const YAML::Node& node : root["points"]) {
    const std::string where = "ur5-sweep-trajectory.yaml point " + std::to_string(points.size());
    SweepRosPoint p;
    p.q = sweep_joints(node["positions"], where + " positions");
    p.qd = sweep_joints(node["velocities"], where + " velocities");
    const YAML::Node time = node["time_from_start"];
    const auto sec = time["sec"].as<int64_t>();
    const auto nanosec = time["nanosec"].as<int64_t>();
    EXPECT_GE(nanosec, 0) << where;
    EXPECT_LT(nanosec, 1000000000) << where;
    p.t_s = static_cast<double>(sec) + static_cast<double>(nanosec) * 1e-9;
    points.push_back(p);
  }
  return points;
}

std::vector<SweepWaypoint> sweep_ros_waypoints() {
  std::vector<SweepWaypoint> waypoints;
  for (const SweepRosPoint& p : sweep_ros_points()) waypoints.push_back({p.t_s, p.q});
  return waypoints;
}

std::vector<JointAngles> sweep_script_poses() {
  std::vector<JointAngles> poses;
  for (const SweepScriptStep& step : sweep_script_steps()) {
    if (step.is_move) poses.push_back(step.q);
  }
  return poses;
}

JointAngles sweep_lerp(const JointAngles& a, const JointAngles& b, double s) {
  JointAngles q{};
  for (size_t j = 0; j < q.size(); ++j) q[j] = a[j] + s * (b[j] - a[j]);
  return q;
}

double sweep_largest_step(const JointAngles& a, const JointAngles& b) {
  double largest = 0.0;
  for (size_t j = 0; j < a.size(); ++j) largest = std::max(largest, std::abs(b[j] - a[j]));
  return largest;
}

// The farthest any capsule end (the arm's searched capsules, unpadded: they cover its body) and
// the flange travel per unit of the interpolation parameter s along the line from a to b: the
// largest point speed is this times ds/dt.
double sweep_point_travel_per_s(const RobotDescription& arm, const JointAngles& a, const JointAngles& b) {
  constexpr int kSteps = 100;
  double largest = 0.0;
  RobotModel before = robot_capsules(arm, a, 0.0, BaseFrame::base);
  for (int k = 1; k <= kSteps; ++k) {
    const JointAngles q = sweep_lerp(a, b, static_cast<double>(k) / kSteps);
    const RobotModel after = robot_capsules(arm, q, 0.0, BaseFrame::base);
    for (size_t c = 0; c < after.capsules.size(); ++c) {
      const double moved = std::max((after.capsules[c].a - before.capsules[c].a).norm(),
                                    (after.capsules[c].b - before.capsules[c].b).norm());
      largest = std::max(largest, moved * kSteps);
    }
    before = after;
  }
  return largest;
}

// Distance from `p` to the tray box of the reference cell (x 0.55..0.85, y 0.3..0.6, z 0..0.06).
double sweep_distance_to_tray(const Eigen::Vector3d& p) {
  const Eigen::Vector3d low(0.55, 0.3, 0.0);
  const Eigen::Vector3d high(0.85, 0.6, 0.06);
  const Eigen::Vector3d outside = (low - p).cwiseMax(p - high).cwiseMax(Eigen::Vector3d::Zero());
  return outside.norm();
}

// Checks one joint state: every link origin (frames 1..6; frame 0 is the base on the table)
// and the flange above kSweepMinHeightM, every capsule of the moving links (upper arm on) clear
// of the tray.
void sweep_expect_clear(const RobotDescription& arm, const JointAngles& q, const std::string& where) {
  const LinkFrames frames = forward_kinematics(arm, q);
  for (int link = 1; link < kArmLinkCount; ++link) {
    EXPECT_GT(frames.T_base_link[static_cast<size_t>(link)].translation().z(), kSweepMinHeightM)
        << where << ": origin of " << link_name(link);
  }
  const Eigen::Vector3d flange = frames.T_base_link[6].translation();
  EXPECT_GT(flange.z(), kSweepMinHeightM) << where << ": flange";
  const RobotModel capsules = robot_capsules(arm, q, 0.0, BaseFrame::base);
  for (const Capsule& capsule : capsules.capsules) {
    if (capsule.link < 2) continue;  // the base and the shoulder stay at the base
    for (int k = 0; k <= 10; ++k) {
      const Eigen::Vector3f p = capsule.a + (capsule.b - capsule.a) * (static_cast<float>(k) / 10.0F);
      EXPECT_GT(sweep_distance_to_tray(p.cast<double>()) - capsule.radius_m, kSweepTrayClearanceM)
          << where << ": " << link_name(capsule.link) << " near the tray";
    }
  }
}

TEST(CalibrationSweep, TheThreeFilesListTheSamePosesInTheSameOrderAtTheSameTimes) {
  const std::vector<SweepWaypoint> config = sweep_config_waypoints();
  ASSERT_GE(config.size(), 20U);  // 10-14 poses, each held between two waypoints
  ASSERT_LE(config.size(), 28U);
  const std::vector<SweepHeldPose> held = sweep_held_poses(config);

  // The URScript: a movej to each pose, then a sleep as long as the YAML holds it.
  std::vector<std::string> lines;
  const std::vector<SweepScriptStep> steps = sweep_script_steps(&lines);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.front().rfind("def ", 0), 0U) << "the controller runs a script whose first line is the def";
  const auto last =
      std::find_if(lines.rbegin(), lines.rend(), [](const std::string& l) { return !sweep_trim(l).empty(); });
  ASSERT_NE(last, lines.rend());
  EXPECT_EQ(*last, "end");
  ASSERT_EQ(steps.size(), 2 * held.size()) << "a movej and a sleep per pose";
  for (size_t i = 0; i < held.size(); ++i) {
    const SweepScriptStep& move = steps[2 * i];
    const SweepScriptStep& wait = steps[2 * i + 1];
    ASSERT_TRUE(move.is_move) << "pose " << i + 1 << ": expected a movej";
    ASSERT_FALSE(wait.is_move) << "pose " << i + 1 << ": expected a sleep after the movej";
    EXPECT_EQ(move.q, held[i].q) << "pose " << i + 1;  // the same digits: exactly equal
    EXPECT_DOUBLE_EQ(wait.sleep_s, held[i].hold_s) << "pose " << i + 1;
  }

  // The ROS trajectory: the YAML's waypoints, times counted from its first, at rest.
  std::vector<std::string> names;
  const std::vector<SweepRosPoint> points = sweep_ros_points(&names);
  EXPECT_EQ(names, (std::vector<std::string>{"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                             "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"}));
  ASSERT_EQ(points.size(), config.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].q, config[i].q) << "point " << i;
    EXPECT_NEAR(points[i].t_s, config[i].t_s - config.front().t_s, 1e-9) << "point " << i;
    EXPECT_EQ(points[i].qd, JointAngles{}) << "point " << i << ": every point is a held pose, at rest";
  }
}

TEST(CalibrationSweep, EveryPoseIsWithinTheUr5JointLimits) {
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  std::vector<std::pair<std::string, JointAngles>> poses;
  for (const SweepWaypoint& w : sweep_config_waypoints()) poses.emplace_back("ur5-sweep.yaml", w.q);
  for (const JointAngles& q : sweep_script_poses()) poses.emplace_back("ur5-sweep.script", q);
  for (const SweepWaypoint& w : sweep_ros_waypoints()) poses.emplace_back("ur5-sweep-trajectory.yaml", w.q);
  ASSERT_FALSE(poses.empty());
  for (const auto& [file, q] : poses) {
    EXPECT_EQ(joint_outside_limits(ur5, q), -1) << file;
    for (size_t j = 0; j < q.size(); ++j) {
      EXPECT_GE(q[j], ur5.limits[j].min_rad) << file << ": " << joint_name(static_cast<int>(j));
      EXPECT_LE(q[j], ur5.limits[j].max_rad) << file << ": " << joint_name(static_cast<int>(j));
    }
    // The elbow also within ±π, ROS ur_description's limit against self-collision (docs/ROBOT.md).
    EXPECT_LE(std::abs(q[2]), kSweepPi) << file << ": elbow";
  }
}

TEST(CalibrationSweep, NoJointTurnsFasterThanTheLimitBetweenWaypoints) {
  // The simulated cell: linear between waypoints, the slope is the speed.
  const std::vector<SweepWaypoint> config = sweep_config_waypoints();
  ASSERT_GE(config.size(), 2U);
  for (size_t i = 1; i < config.size(); ++i) {
    const double dt = config[i].t_s - config[i - 1].t_s;
    ASSERT_GT(dt, 0.0) << "waypoint " << i;
    EXPECT_LE(sweep_largest_step(config[i - 1].q, config[i].q) / dt, kSweepMaxJointSpeedRadS) << "waypoint " << i;
  }
  // The ROS controller's cubic between points at rest peaks at 1.5 times the mean speed.
  const std::vector<SweepWaypoint> ros = sweep_ros_waypoints();
  ASSERT_GE(ros.size(), 2U);
  for (size_t i = 1; i < ros.size(); ++i) {
    const double dt = ros[i].t_s - ros[i - 1].t_s;
    ASSERT_GT(dt, 0.0) << "point " << i;
    EXPECT_LE(kSweepCubicPeakFactor * sweep_largest_step(ros[i - 1].q, ros[i].q) / dt, kSweepMaxJointSpeedRadS)
        << "point " << i;
  }
  // The URScript: movej's v is the fastest joint's speed; a low acceleration too.
  for (const SweepScriptStep& step : sweep_script_steps()) {
    if (!step.is_move) continue;
    EXPECT_GT(step.v, 0.0);
    EXPECT_LE(step.v, std::min(0.3, kSweepMaxJointSpeedRadS));
    EXPECT_GT(step.a, 0.0);
    EXPECT_LE(step.a, 0.5);
  }
}

TEST(CalibrationSweep, NoPointOfTheArmMovesFasterThanTheLimitBetweenWaypoints) {
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  // The simulated cell (linear: ds/dt = 1/dt) and the ROS cubic (peak ds/dt = 1.5/dt).
  const std::vector<SweepWaypoint> config = sweep_config_waypoints();
  ASSERT_GE(config.size(), 2U);
  for (size_t i = 1; i < config.size(); ++i) {
    if (config[i].q == config[i - 1].q) continue;
    const double dt = config[i].t_s - config[i - 1].t_s;
    const double speed = sweep_point_travel_per_s(ur5, config[i - 1].q, config[i].q) / dt;
    EXPECT_LE(speed, kSweepMaxPointSpeedMps) << "ur5-sweep.yaml, waypoint " << i;
    EXPECT_LE(kSweepCubicPeakFactor * speed, kSweepMaxPointSpeedMps) << "the ROS trajectory, point " << i;
  }
  // The URScript: the fastest joint of a move turns at v (once accelerated), the others in
  // proportion, so ds/dt = v / the largest joint step.
  const std::vector<SweepScriptStep> steps = sweep_script_steps();
  const JointAngles* from = nullptr;
  int pose = 0;
  for (const SweepScriptStep& step : steps) {
    if (!step.is_move) continue;
    ++pose;
    if (from != nullptr && sweep_largest_step(*from, step.q) > 0.0) {
      const double speed = sweep_point_travel_per_s(ur5, *from, step.q) * step.v / sweep_largest_step(*from, step.q);
      EXPECT_LE(speed, kSweepMaxPointSpeedMps) << "ur5-sweep.script, the movej to pose " << pose;
    }
    from = &step.q;
  }
}

TEST(CalibrationSweep, TheArmStaysAboveTheTableAndClearOfTheTrayAtAndBetweenWaypoints) {
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  const std::vector<SweepWaypoint> config = sweep_config_waypoints();
  ASSERT_GE(config.size(), 2U);
  for (size_t i = 0; i < config.size(); ++i) {
    sweep_expect_clear(ur5, config[i].q, "waypoint " + std::to_string(i));
    if (i == 0) continue;
    for (int k = 1; k < kSweepStepsBetweenWaypoints + 1; ++k) {
      const double s = static_cast<double>(k) / (kSweepStepsBetweenWaypoints + 1);
      sweep_expect_clear(ur5, sweep_lerp(config[i - 1].q, config[i].q, s),
                         "between waypoints " + std::to_string(i - 1) + " and " + std::to_string(i) + " at " +
                             std::to_string(s));
    }
  }
}

TEST(CalibrationSweep, LoadConfigAcceptsTheSweepCell) {
  Config sweep;
  ASSERT_NO_THROW(sweep = load_config(sweep_path("ur5-sweep.yaml"), {}));
  EXPECT_EQ(sweep.source.type, SourceType::sim);
  EXPECT_EQ(sweep.robot_model, RobotModelType::ur5);
  EXPECT_EQ(sweep.robot_state.source, RobotStateOrigin::sim);
  ASSERT_TRUE(sweep.robot_state.trajectory.has_value());
  const RobotTrajectory& trajectory = *sweep.robot_state.trajectory;
  EXPECT_EQ(trajectory.interpolation, TrajectoryInterpolation::linear);
  EXPECT_FALSE(trajectory.loop);
  ASSERT_FALSE(trajectory.waypoints.empty());
  // The frames cover the sweep and a second more.
  const double end_s = trajectory.waypoints.back().t_s + 1.0;
  EXPECT_GE(static_cast<double>(sweep.sim.frames), end_s * sweep.sim.fps - 1e-6);
  EXPECT_LE(static_cast<double>(sweep.sim.frames), end_s * sweep.sim.fps + 1.0);

  // The cell of cell-ur5-moving.yaml without its person: the same camera, sensor and scene.
  const Config moving = load_config(std::string(HRCSENSE_SOURCE_DIR) + "/config/cell-ur5-moving.yaml", {});
  EXPECT_TRUE(sweep.pipeline.T_base_camera.isApprox(moving.pipeline.T_base_camera, 1e-12));
  EXPECT_EQ(sweep.sim.width, moving.sim.width);
  EXPECT_EQ(sweep.sim.height, moving.sim.height);
  EXPECT_EQ(sweep.sim.fps, moving.sim.fps);
  EXPECT_EQ(sweep.sim.seed, moving.sim.seed);
  EXPECT_EQ(sweep.sim.noise, moving.sim.noise);
  EXPECT_EQ(sweep.sim.disparity_noise_px, moving.sim.disparity_noise_px);
  std::vector<std::string> expected;
  for (const SceneObject& object : moving.scene.objects) {
    if (object.name != "person") expected.push_back(object.name);
  }
  std::vector<std::string> names;
  for (const SceneObject& object : sweep.scene.objects) names.push_back(object.name);
  EXPECT_EQ(names, expected);
}

}  // namespace hrcsense::calibration_sweep_test
