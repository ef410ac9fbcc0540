// SPDX-License-Identifier: Apache-2.0
// hrcsense — the robot arm as a kinematic capsule model: a 6-joint standard-DH description
// (UR5, UR5e, UR10e built in, others from YAML), forward kinematics, and the capsules the
// proximity search uses for a joint state. See docs/ROBOT.md for the frames and numbers.
#pragma once

#include "hrcsense/types.hpp"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {

/// Links 0..6: 0 the fixed base (DH frame 0), i the body moved by joint i (DH frame i);
/// link 6 is wrist 3, whose frame is the tool flange.
inline constexpr int kArmLinkCount = 7;
/// Capsule::link of the tool's capsules (given in the flange frame, DH frame 6).
inline constexpr int kToolLink = 7;

/// One row of a standard Denavit-Hartenberg table, as Universal Robots publish them:
/// T_{i-1,i} = Rz(θ_i) · Tz(d) · Tx(a) · Rx(α).
struct DhRow {
  double d_m = 0.0;        ///< offset along the previous z
  double a_m = 0.0;        ///< length along the new x (UR: negative for the upper arm and forearm)
  double alpha_rad = 0.0;  ///< twist about the new x
};

/// Allowed range of one joint, radians, inclusive.
struct JointLimit {
  double min_rad = -2.0 * 3.14159265358979323846;
  double max_rad = 2.0 * 3.14159265358979323846;
};

/// A capsule fixed to a link: segment ends in that link's DH frame (the flange frame for the
/// tool), metres, and the radius of the real body around the segment.
struct LinkCapsule {
  Eigen::Vector3d a_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d b_m = Eigen::Vector3d::Zero();
  double radius_m = 0.0;  ///< covers the real link; the search adds the padding
};

/// A 6-joint arm: kinematics, the capsules that cover its links (what the search uses, like a
/// URDF's collision geometry) and optionally its own visible shape (like a URDF's visual).
struct RobotDescription {
  std::string name;                                    ///< e.g. "ur5"
  std::array<DhRow, kJointCount> dh{};                 ///< joint 1 first
  std::array<JointLimit, kJointCount> limits{};        ///< joint 1 first
  std::array<std::vector<LinkCapsule>, kArmLinkCount> links;  ///< capsules per link, link frame
  /// The real body per link, link frame, for rendering only (the simulator); it must lie inside
  /// `links`. A link without visual shapes is drawn as its `links` capsules.
  std::array<std::vector<LinkCapsule>, kArmLinkCount> visual;
  std::vector<LinkCapsule> tool;                       ///< in the flange frame; may be empty
  double padding_m = 0.0;  ///< default of robot.padding_m for this arm (added to every radius)
};

/// Which frame robot capsules, camera.T_base_camera and all base-frame outputs refer to.
enum class BaseFrame {
  base,       ///< UR's DH frame 0: as on the UR pendant (actual_TCP_pose) and ROS's `base`
  base_link,  ///< ROS's `base_link`: base rotated π about z, +x along the arm at q = 0
};

/// The robot the pipeline measures against (PipelineParams::robot): an arm whose capsules
/// follow each frame's RobotState, or fixed capsules (robot.model points, the thesis's point).
struct RobotParams {
  std::optional<RobotDescription> arm;  ///< with an arm, the capsules come from the joint state
  double padding_m = 0.0;               ///< `robot.padding_m`, added to every arm capsule's radius
  BaseFrame base_frame = BaseFrame::base;  ///< `robot.base_frame`: the frame of the capsules
  RobotModel points;                    ///< without an arm: the capsules as they are (base frame)
};

/// Pose of every link's DH frame in DH frame 0, which is UR's (and hrcsense's) `base`:
/// T_base_link[0] is the identity (the fixed base), T_base_link[i] the frame after joint i;
/// T_base_link[6] is the tool flange.
struct LinkFrames {
  std::array<Pose, kArmLinkCount> T_base_link;
};

/// The built-in arms (robot.model ur5, ur5e, ur10e): UR's CB3 UR5, the e-Series UR5e and UR10e.
enum class BuiltinArm { ur5, ur5e, ur10e };
inline constexpr BuiltinArm kBuiltinArms[] = {BuiltinArm::ur5, BuiltinArm::ur5e, BuiltinArm::ur10e};
/// A built-in arm's description; its `name` is the arm's robot.model name ("ur5", ...).
const RobotDescription& builtin_robot(BuiltinArm arm);

