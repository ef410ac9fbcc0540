// SPDX-License-Identifier: Apache-2.0
// Tests of joints_at(): linear and cubic (Hermite, Catmull-Rom tangents) interpolation, held
// ends and looping, against values worked out by hand.
#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace hrcsense {
namespace {

constexpr double kTol = 1e-12;

/// Waypoints moving joint 1 through `q0`; the other joints stay at 0.5 rad.
RobotTrajectory trajectory(TrajectoryInterpolation interpolation, bool loop, const std::vector<double>& t_s,
                           const std::vector<double>& q0) {
  RobotTrajectory out;
  out.interpolation = interpolation;
  out.loop = loop;
  for (size_t i = 0; i < t_s.size(); ++i) {
    TrajectoryWaypoint w;
    w.t_s = t_s[i];
    w.q_rad = {q0[i], 0.5, 0.5, 0.5, 0.5, 0.5};
    out.waypoints.push_back(w);
  }
  return out;
}

TEST(JointsAt, LinearIsPiecewiseLinearWithTheSegmentSlope) {
  const RobotTrajectory t = trajectory(TrajectoryInterpolation::linear, false, {0, 2, 4}, {0, 1, -1});
  EXPECT_NEAR(joints_at(t, 1.0).q_rad[0], 0.5, kTol);
  EXPECT_NEAR(joints_at(t, 1.0).qd_rad_s[0], 0.5, kTol);
  EXPECT_NEAR(joints_at(t, 3.0).q_rad[0], 0.0, kTol);
  EXPECT_NEAR(joints_at(t, 3.0).qd_rad_s[0], -1.0, kTol);
  // At a waypoint: its angle, and the slope of the segment that starts there.
  EXPECT_NEAR(joints_at(t, 2.0).q_rad[0], 1.0, kTol);
  EXPECT_NEAR(joints_at(t, 2.0).qd_rad_s[0], -1.0, kTol);
  // The joints that do not move.
  for (size_t j = 1; j < 6; ++j) {
    EXPECT_EQ(joints_at(t, 1.0).q_rad[j], 0.5);
    EXPECT_EQ(joints_at(t, 1.0).qd_rad_s[j], 0.0);
  }
}

TEST(JointsAt, WithoutLoopTheEndsAreHeldAtRest) {
  const RobotTrajectory t = trajectory(TrajectoryInterpolation::linear, false, {0, 2, 4}, {0, 1, -1});
  EXPECT_EQ(joints_at(t, -1.0).q_rad[0], 0.0);
  EXPECT_EQ(joints_at(t, -1.0).qd_rad_s[0], 0.0);
  EXPECT_EQ(joints_at(t, 5.0).q_rad[0], -1.0);
  EXPECT_EQ(joints_at(t, 5.0).qd_rad_s[0], 0.0);
  EXPECT_EQ(joints_at(t, 4.0).q_rad[0], -1.0);
}

TEST(JointsAt, LoopWrapsTimeOverTheWaypoints) {
  // Period 2 s from t = 1: 4.5 s and 0.5 s are both 2.5 s into the cycle, halfway down.
  const RobotTrajectory t = trajectory(TrajectoryInterpolation::linear, true, {1, 2, 3}, {0, 1, 0});
  for (const double time : {2.5, 4.5, 0.5, -1.5, 102.5}) {
    EXPECT_NEAR(joints_at(t, time).q_rad[0], 0.5, kTol) << time;
    EXPECT_NEAR(joints_at(t, time).qd_rad_s[0], -1.0, kTol) << time;
  }
  EXPECT_NEAR(joints_at(t, 3.0).q_rad[0], 0.0, kTol);  // the end is the start again
  EXPECT_NEAR(joints_at(t, 3.0).qd_rad_s[0], 1.0, kTol);
}

TEST(JointsAt, CubicWithZeroTangentsIsSmoothstep) {
  // (0, 0), (1, 1), (2, 0): the inner tangent (0 - 0) / 2 is 0, so on [0, 1] q = 3s² - 2s³.
  const RobotTrajectory t = trajectory(TrajectoryInterpolation::cubic, false, {0, 1, 2}, {0, 1, 0});
  EXPECT_NEAR(joints_at(t, 0.5).q_rad[0], 0.5, kTol);
  EXPECT_NEAR(joints_at(t, 0.5).qd_rad_s[0], 1.5, kTol);
  EXPECT_NEAR(joints_at(t, 0.25).q_rad[0], 0.15625, kTol);  // 3/16 - 2/64
  EXPECT_NEAR(joints_at(t, 0.25).qd_rad_s[0], 1.125, kTol);  // 6/4 - 6/16
  EXPECT_NEAR(joints_at(t, 1.5).q_rad[0], 0.5, kTol);
  EXPECT_NEAR(joints_at(t, 1.5).qd_rad_s[0], -1.5, kTol);
  EXPECT_NEAR(joints_at(t, 0.0).qd_rad_s[0], 0.0, kTol);
  EXPECT_NEAR(joints_at(t, 2.0).qd_rad_s[0], 0.0, kTol);
}

TEST(JointsAt, CubicUsesCentralDifferenceTangentsOnUnevenTimes) {
  // (0, 0), (1, 1), (3, 3): tangent at t = 1 is (3 - 0) / (3 - 0) = 1, zero at both ends.
  // [0, 1], h = 1: q = h01 + h11·1 = -s³ + 2s², qd = -3s² + 4s.
  // [1, 3], h = 2: q = h00·1 + h10·2·1 + h01·3, qd = (h00'·1 + h10'·2 + h01'·3) / 2.
  const RobotTrajectory t = trajectory(TrajectoryInterpolation::cubic, false, {0, 1, 3}, {0, 1, 3});
  EXPECT_NEAR(joints_at(t, 0.5).q_rad[0], 0.375, kTol);
  EXPECT_NEAR(joints_at(t, 0.5).qd_rad_s[0], 1.25, kTol);
  EXPECT_NEAR(joints_at(t, 2.0).q_rad[0], 2.25, kTol);   // 0.5 + 0.125·2 + 0.5·3
  EXPECT_NEAR(joints_at(t, 2.0).qd_rad_s[0], 1.25, kTol);  // (-1.5 - 0.25·2 + 1.5·3) / 2
  // C1 at the inner waypoint: velocity 1 from both sides.
  EXPECT_NEAR(joints_at(t, 1.0 - 1e-9).qd_rad_s[0], 1.0, 1e-6);
  EXPECT_NEAR(joints_at(t, 1.0).qd_rad_s[0], 1.0, kTol);
  EXPECT_NEAR(joints_at(t, 3.0 - 1e-9).qd_rad_s[0], 0.0, 1e-6);
}

TEST(JointsAt, VelocityIsTheDerivativeOfTheAngle) {
  for (const auto interpolation : {TrajectoryInterpolation::linear, TrajectoryInterpolation::cubic}) {
    const RobotTrajectory t = trajectory(interpolation, true, {0, 0.7, 1.5, 2.6}, {0.2, -1.0, 0.4, 0.2});
    for (double time = 0.05; time < 6.0; time += 0.173) {
      const double h = 1e-6;
      const double numeric = (joints_at(t, time + h).q_rad[0] - joints_at(t, time - h).q_rad[0]) / (2 * h);
      EXPECT_NEAR(joints_at(t, time).qd_rad_s[0], numeric, 1e-5) << time;
    }
  }
}

}  // namespace
}  // namespace hrcsense
