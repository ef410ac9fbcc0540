// SPDX-License-Identifier: Apache-2.0
// hrcsense robot — forward kinematics (standard DH) and the capsules of a joint state.
#include "hrcsense/robot.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace hrcsense {
namespace {

// T_{i-1,i} = Rz(θ) · Tz(d) · Tx(a) · Rx(α), the standard DH convention UR's tables use.
Pose dh_transform(const DhRow& row, double theta_rad) {
  const double ct = std::cos(theta_rad);
  const double st = std::sin(theta_rad);
  const double ca = std::cos(row.alpha_rad);
  const double sa = std::sin(row.alpha_rad);
  Pose T = Pose::Identity();
  T.linear() << ct, -st * ca, st * sa,  //
      st, ct * ca, -ct * sa,            //
      0.0, sa, ca;
  T.translation() << row.a_m * ct, row.a_m * st, row.d_m;
  return T;
}

// The configured frame from DH frame 0 (= base): base_link is base turned π about z.
Pose frame_from_base(BaseFrame frame) {
  return frame == BaseFrame::base_link ? T_base_base_link().inverse(Eigen::Isometry) : Pose::Identity();
}

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

std::string capsule_problem(const LinkCapsule& capsule, const std::string& field) {
  if (!finite(capsule.a_m)) return field + ".a_m: expected 3 finite numbers";
  if (!finite(capsule.b_m)) return field + ".b_m: expected 3 finite numbers";
  if (!std::isfinite(capsule.radius_m) || capsule.radius_m < 0.0) {
    return field + ".radius_m: expected a number >= 0";
  }
  return {};
}

// The first bad capsule of a list, named field[i], or "".
std::string list_problem(const std::vector<LinkCapsule>& capsules, const std::string& field) {
  for (size_t i = 0; i < capsules.size(); ++i) {
    std::string problem = capsule_problem(capsules[i], field + "[" + std::to_string(i) + "]");
    if (!problem.empty()) return problem;
  }
  return {};
}

Capsule moved(const LinkCapsule& capsule, const Pose& T_frame_link, double padding_m, int link) {
  Capsule out;
  out.a = (T_frame_link * capsule.a_m).cast<float>();
  out.b = (T_frame_link * capsule.b_m).cast<float>();
  out.radius_m = static_cast<float>(capsule.radius_m + padding_m);
  out.link = link;
  return out;
}

enum class Geometry { collision, visual };

// Every link's capsules (`visual`: its visual shapes where it has any) and the tool's, moved by
// forward kinematics into `frame`, radius + padding_m. Reuses out's buffer.
void place_capsules(const RobotDescription& description, const JointAngles& joints_rad, double padding_m,
                    BaseFrame frame, Geometry geometry, RobotModel& out) {
  const LinkFrames frames = forward_kinematics(description, joints_rad);
  const Pose T_frame_base = frame_from_base(frame);
  out.capsules.clear();
  for (int link = 0; link < kArmLinkCount; ++link) {
    const size_t i = static_cast<size_t>(link);
    const bool visual = geometry == Geometry::visual && !description.visual[i].empty();
    const Pose T_frame_link = T_frame_base * frames.T_base_link[i];
    for (const LinkCapsule& capsule : visual ? description.visual[i] : description.links[i]) {
      out.capsules.push_back(moved(capsule, T_frame_link, padding_m, link));
    }
  }
  const Pose T_frame_flange = T_frame_base * frames.T_base_link[kArmLinkCount - 1];
  for (const LinkCapsule& capsule : description.tool) {
    out.capsules.push_back(moved(capsule, T_frame_flange, padding_m, kToolLink));
  }
}

}  // namespace

std::string link_name(int link) {
  static const char* const names[] = {"base",    "shoulder", "upper_arm", "forearm",
                                      "wrist_1", "wrist_2",  "wrist_3",   "tool"};
  if (link < 0 || link > kToolLink) return "link" + std::to_string(link);
  return names[link];
}

std::string joint_name(int joint) {
  static const char* const names[] = {"shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2", "wrist_3"};
  if (joint < 0 || joint >= kJointCount) return "joint" + std::to_string(joint + 1);
  return names[joint];
}