/// ROS-style name of a link index (0..7): base, shoulder, upper_arm, forearm, wrist_1,
/// wrist_2, wrist_3, tool; "link<i>" outside that range.
std::string link_name(int link);

/// ROS-style name of a joint index (0..5): shoulder_pan, shoulder_lift, elbow, wrist_1,
/// wrist_2, wrist_3; "joint<i+1>" outside that range.
std::string joint_name(int joint);

/// Why `description` cannot be used (a field named as in the YAML format, e.g.
/// "links.forearm[1].radius_m: expected a number >= 0"), or "" when it is valid.
std::string description_problem(const RobotDescription& description);

/// The first joint outside its limits (0-based) or -1 when all are inside. A NaN angle is
/// outside.
int joint_outside_limits(const RobotDescription& description, const JointAngles& joints_rad);

/// T_base_base_link: the pendant/ROS `base` frame (UR's DH frame 0) from ROS's `base_link` (a
/// rotation of π about z; its own inverse).
Pose T_base_base_link();

/// Forward kinematics: every link frame in `base` (DH frame 0) for the joint state.
LinkFrames forward_kinematics(const RobotDescription& description, const JointAngles& joints_rad);

/// Velocity (m/s, in `frame`) of a point fixed to link `link` (0..6, or kToolLink, which moves
/// with the flange) at `point` (in `frame`), for joint angles `joints_rad` and velocities
/// `joint_velocities_rad_s`: the sum over joints 1..link of ω_j · z_{j−1} × (p − o_{j−1}),
/// joint j turning about the z axis of DH frame j−1. Zero for link 0 (the fixed base).
Eigen::Vector3d point_velocity(const RobotDescription& description, const JointAngles& joints_rad,
                               const JointAngles& joint_velocities_rad_s, int link, const Eigen::Vector3d& point,
                               BaseFrame frame);

/// The capsules the proximity search uses, in `frame`: every link and tool capsule moved by
/// forward kinematics, radius = link radius + `padding_m`, Capsule::link = link index 0..6,
/// kToolLink for the tool. Writes into `out`, reusing its buffer (no allocation once sized).
void robot_capsules(const RobotDescription& description, const JointAngles& joints_rad, double padding_m,
                    BaseFrame frame, RobotModel& out);
/// Same, returning a new model.
RobotModel robot_capsules(const RobotDescription& description, const JointAngles& joints_rad, double padding_m,
                          BaseFrame frame);

/// The capsules of `robot` for the joint state `joints_rad` (robot_capsules of the arm with
/// its padding and frame), or its fixed points without an arm. Reuses `out`'s buffer: no
/// allocation once sized.
void robot_model_at(const RobotParams& robot, const JointAngles& joints_rad, RobotModel& out);
/// Same, returning a new model.
RobotModel robot_model_at(const RobotParams& robot, const JointAngles& joints_rad);

/// The arm's own geometry for rendering (the simulator): each link's `visual` shapes, or its
/// `links` capsules where it has none, and the tool's capsules; no padding. Capsule::link as in
/// robot_capsules.
RobotModel robot_render_capsules(const RobotDescription& description, const JointAngles& joints_rad,
                                 BaseFrame frame);

/// Same, into `out`, reusing its buffer (no allocation once sized): the simulator's moving arm.
void robot_render_capsules(const RobotDescription& description, const JointAngles& joints_rad, BaseFrame frame,
                           RobotModel& out);

/// Limits of the check of a controller's reported TCP pose against the forward kinematics of its
/// joints (check_tcp_pose; docs/ROBOT.md, "TCP pose check").
struct TcpPoseCheckParams {
  /// The reported TCP may lie at most this far from the flange, metres: the controller's active
  /// TCP offset (the tool), which the RTDE outputs hrcsense reads do not give.
  double max_tcp_offset_m = 0.5;
  /// The flange → TCP offset implied by a sample may differ from the reference's (the first
  /// plausible sample of the connection) by this much, metres: the offset is fixed to the
  /// flange, and the controller's calibrated kinematics differ from the nominal DH table by
  /// millimetres only.
  double offset_tolerance_m = 0.02;
  /// ...and by this rotation, radians (2°).
  double offset_tolerance_rad = 0.035;
};

