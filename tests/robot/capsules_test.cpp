// SPDX-License-Identifier: Apache-2.0
// The capsules of a joint state: a connected chain, padding on the radius, link indices, the
// base / base_link frames, the tool, the rendering geometry and the thesis's points.
#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

namespace hrcsense {
namespace {

constexpr double kPi = 3.14159265358979323846;

JointAngles random_joints(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  JointAngles q{};
  for (double& v : q) v = angle(rng);
  return q;
}

// First and last capsule of a link in the model (capsules are grouped by link, in order).
const Capsule& first_of(const RobotModel& model, int link) {
  for (const Capsule& c : model.capsules) {
    if (c.link == link) return c;
  }
  throw std::out_of_range("no capsule of link " + std::to_string(link));
}
const Capsule& last_of(const RobotModel& model, int link) {
  const Capsule* last = nullptr;
  for (const Capsule& c : model.capsules) {
    if (c.link == link) last = &c;
  }
  if (last == nullptr) throw std::out_of_range("no capsule of link " + std::to_string(link));
  return *last;
}

TEST(RobotCapsules, ConsecutiveLinksMeetAtTheJoints) {
  std::mt19937 rng(7);
  for (const BuiltinArm arm : kBuiltinArms) {
    const std::string& name = builtin_robot(arm).name;
    for (int trial = 0; trial < 50; ++trial) {
      const JointAngles q = random_joints(rng);
      const RobotModel model = robot_capsules(builtin_robot(arm), q, 0.0, BaseFrame::base);
      for (int link = 0; link + 1 < kArmLinkCount; ++link) {
        EXPECT_LT((last_of(model, link).b - first_of(model, link + 1).a).norm(), 1e-5F)
            << name << " between " << link_name(link) << " and " << link_name(link + 1);
      }
      // Within the forearm the elbow housing leads into the tube.
      const std::vector<const Capsule*> forearm = [&] {
        std::vector<const Capsule*> out;
        for (const Capsule& c : model.capsules) {
          if (c.link == 3) out.push_back(&c);
        }
        return out;
      }();
      ASSERT_EQ(forearm.size(), 2U);
      EXPECT_LT((forearm[0]->b - forearm[1]->a).norm(), 1e-5F);
    }
  }
}

TEST(RobotCapsules, ChainEndsAtTheBaseAndTheFlange) {
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  const JointAngles q{0.4, -1.2, 1.0, -0.3, 0.9, 0.2};
  const RobotModel model = robot_capsules(ur5, q, 0.0, BaseFrame::base);
  EXPECT_LT(first_of(model, 0).a.norm(), 1e-6F);  // on the mounting face, at the base origin
  const Eigen::Vector3f flange = forward_kinematics(ur5, q).T_base_link[6].translation().cast<float>();
  EXPECT_LT((last_of(model, 6).b - flange).norm(), 1e-6F);
  // The upper arm runs beside the DH line by the shoulder offset, parallel to it: at q = 0
  // from (0, −0.13585, d1) to (a2, −0.13585, d1).
  const RobotModel zero = robot_capsules(ur5, JointAngles{}, 0.0, BaseFrame::base);
  EXPECT_LT((first_of(zero, 2).a - Eigen::Vector3f(0.0F, -0.13585F, 0.089159F)).norm(), 1e-6F);
  EXPECT_LT((first_of(zero, 2).b - Eigen::Vector3f(-0.425F, -0.13585F, 0.089159F)).norm(), 1e-6F);
}

TEST(RobotCapsules, RadiusIsLinkRadiusPlusPadding) {
  const RobotDescription& ur10e = builtin_robot(BuiltinArm::ur10e);
  const JointAngles q{0.1, -0.5, 0.5, 0.0, 1.0, 0.0};
  const RobotModel bare = robot_capsules(ur10e, q, 0.0, BaseFrame::base);
  const RobotModel padded = robot_capsules(ur10e, q, 0.05, BaseFrame::base);
  ASSERT_EQ(bare.capsules.size(), 8U);  // base, shoulder, upper arm, elbow + forearm, 3 wrists
  ASSERT_EQ(padded.capsules.size(), bare.capsules.size());
  size_t i = 0;
  for (int link = 0; link < kArmLinkCount; ++link) {
    for (const LinkCapsule& described : ur10e.links[static_cast<size_t>(link)]) {
      EXPECT_EQ(bare.capsules[i].link, link);
      EXPECT_FLOAT_EQ(bare.capsules[i].radius_m, static_cast<float>(described.radius_m));
      EXPECT_FLOAT_EQ(padded.capsules[i].radius_m, static_cast<float>(described.radius_m + 0.05));
      EXPECT_EQ(padded.capsules[i].a, bare.capsules[i].a);  // padding never moves the segment
      ++i;
    }
  }
}

TEST(RobotCapsules, BaseFrameTurnsEveryCapsuleHalfAroundZ) {
  const JointAngles q{1.0, -0.7, 1.3, -2.0, 0.5, 3.0};
  const RobotModel in_base_link = robot_capsules(builtin_robot(BuiltinArm::ur5e), q, 0.02, BaseFrame::base_link);
  const RobotModel in_base = robot_capsules(builtin_robot(BuiltinArm::ur5e), q, 0.02, BaseFrame::base);
  ASSERT_EQ(in_base.capsules.size(), in_base_link.capsules.size());
  for (size_t i = 0; i < in_base.capsules.size(); ++i) {
    const Capsule& l = in_base_link.capsules[i];
    const Capsule& b = in_base.capsules[i];
    EXPECT_LT((b.a - Eigen::Vector3f(-l.a.x(), -l.a.y(), l.a.z())).norm(), 1e-6F);
    EXPECT_LT((b.b - Eigen::Vector3f(-l.b.x(), -l.b.y(), l.b.z())).norm(), 1e-6F);
    EXPECT_EQ(b.radius_m, l.radius_m);
    EXPECT_EQ(b.link, l.link);
  }
}

TEST(RobotCapsules, ToolHangsOffTheFlange) {
  RobotDescription arm = builtin_robot(BuiltinArm::ur5);
  // A 0.15 m gripper along the flange's z.
  arm.tool.push_back(LinkCapsule{Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.15), 0.04});
  // At q = 0 the flange's z is −y of base_link (see kinematics_test), so the tool tip is
  // 0.15 m further along −y: (a2 + a3, −(d4 + d6) − 0.15, d1 − d5).
  const RobotModel model = robot_capsules(arm, JointAngles{}, 0.01, BaseFrame::base);
  const Capsule& tool = model.capsules.back();
  EXPECT_EQ(tool.link, kToolLink);
  EXPECT_LT((tool.a - Eigen::Vector3f(-0.81725F, -0.19145F, -0.005491F)).norm(), 1e-6F);
  EXPECT_LT((tool.b - Eigen::Vector3f(-0.81725F, -0.34145F, -0.005491F)).norm(), 1e-6F);
  EXPECT_FLOAT_EQ(tool.radius_m, 0.05F);
  EXPECT_EQ(link_name(kToolLink), "tool");
}

TEST(RobotCapsules, ReusesTheCallersBuffer) {
  RobotModel model;
  robot_capsules(builtin_robot(BuiltinArm::ur5), JointAngles{}, 0.0, BaseFrame::base, model);
  const Capsule* storage = model.capsules.data();
  robot_capsules(builtin_robot(BuiltinArm::ur5), JointAngles{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}, 0.0, BaseFrame::base, model);
  EXPECT_EQ(model.capsules.data(), storage);  // same size: no reallocation
  EXPECT_EQ(model.capsules.size(), 8U);
}

// Signed distance from p to the union of the capsules (negative inside), in double.
double to_union_m(const Eigen::Vector3d& p, const RobotModel& model) {
  double best = 1e9;
  for (const Capsule& c : model.capsules) {
    const Eigen::Vector3d a = c.a.cast<double>();
    const Eigen::Vector3d ab = c.b.cast<double>() - a;
    const double t = ab.squaredNorm() > 0.0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    best = std::min(best, (p - (a + t * ab)).norm() - c.radius_m);
  }
  return best;
}

// Points on the surface of every rendered (visual) capsule: random points of its axis pushed
// out by its radius in a random direction. Each must lie inside the searched capsules with no
// padding at all: the collision model covers the real arm by itself, the padding is margin.
TEST(RobotRenderCapsules, VisualBodyLiesInsideTheUnpaddedCapsules) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (const BuiltinArm arm : kBuiltinArms) {
    const std::string& name = builtin_robot(arm).name;
    for (int pose = 0; pose < 20; ++pose) {
      const JointAngles q = random_joints(rng);
      const RobotModel visual = robot_render_capsules(builtin_robot(arm), q, BaseFrame::base);
      const RobotModel bare = robot_capsules(builtin_robot(arm), q, 0.0, BaseFrame::base);
      ASSERT_EQ(visual.capsules.size(), 8U) << name;
      for (const Capsule& c : visual.capsules) {
        for (int k = 0; k < 200; ++k) {
          const Eigen::Vector3d on_axis = c.a.cast<double>() + unit(rng) * (c.b - c.a).cast<double>();
          const Eigen::Vector3d direction = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
          const Eigen::Vector3d p = on_axis + c.radius_m * direction;
          EXPECT_LE(to_union_m(p, bare), 1e-6) << name << " link " << c.link << " at " << p.transpose();
        }
      }
    }
  }
}

