// SPDX-License-Identifier: Apache-2.0
// hrcsense robot — a controller's reported TCP pose against the forward kinematics of its joints:
// what tells a wrong robot description or a turned base frame apart from a good one.
#include "hrcsense/robot.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace hrcsense {

Pose pose_from_ur_vector(const std::array<double, 6>& pose) {
  Pose T = Pose::Identity();
  T.translation() << pose[0], pose[1], pose[2];
  const Eigen::Vector3d rotation(pose[3], pose[4], pose[5]);
  const double angle_rad = rotation.norm();
  // Below 1e-12 rad the axis is noise and the rotation the identity to double precision.
  if (angle_rad > 1e-12) T.linear() = Eigen::AngleAxisd(angle_rad, rotation / angle_rad).toRotationMatrix();
  return T;
}

TcpPoseCheck check_tcp_pose(const RobotDescription& description, const JointAngles& q_rad,
                            const std::array<double, 6>& tcp_pose_base, const Pose* reference,
                            const TcpPoseCheckParams& params) {
  TcpPoseCheck out;
  bool finite = true;
  for (double v : q_rad) finite = finite && std::isfinite(v);
  for (double v : tcp_pose_base) finite = finite && std::isfinite(v);
  if (!finite) return out;
  const Pose T_base_flange = forward_kinematics(description, q_rad).T_base_link[kArmLinkCount - 1];
  const Pose T_base_tcp = pose_from_ur_vector(tcp_pose_base);
  // The pendant's frame is UR's DH frame 0, hrcsense's `base`; the kinematics turned π about z
  // (base_link) are the diagnosis of a frame mix-up.
  out.T_flange_tcp = T_base_flange.inverse(Eigen::Isometry) * T_base_tcp;
  out.offset_m = out.T_flange_tcp.translation().norm();
  out.offset_turned_m = ((T_base_base_link() * T_base_flange).inverse(Eigen::Isometry) * T_base_tcp).translation().norm();
  out.consistent = out.offset_m <= params.max_tcp_offset_m;
  if (reference != nullptr) {
    out.drift_m = (out.T_flange_tcp.translation() - reference->translation()).norm();
    out.drift_rad = Eigen::AngleAxisd(reference->linear().transpose() * out.T_flange_tcp.linear()).angle();
    out.consistent = out.consistent && out.drift_m <= params.offset_tolerance_m &&
                     out.drift_rad <= params.offset_tolerance_rad;
  }
  return out;
}

std::string tcp_pose_problem(const std::string& robot, const TcpPoseCheck& check, const TcpPoseCheckParams& limits) {
  constexpr double kDegPerRad = 180.0 / M_PI;
  char what[256];
  const bool too_long = check.offset_m > limits.max_tcp_offset_m;
  if (too_long) {
    std::snprintf(what, sizeof what, "the TCP is %.3f m from the flange (a tool offset is at most %.3f m)",
                  check.offset_m, limits.max_tcp_offset_m);
  } else {
    std::snprintf(what, sizeof what,
                  "the flange-to-TCP offset moved %.3f m and %.1f deg from the reference sample's "
                  "(at most %.3f m and %.1f deg)",
                  check.drift_m, check.drift_rad * kDegPerRad, limits.offset_tolerance_m,
                  limits.offset_tolerance_rad * kDegPerRad);
  }
  char cause[160];
  if (too_long && check.offset_turned_m <= limits.max_tcp_offset_m) {
    std::snprintf(cause, sizeof cause, "with the pose turned pi about z it would be %.3f m: a base/base_link mix-up?",
                  check.offset_turned_m);
  } else {
    std::snprintf(cause, sizeof cause, "wrong robot.model, or a base frame turned?");
  }
  return "disagrees with the " + robot + " forward kinematics of the joints: " + what + "; " + cause;
}

}  // namespace hrcsense
