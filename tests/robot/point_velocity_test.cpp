// SPDX-License-Identifier: Apache-2.0
// point_velocity against a hand-worked case and against central differences of the forward
// kinematics (an independent route to the same velocity).

#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>

namespace hrcsense {
namespace {

TEST(PointVelocity, ShoulderPanAloneTurnsAboutTheBaseZ) {
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  JointAngles q{};
  JointAngles qd{};
  qd[0] = 0.5;
  // Joint 1 turns about base z through the origin: v = ω·ẑ × p = 0.5·(−0.2, 0.3, 0).
  const Eigen::Vector3d p(0.3, 0.2, 0.4);
  for (int link : {1, 3, 6, kToolLink}) {
    const Eigen::Vector3d v = point_velocity(ur5, q, qd, link, p, BaseFrame::base);
    EXPECT_NEAR((v - Eigen::Vector3d(-0.1, 0.15, 0.0)).norm(), 0.0, 1e-12) << link;
  }
  EXPECT_EQ(point_velocity(ur5, q, qd, 0, p, BaseFrame::base), Eigen::Vector3d::Zero());  // the fixed base
  // base_link is base turned π about z: the same motion reads (−x, −y, z) there, and the point
  // (0.3, 0.2, 0.4) of base_link is (−0.3, −0.2, 0.4) of base: v_base = 0.5·(0.2, −0.3, 0).
  const Eigen::Vector3d v_link = point_velocity(ur5, q, qd, 3, p, BaseFrame::base_link);
  EXPECT_NEAR((v_link - Eigen::Vector3d(-0.1, 0.15, 0.0)).norm(), 0.0, 1e-12);
}

// p(q) of a point fixed in link `link`'s frame, in base.
Eigen::Vector3d point_at(const RobotDescription& arm, const JointAngles& q, int link, const Eigen::Vector3d& p_link) {
  return forward_kinematics(arm, q).T_base_link[static_cast<size_t>(link == kToolLink ? kJointCount : link)] * p_link;
}

TEST(PointVelocity, MatchesCentralDifferencesOfTheKinematics) {
  const Eigen::Vector3d p_link(0.1, -0.05, 0.02);
  const JointAngles q{0.3, -1.2, 1.1, -0.4, 0.7, 0.2};
  const JointAngles qd{0.4, -0.3, 0.5, 1.0, -0.8, 0.6};
  const double h = 1e-6;
  JointAngles q_plus = q, q_minus = q;
  for (size_t j = 0; j < q.size(); ++j) {
    q_plus[j] += qd[j] * h;
    q_minus[j] -= qd[j] * h;
  }
  for (const BuiltinArm name : {BuiltinArm::ur5, BuiltinArm::ur10e}) {
    const RobotDescription& arm = builtin_robot(name);
    for (int link = 1; link <= kJointCount; ++link) {
      const Eigen::Vector3d expected =
          (point_at(arm, q_plus, link, p_link) - point_at(arm, q_minus, link, p_link)) / (2.0 * h);
      const Eigen::Vector3d v = point_velocity(arm, q, qd, link, point_at(arm, q, link, p_link), BaseFrame::base);
      EXPECT_NEAR((v - expected).norm(), 0.0, 1e-6) << arm.name << " link " << link;
    }
  }
}

}  // namespace
}  // namespace hrcsense
