// SPDX-License-Identifier: Apache-2.0
// The two lists of waypoints, robot.trajectory's and a scene object's path, are read by one
// reader with one rule: times strictly increasing (docs/CONFIG.md). A repeated time is refused
// in both with the same message; what is read interpolates as worked out by hand below.
#include "config_test_util.hpp"

#include "hrcsense/config/config.hpp"
#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

using test::expect_config_error;

const std::string kArm = "robot.model=ur5";
const std::string kPose = "robot.joints_rad=[0, 0, 0, 0, 0, 0]";

std::string trajectory(double t0, double t1) {
  return "robot.trajectory={waypoints: [{t_s: " + std::to_string(t0) + ", joints_rad: [0, 0, 0, 0, 0, 0]}, {t_s: " +
         std::to_string(t1) + ", joints_rad: [1, 0, 0, 0, 0, 0]}]}";
}

std::string person_path_override(double t0, double t1) {
  return "scene.objects=[{name: person, path: [{t_s: " + std::to_string(t0) + ", offset_m: [0, 0, 0]}, {t_s: " +
         std::to_string(t1) + ", offset_m: [1, 0, 0]}], shapes: [{sphere: {center: [0, 0, 2], radius_m: 0.1}}]}]";
}

TEST(Waypoints, ARepeatedTimeIsRefusedInBothLists) {
  expect_config_error("", {kArm, kPose, trajectory(1.0, 1.0)},
                      {"robot.trajectory.waypoints[1].t_s", "expected times strictly increasing (1 s after 1 s)"});
  expect_config_error("", {person_path_override(1.0, 1.0)},
                      {"scene.objects[0].path[1].t_s", "expected times strictly increasing (1 s after 1 s)"});
}

TEST(Waypoints, AnEarlierTimeIsRefusedInBothLists) {
  expect_config_error("", {kArm, kPose, trajectory(2.0, 1.5)},
                      {"robot.trajectory.waypoints[1].t_s", "expected times strictly increasing (1.5 s after 2 s)"});
  expect_config_error("", {person_path_override(2.0, 1.5)},
                      {"scene.objects[0].path[1].t_s", "expected times strictly increasing (1.5 s after 2 s)"});
}

TEST(Waypoints, IncreasingTimesAreReadAndInterpolated) {
  // Joint 1 goes from 0 to 1 rad between t = 0 and t = 2 s, linearly: at 0.5 s a quarter of
  // the way, 0.25 rad, at 0.5 rad/s; held at the ends.
  const Config arm = load_config("", {kArm, kPose, trajectory(0.0, 2.0)});
  ASSERT_TRUE(arm.robot_state.trajectory.has_value());
  ASSERT_EQ(arm.robot_state.trajectory->waypoints.size(), 2U);
  const TrajectorySample quarter = joints_at(*arm.robot_state.trajectory, 0.5);
  EXPECT_DOUBLE_EQ(quarter.q_rad[0], 0.25);
  EXPECT_DOUBLE_EQ(quarter.qd_rad_s[0], 0.5);
  EXPECT_DOUBLE_EQ(joints_at(*arm.robot_state.trajectory, 3.0).q_rad[0], 1.0);

  const Config scene = load_config("", {person_path_override(0.0, 2.0)});
  ASSERT_EQ(scene.scene.objects.size(), 1U);
  const std::vector<Waypoint>& path = scene.scene.objects[0].path;
  ASSERT_EQ(path.size(), 2U);
  EXPECT_DOUBLE_EQ(path[0].t_s, 0.0);
  EXPECT_DOUBLE_EQ(path[1].t_s, 2.0);
  EXPECT_EQ(path[1].offset_m, Eigen::Vector3f(1, 0, 0));
}

}  // namespace
}  // namespace hrcsense
