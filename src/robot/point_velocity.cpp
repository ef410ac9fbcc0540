// SPDX-License-Identifier: Apache-2.0
// hrcsense — the velocity of a point on the arm from the joint velocities (robot.hpp):
// speed and separation monitoring needs the robot's speed at its closest point.

#include "hrcsense/robot.hpp"

#include <algorithm>

namespace hrcsense {

Eigen::Vector3d point_velocity(const RobotDescription& description, const JointAngles& joints_rad,
                               const JointAngles& joint_velocities_rad_s, int link, const Eigen::Vector3d& point,
                               BaseFrame frame) {
  // Work in `base` (DH frame 0), where the kinematics are; base_link is base turned π about z.
  const bool in_base_link = frame == BaseFrame::base_link;
  const Pose T_base_frame = in_base_link ? T_base_base_link() : Pose::Identity();
  const Eigen::Vector3d p_base = T_base_frame * point;
  const LinkFrames frames = forward_kinematics(description, joints_rad);
  const int moved_by = link == kToolLink ? kJointCount : std::clamp(link, 0, kJointCount);
  Eigen::Vector3d v_base = Eigen::Vector3d::Zero();
  for (int j = 0; j < moved_by; ++j) {
    const Pose& T = frames.T_base_link[static_cast<size_t>(j)];  // DH frame j: joint j+1 turns about its z
    const Eigen::Vector3d axis = T.linear().col(2);
    v_base += joint_velocities_rad_s[static_cast<size_t>(j)] * axis.cross(p_base - T.translation());
  }
  return T_base_frame.linear().transpose() * v_base;
}

}  // namespace hrcsense
