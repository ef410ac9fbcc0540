// SPDX-License-Identifier: Apache-2.0
// Forward kinematics of the built-in arms against flange positions worked out by hand from
// UR's DH tables, and the base / base_link frames.
//
// How the hand values are found: at q = 0 the UR arm lies stretched along −x of base_link
// (a2, a3 < 0) and the joint axes are, with S = (0, 0, d1) the shoulder, E = S + (a2, 0, 0)
// the elbow, W1 = S + (a2 + a3, 0, 0), W2 = W1 + (0, −d4, 0), W3 = W2 + (0, 0, −d5):
//   joint 1: +z through the origin; joints 2, 3, 4: −y through S, E, W1;
//   joint 5: −z through W2; joint 6: −y through W3.
// The flange at q = 0 is F0 = (a2 + a3, −(d4 + d6), d1 − d5). Turning one joint by θ turns
// everything beyond it about that joint's axis: F = P + R(F0 − P). A turn by θ about −y is
// Ry(−θ), so Ry(+90°)(x, y, z) = (z, y, −x) and Ry(−90°)(x, y, z) = (−z, y, x); about −z it
// is Rz(−θ), and Rz(+90°)(x, y, z) = (−y, x, z), Rz(−90°)(x, y, z) = (y, −x, z).
#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace hrcsense {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kTolerance_m = 1e-6;

// UR5 (CB3) DH values, from UR's published table, independent of the built-in description.
constexpr double d1 = 0.089159, a2 = -0.425, a3 = -0.39225, d4 = 0.10915, d5 = 0.09465, d6 = 0.0823;

// UR's DH frame 0 is the pendant's `base` (ROS's `base`; its `base_link` is turned π about z,
// +x along the arm at q = 0: ur_description's "Robot Frames").
Eigen::Vector3d flange(BuiltinArm arm, JointAngles q_deg, BaseFrame frame = BaseFrame::base) {
  for (double& q : q_deg) q *= kDeg;
  const LinkFrames frames = forward_kinematics(builtin_robot(arm), q_deg);
  const Pose T_base_link_base = T_base_base_link().inverse(Eigen::Isometry);
  const Pose T = frame == BaseFrame::base_link ? T_base_link_base * frames.T_base_link[6] : frames.T_base_link[6];
  return T.translation();
}

void expect_near(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected) {
  EXPECT_NEAR(actual.x(), expected.x(), kTolerance_m) << actual.transpose() << " vs " << expected.transpose();
  EXPECT_NEAR(actual.y(), expected.y(), kTolerance_m) << actual.transpose() << " vs " << expected.transpose();
  EXPECT_NEAR(actual.z(), expected.z(), kTolerance_m) << actual.transpose() << " vs " << expected.transpose();
}

TEST(ForwardKinematics, Ur5ZeroPosePutsTheFlangeWhereTheDhTableSays) {
  // The acceptance value: (a2 + a3, −(d4 + d6), d1 − d5).
  expect_near(flange(BuiltinArm::ur5, {0, 0, 0, 0, 0, 0}), {-0.81725, -0.19145, -0.005491});
  // The DH frame 0 is base_link; every frame's origin at q = 0, one by one.
  const LinkFrames frames = forward_kinematics(builtin_robot(BuiltinArm::ur5), JointAngles{});
  expect_near(frames.T_base_link[0].translation(), {0, 0, 0});
  expect_near(frames.T_base_link[1].translation(), {0, 0, d1});
  expect_near(frames.T_base_link[2].translation(), {a2, 0, d1});
  expect_near(frames.T_base_link[3].translation(), {a2 + a3, 0, d1});
  expect_near(frames.T_base_link[4].translation(), {a2 + a3, -d4, d1});
  expect_near(frames.T_base_link[5].translation(), {a2 + a3, -d4, d1 - d5});
  // The flange's z (the tool direction) points along −y at q = 0 (z6 = z5 = y4 = z3 = −y0).
  expect_near(frames.T_base_link[6].linear().col(2), {0, -1, 0});
}