std::string description_problem(const RobotDescription& description) {
  for (int j = 0; j < kJointCount; ++j) {
    const DhRow& row = description.dh[static_cast<size_t>(j)];
    if (!std::isfinite(row.d_m) || !std::isfinite(row.a_m) || !std::isfinite(row.alpha_rad)) {
      return "dh[" + std::to_string(j) + "]: expected finite numbers";
    }
    const JointLimit& limit = description.limits[static_cast<size_t>(j)];
    if (!std::isfinite(limit.min_rad) || !std::isfinite(limit.max_rad) || limit.min_rad > limit.max_rad) {
      return "joint_limits_deg[" + std::to_string(j) + "]: expected [min, max] with min <= max";
    }
  }
  size_t count = description.tool.size();
  for (int link = 0; link < kArmLinkCount; ++link) {
    const size_t i = static_cast<size_t>(link);
    std::string problem = list_problem(description.links[i], "links." + link_name(link));
    if (problem.empty()) problem = list_problem(description.visual[i], "visual." + link_name(link));
    if (!problem.empty()) return problem;
    count += description.links[i].size();
  }
  const std::string problem = list_problem(description.tool, "tool");
  if (!problem.empty()) return problem;
  // An arm without capsules would never be near anything: every verdict would be "run".
  if (count == 0) return "links: expected at least one capsule";
  if (!std::isfinite(description.padding_m) || description.padding_m < 0.0) {
    return "padding_m: expected a number >= 0";
  }
  return {};
}

int joint_outside_limits(const RobotDescription& description, const JointAngles& joints_rad) {
  for (int j = 0; j < kJointCount; ++j) {
    const JointLimit& limit = description.limits[static_cast<size_t>(j)];
    const double q = joints_rad[static_cast<size_t>(j)];
    if (!(q >= limit.min_rad && q <= limit.max_rad)) return j;  // NaN fails both comparisons
  }
  return -1;
}

Pose T_base_base_link() {
  // Rz(π) written out: AngleAxis(π) would leave sin(π) ≈ 1.2e-16 off the diagonal.
  Pose T = Pose::Identity();
  T.linear() = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
  return T;
}

LinkFrames forward_kinematics(const RobotDescription& description, const JointAngles& joints_rad) {
  LinkFrames frames;
  frames.T_base_link[0] = Pose::Identity();
  for (int j = 0; j < kJointCount; ++j) {
    const size_t i = static_cast<size_t>(j);
    frames.T_base_link[i + 1] = frames.T_base_link[i] * dh_transform(description.dh[i], joints_rad[i]);
  }
  return frames;
}

void robot_capsules(const RobotDescription& description, const JointAngles& joints_rad, double padding_m,
                    BaseFrame frame, RobotModel& out) {
  place_capsules(description, joints_rad, padding_m, frame, Geometry::collision, out);
}

RobotModel robot_capsules(const RobotDescription& description, const JointAngles& joints_rad, double padding_m,
                          BaseFrame frame) {
  RobotModel model;
  robot_capsules(description, joints_rad, padding_m, frame, model);
  return model;
}

void robot_model_at(const RobotParams& robot, const JointAngles& joints_rad, RobotModel& out) {
  if (robot.arm) {
    robot_capsules(*robot.arm, joints_rad, robot.padding_m, robot.base_frame, out);
  } else {
    out.capsules.assign(robot.points.capsules.begin(), robot.points.capsules.end());  // keeps out's capacity
  }
}

RobotModel robot_model_at(const RobotParams& robot, const JointAngles& joints_rad) {
  RobotModel model;
  robot_model_at(robot, joints_rad, model);
  return model;
}

RobotModel robot_render_capsules(const RobotDescription& description, const JointAngles& joints_rad,
                                 BaseFrame frame) {
  // No padding: the visual shapes are the real arm, which the searched capsules (link radius
  // plus padding) must contain.
  RobotModel model;
  robot_render_capsules(description, joints_rad, frame, model);
  return model;
}

void robot_render_capsules(const RobotDescription& description, const JointAngles& joints_rad, BaseFrame frame,
                           RobotModel& out) {
  place_capsules(description, joints_rad, 0.0, frame, Geometry::visual, out);
}

RobotModel robot_points(const std::vector<Eigen::Vector3f>& points_base, double padding_m) {
  RobotModel model;
  for (size_t i = 0; i < points_base.size(); ++i) {
    model.capsules.push_back(Capsule{points_base[i], points_base[i], static_cast<float>(padding_m), static_cast<int>(i)});
  }
  return model;
}

void split_by_link(const RobotModel& robot, std::vector<RobotModel>& out) {
  // Links are few (8 for an arm with a tool) and each capsule is visited once per link: no
  // sort, no map, no allocation once `out` has its size.
  size_t links = 0;
  int previous = std::numeric_limits<int>::min();
  for (;;) {
    int next = std::numeric_limits<int>::max();
    for (const Capsule& c : robot.capsules) {
      if (c.link > previous && c.link < next) next = c.link;
    }
    if (next == std::numeric_limits<int>::max()) break;
    if (out.size() <= links) out.emplace_back();
    RobotModel& model = out[links++];
    model.capsules.clear();
    for (const Capsule& c : robot.capsules) {
      if (c.link == next) model.capsules.push_back(c);
    }
    previous = next;
  }
  out.resize(links);
}

}  // namespace hrcsense
