// SPDX-License-Identifier: Apache-2.0
// hrcsense robot — the built-in arms: Universal Robots' published DH tables plus capsules that
// cover the real links. The numbers and their sources are listed in docs/ROBOT.md; the same
// descriptions are spelt out in config/robots/*.yaml (a test keeps the two equal).
#include "hrcsense/robot.hpp"

#include <stdexcept>

namespace hrcsense {
namespace {

// The real arm's radii (its visual geometry), each no larger than the capsule that covers it.
struct UrBody {
  double base_radius_m, shoulder_radius_m, upper_arm_radius_m, elbow_radius_m, forearm_radius_m, wrist_radius_m;
};

// What a UR arm's capsules are built from. The DH frames put every link on the arm's
// centre plane, but the real upper arm and forearm run beside it: the upper arm at
// `shoulder_offset_m` along joint 2's axis, the forearm at `forearm_offset_m`, and the
// wrist 1 joint at d4. Lateral offsets are along +z of DH frames 1-3, the side of the wrist.
struct UrGeometry {
  const char* name;
  double d1, a2, a3, d4, d5, d6;  ///< UR's DH table, metres
  double shoulder_offset_m;       ///< upper arm axis beside the base axis
  double forearm_offset_m;        ///< forearm axis beside the base axis
  double base_radius_m;           ///< base and joint 1 housing
  double shoulder_radius_m;       ///< joint 2 housing
  double upper_arm_radius_m;      ///< upper arm tube
  double elbow_radius_m;          ///< joint 3 housing
  double forearm_radius_m;        ///< forearm tube
  double wrist_radius_m;          ///< joints 4-6 housings
  UrBody body;                    ///< the real arm's radii, for rendering
};

LinkCapsule link_capsule(double ax, double ay, double az, double bx, double by, double bz, double radius_m) {
  return LinkCapsule{Eigen::Vector3d(ax, ay, az), Eigen::Vector3d(bx, by, bz), radius_m};
}

RobotDescription ur_arm(const UrGeometry& g) {
  RobotDescription r;
  r.name = g.name;
  // α = 90°, 0, 0, 90°, −90°, 0 for every UR arm; (deg / 180) · π so that ±90° is exactly ±π/2
  // (the YAML reader converts the same way).
  const double quarter = (90.0 / 180.0) * kPi;
  r.dh = {DhRow{g.d1, 0.0, quarter}, DhRow{0.0, g.a2, 0.0}, DhRow{0.0, g.a3, 0.0},
          DhRow{g.d4, 0.0, quarter}, DhRow{g.d5, 0.0, -quarter}, DhRow{g.d6, 0.0, 0.0}};
  // UR's datasheets: ±360° on every joint.
  for (JointLimit& limit : r.limits) limit = JointLimit{-(360.0 / 180.0) * kPi, (360.0 / 180.0) * kPi};
  const double s = g.shoulder_offset_m;
  const double f = g.forearm_offset_m;
  // Each capsule ends where the next link's begins, so the chain has no gaps at the joints.
  // Housings lie on their joint's axis, so they do not move with that joint's angle.
  r.links[0] = {link_capsule(0, 0, 0, 0, 0, g.d1, g.base_radius_m)};          // base to joint 2's axis
  r.links[1] = {link_capsule(0, 0, 0, 0, 0, s, g.shoulder_radius_m)};         // along joint 2's axis
  r.links[2] = {link_capsule(-g.a2, 0, s, 0, 0, s, g.upper_arm_radius_m)};    // shoulder to elbow
  r.links[3] = {link_capsule(-g.a3, 0, s, -g.a3, 0, f, g.elbow_radius_m),     // along joint 3's axis
                link_capsule(-g.a3, 0, f, 0, 0, f, g.forearm_radius_m)};      // elbow to wrist 1
  r.links[4] = {link_capsule(0, -(g.d4 - f), 0, 0, 0, 0, g.wrist_radius_m)};  // along joint 4's axis
  r.links[5] = {link_capsule(0, g.d5, 0, 0, 0, 0, g.wrist_radius_m)};         // along joint 5's axis
  r.links[6] = {link_capsule(0, 0, -g.d6, 0, 0, 0, g.wrist_radius_m)};        // along joint 6's axis to the flange
  // The visible arm: housings and tubes at their real radii. The base housing stops under the
  // shoulder housing instead of running up to joint 2's axis.
  const UrBody& v = g.body;
  r.visual[0] = {link_capsule(0, 0, 0, 0, 0, g.d1 - v.shoulder_radius_m, v.base_radius_m)};
  r.visual[1] = {link_capsule(0, 0, 0, 0, 0, s, v.shoulder_radius_m)};
  r.visual[2] = {link_capsule(-g.a2, 0, s, 0, 0, s, v.upper_arm_radius_m)};
  r.visual[3] = {link_capsule(-g.a3, 0, s, -g.a3, 0, f, v.elbow_radius_m),
                 link_capsule(-g.a3, 0, f, 0, 0, f, v.forearm_radius_m)};
  r.visual[4] = {link_capsule(0, -(g.d4 - f), 0, 0, 0, 0, v.wrist_radius_m)};
  r.visual[5] = {link_capsule(0, g.d5, 0, 0, 0, 0, v.wrist_radius_m)};
  r.visual[6] = {link_capsule(0, 0, -g.d6, 0, 0, 0, v.wrist_radius_m)};
  return r;
}

// DH: UR's "DH parameters for calculations of kinematics and dynamics" (CB3 UR5 and e-Series).
// Lateral offsets: UR's link geometry as published with its meshes (ROS ur_description).
// Radii: rounded up from the footprints in UR's datasheets (UR5/UR5e Ø149 mm, UR10e Ø190 mm)
// and the housings' size; the bodies: the footprint and the collision primitives published
// with UR's meshes (UR10e's scaled from them); docs/ROBOT.md gives the reasoning per link.
const UrGeometry kUr5{"ur5", 0.089159, -0.425, -0.39225, 0.10915, 0.09465, 0.0823,
                      0.13585, 0.01615,  // forearm: 0.13585 - 0.1197 (elbow offset)
                      0.075, 0.065, 0.060, 0.060, 0.050, 0.045,
                      UrBody{0.0745, 0.060, 0.050, 0.055, 0.038, 0.040}};
const UrGeometry kUr5e{"ur5e", 0.1625, -0.425, -0.3922, 0.1333, 0.0997, 0.0996,
                       0.138, 0.007,  // forearm: 0.138 - 0.131
                       0.075, 0.065, 0.060, 0.060, 0.050, 0.045,
                      UrBody{0.0745, 0.060, 0.050, 0.055, 0.038, 0.040}};
const UrGeometry kUr10e{"ur10e", 0.1807, -0.6127, -0.57155, 0.17415, 0.11985, 0.11655,
                        0.176, 0.039,  // forearm: 0.176 - 0.137
                        0.095, 0.085, 0.070, 0.065, 0.050, 0.055,
                        UrBody{0.095, 0.075, 0.060, 0.060, 0.045, 0.045}};

}  // namespace

const RobotDescription& builtin_robot(BuiltinArm arm) {
  static const RobotDescription ur5 = ur_arm(kUr5);
  static const RobotDescription ur5e = ur_arm(kUr5e);
  static const RobotDescription ur10e = ur_arm(kUr10e);
  switch (arm) {
    case BuiltinArm::ur5: return ur5;
    case BuiltinArm::ur5e: return ur5e;
    case BuiltinArm::ur10e: return ur10e;
  }
  throw std::invalid_argument("builtin_robot: " + std::to_string(static_cast<int>(arm)) + " is not a built-in arm");
}

}  // namespace hrcsense