TEST(ForwardKinematics, Ur5EachJointAtNinetyDegreesByHand) {
  // Joint 1 +90°: the whole arm turns about +z: Rz(90°)(F0) = (−F0y, F0x, F0z).
  expect_near(flange(BuiltinArm::ur5, {90, 0, 0, 0, 0, 0}), {d4 + d6, a2 + a3, d1 - d5});  // (0.19145, −0.81725, −0.005491)
  // Joint 1 −90°: Rz(−90°)(F0) = (F0y, −F0x, F0z).
  expect_near(flange(BuiltinArm::ur5, {-90, 0, 0, 0, 0, 0}), {-(d4 + d6), -(a2 + a3), d1 - d5});
  // Joint 2 −90° (about −y through S): Ry(+90°)(F0 − S) with F0 − S = (a2 + a3, −(d4 + d6), −d5)
  // gives (−d5, −(d4 + d6), −(a2 + a3)): the arm points straight up. F = (−0.09465, −0.19145, 0.906409).
  expect_near(flange(BuiltinArm::ur5, {0, -90, 0, 0, 0, 0}), {-d5, -(d4 + d6), d1 - (a2 + a3)});
  // Joint 3 +90° (about −y through E): F0 − E = (a3, −(d4 + d6), −d5); Ry(−90°) gives
  // (d5, −(d4 + d6), a3): the forearm hangs down. F = (−0.33035, −0.19145, −0.303091).
  expect_near(flange(BuiltinArm::ur5, {0, 0, 90, 0, 0, 0}), {a2 + d5, -(d4 + d6), d1 + a3});
  // Joint 4 −90° (about −y through W1): F0 − W1 = (0, −(d4 + d6), −d5); Ry(+90°) gives
  // (−d5, −(d4 + d6), 0). F = (−0.9119, −0.19145, 0.089159).
  expect_near(flange(BuiltinArm::ur5, {0, 0, 0, -90, 0, 0}), {a2 + a3 - d5, -(d4 + d6), d1});
  // Joint 5 +90° (about −z through W2): F0 − W2 = (0, −d6, −d5); Rz(−90°) gives (−d6, 0, −d5).
  // F = (−0.89955, −0.10915, −0.005491).
  expect_near(flange(BuiltinArm::ur5, {0, 0, 0, 0, 90, 0}), {a2 + a3 - d6, -d4, d1 - d5});
  // Joint 6 −90°: the flange centre is on joint 6's axis and stays; its x axis (x0 at q = 0)
  // turns about −y by −90°, i.e. Ry(+90°)(1, 0, 0) = (0, 0, −1).
  expect_near(flange(BuiltinArm::ur5, {0, 0, 0, 0, 0, -90}), {a2 + a3, -(d4 + d6), d1 - d5});
  const LinkFrames frames = forward_kinematics(builtin_robot(BuiltinArm::ur5), JointAngles{0, 0, 0, 0, 0, -90 * kDeg});
  expect_near(frames.T_base_link[6].linear().col(0), {0, 0, -1});
}

TEST(ForwardKinematics, Ur5CombinedJointsByHand) {
  // Joints 1 +90° and 2 −90°: the upright arm of the joint-2 case, turned by Rz(90°):
  // (−0.09465, −0.19145, 0.906409) → (0.19145, −0.09465, 0.906409).
  expect_near(flange(BuiltinArm::ur5, {90, -90, 0, 0, 0, 0}), {d4 + d6, -d5, d1 - (a2 + a3)});
  // Joints 2 −90° and 4 −90° (UR's upright "home" with the wrist up): joint 4 first gives the
  // wrist W1 + (−d5, −(d4 + d6), 0); then joint 2 turns S + (a2 + a3 − d5, −(d4 + d6), 0) by
  // Ry(+90°) to S + (0, −(d4 + d6), −(a2 + a3 − d5)): the flange 1.001059 m up.
  expect_near(flange(BuiltinArm::ur5, {0, -90, 0, -90, 0, 0}), {0, -(d4 + d6), d1 - (a2 + a3) + d5});
}

TEST(ForwardKinematics, BaseIsBaseLinkTurnedHalfAroundZ) {
  // At q = 0 the pendant shows the flange at (a2 + a3, −(d4 + d6), d1 − d5) = (−0.81725,
  // −0.19145, −0.005491) in `base`; in ROS's base_link, where the arm points along +x, at
  // (0.81725, 0.19145, −0.005491).
  expect_near(flange(BuiltinArm::ur5, {0, 0, 0, 0, 0, 0}, BaseFrame::base), {-0.81725, -0.19145, -0.005491});
  expect_near(flange(BuiltinArm::ur5, {0, 0, 0, 0, 0, 0}, BaseFrame::base_link), {0.81725, 0.19145, -0.005491});
  const JointAngles q{0.3, -1.1, 0.7, -0.2, 1.4, 2.0};
  const Eigen::Vector3d in_base = forward_kinematics(builtin_robot(BuiltinArm::ur5), q).T_base_link[6].translation();
  const Eigen::Vector3d in_base_link = T_base_base_link().inverse(Eigen::Isometry) * in_base;
  expect_near(in_base_link, {-in_base.x(), -in_base.y(), in_base.z()});
}