TEST(RobotRenderCapsules, ALinkWithoutVisualShapesIsDrawnAsItsCapsules) {
  RobotDescription arm = builtin_robot(BuiltinArm::ur5);
  arm.visual[2].clear();  // the upper arm
  arm.tool.push_back(LinkCapsule{Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.15), 0.04});
  const JointAngles q{0.5, -1.0, 1.5, -0.5, -1.0, 0.3};
  const RobotModel rendered = robot_render_capsules(arm, q, BaseFrame::base);
  const RobotModel searched = robot_capsules(arm, q, 0.03, BaseFrame::base);
  EXPECT_FLOAT_EQ(first_of(rendered, 2).radius_m, 0.06F);  // the upper arm capsule's own radius
  EXPECT_EQ(first_of(rendered, 2).a, first_of(searched, 2).a);
  EXPECT_FLOAT_EQ(first_of(rendered, 1).radius_m, 0.06F);  // shoulder: its visual housing (capsule 0.065)
  EXPECT_FLOAT_EQ(last_of(rendered, kToolLink).radius_m, 0.04F);  // the tool, unpadded
}

TEST(RobotPoints, AreZeroLengthCapsulesWithThePaddingAsRadius) {
  const RobotModel model = robot_points({Eigen::Vector3f(1, 2, 3), Eigen::Vector3f(-1, 0, 0.5)}, 0.1);
  ASSERT_EQ(model.capsules.size(), 2U);
  EXPECT_EQ(model.capsules[1].a, Eigen::Vector3f(-1, 0, 0.5));
  EXPECT_EQ(model.capsules[1].b, Eigen::Vector3f(-1, 0, 0.5));
  EXPECT_FLOAT_EQ(model.capsules[1].radius_m, 0.1F);
  EXPECT_EQ(model.capsules[1].link, 1);
}

}  // namespace
}  // namespace hrcsense