/// The result of one check_tcp_pose.
struct TcpPoseCheck {
  bool consistent = false;   ///< within every limit (false for non-finite input)
  /// The flange → TCP transform the reported pose implies: T_base_flange(q)⁻¹ · T_base_tcp.
  Pose T_flange_tcp = Pose::Identity();
  double offset_m = 0.0;     ///< |translation of T_flange_tcp|: the implied tool length
  double drift_m = 0.0;      ///< translation between T_flange_tcp and the reference's; 0 without one
  double drift_rad = 0.0;    ///< rotation angle between them; 0 without one
  /// |translation| of the implied offset if the kinematics were turned π about z (a description
  /// in base_link taken for base): small where offset_m is not points at a base frame mix-up.
  double offset_turned_m = 0.0;
};

/// UR's pose vector [x, y, z (m), rx, ry, rz (rotation vector: axis times angle, rad)] as a Pose.
Pose pose_from_ur_vector(const std::array<double, 6>& pose);

/// Compares `tcp_pose_base` (UR's actual_TCP_pose: in the pendant's base frame, `base`,
/// with the controller's active TCP offset applied) with the forward kinematics of `q_rad`:
/// consistent when the implied flange → TCP offset is at most max_tcp_offset_m long and, with
/// a `reference` (an earlier sample's T_flange_tcp), within the offset tolerances of it.
/// robot.base_frame does not enter: both sides are taken in the pendant's frame.
TcpPoseCheck check_tcp_pose(const RobotDescription& description, const JointAngles& q_rad,
                            const std::array<double, 6>& tcp_pose_base, const Pose* reference,
                            const TcpPoseCheckParams& params);

/// A failed check for people: "disagrees with the `robot` forward kinematics of the joints: " what
/// is off by how much against which limit, and the likely cause (a base/base_link mix-up when
/// the turned reading fits, else a wrong description or frame).
std::string tcp_pose_problem(const std::string& robot, const TcpPoseCheck& check, const TcpPoseCheckParams& limits);

/// One waypoint of a scripted arm motion (`robot.trajectory.waypoints[i]`).
struct TrajectoryWaypoint {
  double t_s = 0.0;       ///< source time, seconds (the simulator's frame index / fps)
  JointAngles q_rad{};    ///< joint angles at t_s, joint 1 first
};

/// How joints_at() moves between waypoints.
enum class TrajectoryInterpolation {
  linear,  ///< piecewise linear: qd is the segment's slope (steps at the waypoints)
  /// Cubic Hermite (C1): at an inner waypoint k the velocity is the central difference
  /// (q[k+1] - q[k-1]) / (t[k+1] - t[k-1]) (a Catmull-Rom spline for non-uniform times); zero at
  /// the first and last waypoint, so a looped cycle is C1 across the wrap too.
  cubic,
};

/// A scripted arm motion (`robot.trajectory`, docs/CONFIG.md). Valid as config checks it: at
/// least two waypoints, t_s strictly increasing, joints within the arm's limits; with `loop`
/// the last waypoint's joints equal the first's (a closed cycle).
struct RobotTrajectory {
  TrajectoryInterpolation interpolation = TrajectoryInterpolation::linear;
  /// true: time wraps over [first t_s, last t_s); false: the ends are held (qd 0) outside.
  bool loop = false;
  std::vector<TrajectoryWaypoint> waypoints;
  /// `robot.trajectory.follow_link` (simulator only; a test and demo feature): the arm obeys the
  /// speed scale hrcsense sends, its trajectory time advancing by each frame step times the
  /// last scale sent (TrajectoryClock). false: it runs at its programmed speed whatever is sent.
  bool follow_link = false;
};

/// Joint angles and velocities of a trajectory at one time.
struct TrajectorySample {
  JointAngles q_rad{};     ///< joint angles
  JointAngles qd_rad_s{};  ///< joint velocities (the derivative of q_rad in t)
};

/// The trajectory's state at `t_s` (same clock as the waypoints). Pure and allocation-free.
/// At a waypoint: its joints, with the velocity of the segment that starts there. Before the
/// first waypoint or from the last on (without loop): that waypoint's joints, qd 0.
/// Precondition: the trajectory is valid as RobotTrajectory says; an empty one gives zeros.
TrajectorySample joints_at(const RobotTrajectory& trajectory, double t_s);

/// `robot`'s capsules grouped by link (Capsule::link), one model per link in ascending link
/// order, each keeping its capsules' order. Reuses `out`'s buffers: no allocation once sized.
void split_by_link(const RobotModel& robot, std::vector<RobotModel>& out);

/// The thesis's robot: one zero-length capsule per point (base frame), radius `padding_m`,
/// link = the point's index.
RobotModel robot_points(const std::vector<Eigen::Vector3f>& points_base, double padding_m);

}  // namespace hrcsense