TEST(ForwardKinematics, EseriesZeroPoses) {
  // (a2 + a3, −(d4 + d6), d1 − d5) with UR's e-Series tables.
  expect_near(flange(BuiltinArm::ur5e, {0, 0, 0, 0, 0, 0}), {-0.425 - 0.3922, -(0.1333 + 0.0996), 0.1625 - 0.0997});
  expect_near(flange(BuiltinArm::ur10e, {0, 0, 0, 0, 0, 0}), {-0.6127 - 0.57155, -(0.17415 + 0.11655), 0.1807 - 0.11985});
  expect_near(flange(BuiltinArm::ur10e, {0, 0, 0, 0, 0, 0}, BaseFrame::base_link), {1.18425, 0.2907, 0.06085});
  // UR10e joint 2 −90°: upright, as for the UR5: (−d5, −(d4 + d6), d1 − (a2 + a3)).
  expect_near(flange(BuiltinArm::ur10e, {0, -90, 0, 0, 0, 0}), {-0.11985, -0.2907, 0.1807 + 1.18425});
}

TEST(ForwardKinematics, FramesStayRigid) {
  // Rotations stay orthonormal for an arbitrary state (a broken DH product would shear them).
  const LinkFrames frames = forward_kinematics(builtin_robot(BuiltinArm::ur10e), JointAngles{1, 2, -2.5, 0.4, -3, 5});
  for (const Pose& T : frames.T_base_link) {
    EXPECT_TRUE((T.linear() * T.linear().transpose()).isIdentity(1e-12));
    EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
  }
}

TEST(RobotDescription, BuiltinsAreValidAndLimitsAreChecked) {
  // Each arm's description carries its robot.model name (robot_model_name prints it).
  const std::pair<BuiltinArm, const char*> named[] = {
      {BuiltinArm::ur5, "ur5"}, {BuiltinArm::ur5e, "ur5e"}, {BuiltinArm::ur10e, "ur10e"}};
  ASSERT_EQ(std::size(kBuiltinArms), std::size(named));
  for (const auto& [arm, name] : named) {
    EXPECT_EQ(description_problem(builtin_robot(arm)), "") << name;
    EXPECT_EQ(builtin_robot(arm).name, name);
  }
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  EXPECT_EQ(joint_outside_limits(ur5, JointAngles{0, 0, 0, 0, 0, 0}), -1);
  EXPECT_EQ(joint_outside_limits(ur5, JointAngles{0, 0, 6.3, 0, 0, 0}), 2);  // > 2π
  EXPECT_EQ(joint_outside_limits(ur5, JointAngles{0, 0, 0, 0, -6.3, 0}), 4);
  EXPECT_EQ(joint_outside_limits(ur5, JointAngles{0, 0, 0, 0, 0, std::nan("")}), 5);
  EXPECT_EQ(joint_outside_limits(ur5, JointAngles{2 * 3.14159265358979323846, 0, 0, 0, 0, 0}), -1);  // inclusive
}

TEST(RobotDescription, ProblemsNameTheField) {
  RobotDescription d = builtin_robot(BuiltinArm::ur5);
  d.links[3][1].radius_m = -0.1;
  EXPECT_EQ(description_problem(d), "links.forearm[1].radius_m: expected a number >= 0");
  d = builtin_robot(BuiltinArm::ur5);
  d.dh[2].a_m = std::nan("");
  EXPECT_EQ(description_problem(d), "dh[2]: expected finite numbers");
  d = builtin_robot(BuiltinArm::ur5);
  d.limits[1] = JointLimit{1.0, -1.0};
  EXPECT_EQ(description_problem(d), "joint_limits_deg[1]: expected [min, max] with min <= max");
  d = builtin_robot(BuiltinArm::ur5);
  for (auto& link : d.links) link.clear();
  EXPECT_EQ(description_problem(d), "links: expected at least one capsule");
  d.tool.push_back(LinkCapsule{Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.1), 0.04});
  EXPECT_EQ(description_problem(d), "");  // a tool alone is a robot
}

}  // namespace
}  // namespace hrcsense
