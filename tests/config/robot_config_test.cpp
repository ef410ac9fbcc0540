// SPDX-License-Identifier: Apache-2.0
// Tests of the robot keys (robot.model, robot.description, robot.joints_rad, robot.padding_m,
// robot.base_frame) and of robot description files.
#include "config_test_util.hpp"

#include <gtest/gtest.h>

#include "common/assembly.hpp"
#include "hrcsense/camera.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

const std::string kZeroPose = "robot.joints_rad=[0, 0, 0, 0, 0, 0]";

std::string robots_dir() { return std::string(HRCSENSE_SOURCE_DIR) + "/config/robots/"; }

// A small custom arm: a 1 m vertical post (link 0) and a 0.5 m arm along x of frame 1 that
// joint 1 turns; the other joints carry nothing. DH: d1 = 1, all else 0.
const char* const kPostArm = R"(name: post
dh:
  - {d_m: 1, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
joint_limits_deg: [[-90, 90], [-360, 360], [-360, 360], [-360, 360], [-360, 360], [-360, 360]]
padding_m: 0.02
links:
  base: [{a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: 0.1}]
  shoulder: [{a_m: [0, 0, 0], b_m: [0.5, 0, 0], radius_m: 0.05}]
)";

TEST(RobotConfig, Ur5CapsulesFollowTheJointsAndTheFrame) {
  const Config c = load_config("", {"robot.model=ur5", kZeroPose});
  ASSERT_TRUE(c.pipeline.robot.arm.has_value());
  EXPECT_EQ(c.pipeline.robot.arm->name, "ur5");
  ASSERT_EQ(fixed_robot_model(c).capsules.size(), 8U);
  // Default frame `base` (UR's DH frame 0, the pendant's): the flange (end of wrist 3) at
  // (a2 + a3, −(d4 + d6), d1 − d5) = (−0.81725, −0.19145, −0.005491).
  const Capsule wrist_3 = fixed_robot_model(c).capsules.back();
  EXPECT_EQ(wrist_3.link, 6);
  EXPECT_LT((wrist_3.b - Eigen::Vector3f(-0.81725F, -0.19145F, -0.005491F)).norm(), 1e-6F);
  EXPECT_FLOAT_EQ(wrist_3.radius_m, 0.045F);  // the built-in's wrist radius, no padding by default

  const Config link = load_config("", {"robot.model=ur5", kZeroPose, "robot.base_frame=base_link",
                                       "robot.padding_m=0.05"});
  EXPECT_EQ(link.pipeline.robot.base_frame, BaseFrame::base_link);
  const Capsule flange = fixed_robot_model(link).capsules.back();
  EXPECT_LT((flange.b - Eigen::Vector3f(0.81725F, 0.19145F, -0.005491F)).norm(), 1e-6F);  // x, y negated
  EXPECT_FLOAT_EQ(flange.radius_m, 0.095F);
  EXPECT_DOUBLE_EQ(link.pipeline.robot.padding_m, 0.05);

  // Joint 1 at +90° turns the whole arm about z: in base, Rz(90°)(−0.81725, −0.19145) = (0.19145, −0.81725).
  const Config turned = load_config("", {"robot.model=ur5", "robot.joints_rad=[1.5707963267948966, 0, 0, 0, 0, 0]"});
  EXPECT_LT((fixed_robot_model(turned).capsules.back().b - Eigen::Vector3f(0.19145F, -0.81725F, -0.005491F)).norm(), 1e-6F);
}

TEST(RobotConfig, EveryBuiltinArmLoads) {
  for (const std::string model : {"ur5", "ur5e", "ur10e"}) {
    const Config c = load_config("", {"robot.model=" + model, kZeroPose});
    EXPECT_EQ(fixed_robot_model(c).capsules.size(), 8U) << model;
    EXPECT_EQ(c.pipeline.robot.arm->name, model);
  }
}

TEST(RobotConfig, PointsModelIsTheThesisPoint) {
  const Config c = load_config("", {});
  EXPECT_EQ(c.robot_model, RobotModelType::points);
  EXPECT_FALSE(c.pipeline.robot.arm.has_value());
  ASSERT_EQ(fixed_robot_model(c).capsules.size(), 1U);
  EXPECT_EQ(fixed_robot_model(c).capsules[0].a, Eigen::Vector3f(-0.5F, -0.5F, 0.5F));
  EXPECT_EQ(fixed_robot_model(c).capsules[0].radius_m, 0.0F);
}

void expect_same_capsules(const std::vector<LinkCapsule>& file, const std::vector<LinkCapsule>& builtin,
                          const std::string& name) {
  ASSERT_EQ(file.size(), builtin.size()) << name;
  for (size_t i = 0; i < file.size(); ++i) {
    EXPECT_LT((file[i].a_m - builtin[i].a_m).norm(), 1e-12) << name << "[" << i << "].a_m";
    EXPECT_LT((file[i].b_m - builtin[i].b_m).norm(), 1e-12) << name << "[" << i << "].b_m";
    EXPECT_NEAR(file[i].radius_m, builtin[i].radius_m, 1e-12) << name << "[" << i << "].radius_m";
  }
}

TEST(RobotConfig, ShippedDescriptionFilesEqualTheBuiltins) {
  for (const BuiltinArm arm : kBuiltinArms) {
    const RobotDescription& builtin = builtin_robot(arm);
    const std::string path = robots_dir() + builtin.name + ".yaml";
    const RobotDescription file = load_robot_description(path);
    EXPECT_EQ(file.name, builtin.name) << path;
    EXPECT_DOUBLE_EQ(file.padding_m, builtin.padding_m) << path;
    for (size_t j = 0; j < kJointCount; ++j) {
      EXPECT_NEAR(file.dh[j].d_m, builtin.dh[j].d_m, 1e-12) << path << " dh[" << j << "]";
      EXPECT_NEAR(file.dh[j].a_m, builtin.dh[j].a_m, 1e-12) << path << " dh[" << j << "]";
      EXPECT_NEAR(file.dh[j].alpha_rad, builtin.dh[j].alpha_rad, 1e-12) << path << " dh[" << j << "]";
      EXPECT_NEAR(file.limits[j].min_rad, builtin.limits[j].min_rad, 1e-12) << path;
      EXPECT_NEAR(file.limits[j].max_rad, builtin.limits[j].max_rad, 1e-12) << path;
    }
    for (size_t link = 0; link < kArmLinkCount; ++link) {
      const std::string label = path + " " + link_name(static_cast<int>(link));
      expect_same_capsules(file.links[link], builtin.links[link], label);
      expect_same_capsules(file.visual[link], builtin.visual[link], label + " (visual)");
    }
    EXPECT_TRUE(file.tool.empty());
  }
}

TEST(RobotConfig, ToolKeyPutsAGripperOnABuiltinArm) {
  // A 15 cm gripper of radius 4 cm: at q = 0 the flange's z points along −y of base from the
  // flange at (a2 + a3, −(d4 + d6), d1 − d5), so the tool ends 0.15 m further along −y.
  const Config c = load_config("", {"robot.model=ur5", kZeroPose,
                                    "robot.tool=[{a_m: [0, 0, 0], b_m: [0, 0, 0.15], radius_m: 0.04}]"});
  ASSERT_EQ(fixed_robot_model(c).capsules.size(), 9U);
  const Capsule tool = fixed_robot_model(c).capsules.back();
  EXPECT_EQ(tool.link, kToolLink);
  EXPECT_LT((tool.a - Eigen::Vector3f(-0.81725F, -0.19145F, -0.005491F)).norm(), 1e-6F);
  EXPECT_LT((tool.b - Eigen::Vector3f(-0.81725F, -0.34145F, -0.005491F)).norm(), 1e-6F);
  EXPECT_FLOAT_EQ(tool.radius_m, 0.04F);
  EXPECT_EQ(robot_scene_object(c)->shapes.size(), 9U);  // the tool is rendered too
  expect_config_error("", {"robot.model=ur5", kZeroPose, "robot.tool=[{a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: -1}]"},
                      {"'robot.tool[0].radius_m'", ">= 0"});
  expect_config_error("", {"robot.tool=[]"}, {"'robot.tool'", "only read with an arm"});
}

TEST(RobotConfig, CustomArmFromAFileOrInline) {
  TempDir dir;
  const std::string arm = dir.write("post.yaml", kPostArm);
  // Joint 1 at 90°: the shoulder capsule turns from +x to +y of the DH frame 0, which is `base`:
  // it runs from (0, 0, 1) to (0, 0.5, 1). The arm's own padding (0.02) is the default.
  const Config c = load_config("", {"robot.model=custom", "robot.description=" + arm,
                                    "robot.joints_rad=[1.5707963267948966, 0, 0, 0, 0, 0]"});
  ASSERT_EQ(fixed_robot_model(c).capsules.size(), 2U);
  EXPECT_EQ(c.pipeline.robot.arm->name, "post");
  const Capsule shoulder = fixed_robot_model(c).capsules[1];
  EXPECT_EQ(shoulder.link, 1);
  EXPECT_LT((shoulder.a - Eigen::Vector3f(0, 0, 1)).norm(), 1e-6F);
  EXPECT_LT((shoulder.b - Eigen::Vector3f(0, 0.5F, 1)).norm(), 1e-6F);
  EXPECT_FLOAT_EQ(shoulder.radius_m, 0.07F);
  EXPECT_FLOAT_EQ(fixed_robot_model(c).capsules[0].radius_m, 0.12F);
  // robot.padding_m replaces the arm's own padding.
  const Config padded = load_config("", {"robot.model=custom", "robot.description=" + arm, kZeroPose,
                                         "robot.padding_m=0"});
  EXPECT_FLOAT_EQ(fixed_robot_model(padded).capsules[1].radius_m, 0.05F);

  // The shipped UR5 file gives the built-in's capsules.
  const Config from_file = load_config("", {"robot.model=custom", "robot.description=" + robots_dir() + "ur5.yaml",
                                            "robot.joints_rad=[0.3, -1, 1, 0.2, 0.4, 0.5]"});
  const Config builtin = load_config("", {"robot.model=ur5", "robot.joints_rad=[0.3, -1, 1, 0.2, 0.4, 0.5]"});
  ASSERT_EQ(fixed_robot_model(from_file).capsules.size(), fixed_robot_model(builtin).capsules.size());
  for (size_t i = 0; i < fixed_robot_model(builtin).capsules.size(); ++i) {
    EXPECT_LT((fixed_robot_model(from_file).capsules[i].a - fixed_robot_model(builtin).capsules[i].a).norm(), 1e-6F);
    EXPECT_LT((fixed_robot_model(from_file).capsules[i].b - fixed_robot_model(builtin).capsules[i].b).norm(), 1e-6F);
  }

  // Inline in the configuration, the same arm.
  const std::string config = dir.write("cell.yaml", std::string("robot:\n  model: custom\n  joints_rad: [0, 0, 0, 0, 0, 0]\n"
                                                                "  description:\n") +
                                                        [] {
                                                          std::string indented;
                                                          for (const char* p = kPostArm; *p != '\0'; ++p) {
                                                            if (p == kPostArm || p[-1] == '\n') indented += "    ";
                                                            indented += *p;
                                                          }
                                                          return indented;
                                                        }());
  const Config inline_arm = load_config(config, {});
  ASSERT_EQ(fixed_robot_model(inline_arm).capsules.size(), 2U);
  EXPECT_FLOAT_EQ(fixed_robot_model(inline_arm).capsules[0].radius_m, 0.12F);
}

TEST(RobotConfig, HashFollowsTheArmNotTheFileName) {
  TempDir dir;
  const std::string a = dir.write("a.yaml", kPostArm);
  const std::string b = dir.write("b.yaml", std::string(kPostArm) + "# a comment changes nothing\n");
  std::string longer = kPostArm;
  longer.replace(longer.find("[0.5, 0, 0]"), 11, "[0.6, 0, 0]");
  const std::string c = dir.write("c.yaml", longer);
  const auto hash = [&](const std::string& file) {
    return config_hash(load_config("", {"robot.model=custom", "robot.description=" + file, kZeroPose}));
  };
  EXPECT_EQ(hash(a), hash(b));
  EXPECT_NE(hash(a), hash(c));
  // The canonical configuration holds the arm inline and reads back to the same effect.
  const Config original = load_config("", {"robot.model=custom", "robot.description=" + a, kZeroPose});
  const std::string again = dir.write("canonical.yaml", original.canonical_yaml);
  const Config reread = load_config(again, {});
  EXPECT_EQ(config_hash(reread), config_hash(original));
  ASSERT_EQ(fixed_robot_model(reread).capsules.size(), fixed_robot_model(original).capsules.size());
  EXPECT_EQ(fixed_robot_model(reread).capsules[1].b, fixed_robot_model(original).capsules[1].b);
}

// Distance from p to the segment ab (double precision, independent of the proximity code).
double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

TEST(RobotSceneObject, IsTheArmsVisualBodyWithoutPadding) {
  EXPECT_FALSE(robot_scene_object(load_config("", {})).has_value());  // points: nothing to render
  const Config c = load_config("", {"robot.model=ur5", "robot.joints_rad=[0.2, -1.2, 1.1, -0.4, 0.6, 0]",
                                    "robot.padding_m=0.04"});
  const std::optional<SceneObject> arm = robot_scene_object(c);
  ASSERT_TRUE(arm.has_value());
  EXPECT_TRUE(arm->is_static);  // learnt as background
  // The UR5's visual radii of docs/ROBOT.md (base, shoulder, upper arm, elbow, forearm, wrists),
  // not the searched capsules' (collision radius + 0.04 m padding).
  const std::vector<float> expected_radii_m{0.0745F, 0.06F, 0.05F, 0.055F, 0.038F, 0.04F, 0.04F, 0.04F};
  ASSERT_EQ(arm->shapes.size(), expected_radii_m.size());
  for (size_t i = 0; i < arm->shapes.size(); ++i) {
    EXPECT_EQ(arm->shapes[i].type, Shape::Type::capsule);
    EXPECT_FLOAT_EQ(arm->shapes[i].radius_m, expected_radii_m[i]) << i;
    EXPECT_LT(arm->shapes[i].radius_m, fixed_robot_model(c).capsules[i].radius_m - 0.04F) << i;
  }
}

// Renders the configured arm alone (noise-free) and checks every pixel that hit something:
// it lies on the rendered surface (the union of the visual capsules) and inside the searched
// capsules without their padding. Counts the pixels per link (the nearest capsule's link).
void expect_rendered_inside(const Config& c, double padding_m, std::vector<int>& seen_per_link) {
  Simulator sim = make_simulator(c);
  sim.scene.objects.clear();
  sim.scene.objects.push_back(*robot_scene_object(c));
  Frame frame;
  sim.render(0, frame);
  ASSERT_TRUE(frame.truth.has_value());
  const RobotModel rendered =
      robot_render_capsules(*c.pipeline.robot.arm, c.robot_state.joints_rad, c.pipeline.robot.base_frame);
  size_t seen = 0;
  for (int v = 0; v < frame.intrinsics.height; ++v) {
    for (int u = 0; u < frame.intrinsics.width; ++u) {
      const float z_m = frame.truth->depth_m[static_cast<size_t>(v) * frame.intrinsics.width + u];
      if (z_m <= 0.0F) continue;
      const std::optional<Eigen::Vector3f> p_camera =
          deproject(frame.intrinsics, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), z_m);
      ASSERT_TRUE(p_camera.has_value());
      const Eigen::Vector3d p_base = c.pipeline.T_base_camera * p_camera->cast<double>();
      double to_rendered_m = 1e9;  // signed distance to the union of the rendered (visual) capsules
      int link = -1;
      for (const Capsule& capsule : rendered.capsules) {
        const double to_capsule_m =
            segment_distance(p_base, capsule.a.cast<double>(), capsule.b.cast<double>()) - capsule.radius_m;
        if (to_capsule_m < to_rendered_m) {
          to_rendered_m = to_capsule_m;
          link = capsule.link;
        }
      }
      double to_bare_m = 1e9;  // signed distance to the union of the searched capsules without padding
      for (const Capsule& capsule : fixed_robot_model(c).capsules) {
        const double axis_m = segment_distance(p_base, capsule.a.cast<double>(), capsule.b.cast<double>());
        to_bare_m = std::min(to_bare_m, axis_m - (capsule.radius_m - padding_m));
      }
      EXPECT_LT(std::abs(to_rendered_m), 1e-3) << "pixel " << u << "," << v << " at " << p_base.transpose();
      // Inside the collision capsules even before the padding: the padding is all margin.
      EXPECT_LT(to_bare_m, 0.0) << "pixel " << u << "," << v << " at " << p_base.transpose();
      ++seen;
      ++seen_per_link[static_cast<size_t>(link)];
    }
  }
  EXPECT_GT(seen, 1000U);  // the arm is in view
}

TEST(RobotSceneObject, RenderedArmLiesInsideTheUnpaddedSearchedCapsules) {
  // A UR5 lying along +x of `base` (q = 0 but wrist 2 at 90°, so wrist 3 points along +x),
  // seen from two cameras 1.4-1.5 m away so that every moving link shows somewhere.
  const std::vector<std::string> arm{"robot.model=ur5", "robot.joints_rad=[0, 0, 0, 0, 1.5707963267948966, 0]",
                                     "robot.padding_m=0.01", "sim.width=424", "sim.height=240",
                                     "sim.noise=false", "sim.frames=1"};
  std::vector<int> seen_per_link(kArmLinkCount, 0);
  // In front, looking along +y: camera x = base x, camera y (down) = −z: Rx(−90°).
  std::vector<std::string> side = arm;
  side.push_back("camera.T_base_camera.translation_m=[0.4, -1.5, 0.1]");
  side.push_back("camera.T_base_camera.rotation_rpy_deg=[-90, 0, 0]");
  expect_rendered_inside(load_config("", side), 0.01, seen_per_link);
  // Above, looking down: camera x = base x, camera y = −y, z = −z: Rx(180°).
  std::vector<std::string> top = arm;
  top.push_back("camera.T_base_camera.translation_m=[0.4, 0.1, 1.5]");
  top.push_back("camera.T_base_camera.rotation_rpy_deg=[180, 0, 0]");
  expect_rendered_inside(load_config("", top), 0.01, seen_per_link);
  for (int link = 0; link < kArmLinkCount; ++link) {
    EXPECT_GT(seen_per_link[static_cast<size_t>(link)], 0) << link_name(link);
  }
}

TEST(RobotConfigErrors, KeysAndJointsAreNamed) {
  expect_config_error("", {"robot.model=ur5"}, {"'robot.joints_rad'", "required for robot.model ur5"});
  expect_config_error("", {"robot.model=ur5e", "robot.joints_rad=[0, 0, 7, 0, 0, 0]"},
                      {"'robot.joints_rad'", "joint 3 (elbow)", "outside its limits"});
  expect_config_error("", {"robot.model=ur10e", "robot.joints_rad=[0, 0, 0, 0, 0, -6.5]"},
                      {"'robot.joints_rad'", "joint 6 (wrist_3)"});
  expect_config_error("", {"robot.model=ur5", "robot.joints_rad=[0, 0, 0]"}, {"'robot.joints_rad'", "6 numbers"});
  expect_config_error("", {"robot.model=ur5", kZeroPose, "robot.padding_m=-1"}, {"'robot.padding_m'", ">= 0"});
  expect_config_error("", {"robot.model=ur3"}, {"'robot.model'", "points, ur5, ur5e, ur10e, custom"});
  expect_config_error("", {"robot.model=custom", kZeroPose}, {"'robot.description'", "required for robot.model custom"});
  expect_config_error("", {"robot.model=ur5", kZeroPose, "robot.description=arm.yaml"},
                      {"'robot.description'", "only read with robot.model custom"});
  TempDir dir;
  const std::string cell = dir.write("cell.yaml", "robot: {model: custom, description: no/such/arm.yaml}\n");
  expect_config_error(cell, {}, {"cell.yaml", "'robot.description'", "no/such/arm.yaml", "cannot open"});
}

TEST(RobotConfigErrors, DescriptionFilesNameFileAndField) {
  TempDir dir;
  const auto check = [&](const std::string& from, const std::string& to, const std::vector<std::string>& needles) {
    std::string text = kPostArm;
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    const std::string arm = dir.write("bad_arm.yaml", text);
    std::vector<std::string> all = needles;
    all.push_back("bad_arm.yaml");
    expect_config_error("", {"robot.model=custom", "robot.description=" + arm, kZeroPose}, all);
  };
  check("radius_m: 0.05", "radius_m: -0.05", {"'links.shoulder[0].radius_m'", ">= 0"});
  check("radius_m: 0.05", "radius_m: thick", {"'links.shoulder[0].radius_m'", "number"});
  check("shoulder:", "elbow:", {"unknown key 'links.elbow'"});
  check("padding_m: 0.02", "padding: 0.02", {"unknown key 'padding'"});
  check("b_m: [0.5, 0, 0]", "b_m: [0.5, 0]", {"'links.shoulder[0].b_m'", "3 numbers"});
  check("  - {d_m: 1, a_m: 0, alpha_deg: 0}\n", "", {"'dh'", "6 rows"});
  check("{d_m: 1, a_m: 0, alpha_deg: 0}", "{d_m: 1, a_m: 0}", {"'dh[0].alpha_deg'", "required"});
  check("[[-90, 90],", "[[90, -90],", {"'joint_limits_deg[0]'", "min <= max"});
  check("links:\n  base: [{a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: 0.1}]\n  shoulder: [{a_m: [0, 0, 0], b_m: [0.5, 0, 0], radius_m: 0.05}]\n",
        "links: {}\n", {"'links'", "at least one capsule"});
  check("name: post", "name: [post", {"YAML syntax error"});
  // The joint limits come from the description: ±90° on joint 1 of the post arm.
  const std::string arm = dir.write("post.yaml", kPostArm);
  expect_config_error("", {"robot.model=custom", "robot.description=" + arm, "robot.joints_rad=[2, 0, 0, 0, 0, 0]"},
                      {"'robot.joints_rad'", "joint 1 (shoulder_pan)"});
  // Inline descriptions name the field below robot.description.
  expect_config_error("", {"robot.model=custom", kZeroPose, "robot.description={dh: [], links: {}}"},
                      {"'robot.description.dh'"});
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

TEST(RobotStateConfig, DefaultsAreTheDocumentedOnes) {
  const Config c = load_config("", {});
  EXPECT_EQ(c.robot_state.source, RobotStateOrigin::fixed);
  EXPECT_EQ(c.robot_state.port, 30004);
  EXPECT_DOUBLE_EQ(c.robot_state.frequency_hz, 125.0);
  EXPECT_EQ(c.robot_state.listen, "127.0.0.1:30010");
  EXPECT_DOUBLE_EQ(c.robot_state.history.max_age_s, 0.05);
  EXPECT_DOUBLE_EQ(c.robot_state.camera_latency_s, 0.0);
  EXPECT_DOUBLE_EQ(c.robot_state.sim_latency_s, 0.0);
  EXPECT_DOUBLE_EQ(c.robot_state.sim_jitter_s, 0.0);
}

TEST(RobotStateConfig, KeysAreReadAndChecked) {
  const Config c = load_config("", {"robot.state.source=rtde", "robot.state.host=192.168.1.10",
                                    "robot.state.frequency_hz=500", "robot.state.max_age_s=0.02",
                                    "robot.state.camera_latency_s=0.015"});
  EXPECT_EQ(c.robot_state.source, RobotStateOrigin::rtde);
  EXPECT_EQ(c.robot_state.host, "192.168.1.10");
  EXPECT_DOUBLE_EQ(c.robot_state.frequency_hz, 500.0);
  EXPECT_DOUBLE_EQ(c.robot_state.history.max_age_s, 0.02);
  EXPECT_DOUBLE_EQ(c.robot_state.camera_latency_s, 0.015);
  test::expect_config_error("", {"robot.state.source=rtde"}, {"'robot.state.host'", "required"});
  test::expect_config_error("", {"robot.state.source=ros"}, {"'robot.state.source'", "udp_json"});
  test::expect_config_error("", {"robot.state.frequency_hz=501"}, {"'robot.state.frequency_hz'"});
  test::expect_config_error("", {"robot.state.max_age_s=0"}, {"'robot.state.max_age_s'"});
  for (const char* listen : {"30010", "127.0.0.1", "127.0.0.1:", "127.0.0.1:70000", ":30010", "host:3x"}) {
    test::expect_config_error("", {std::string("robot.state.listen=") + listen}, {"'robot.state.listen'"});
  }
  test::expect_config_error("", {"robot.state.listen=localhost"}, {"'robot.state.listen'", "expected host:port"});
}

// An arm needs robot.joints_rad only with the fixed source: a live or simulated source brings
// the joints itself.
TEST(RobotStateConfig, JointsAreRequiredOnlyForTheFixedSource) {
  test::expect_config_error("", {"robot.model=ur5"}, {"'robot.joints_rad'", "robot.state.source fixed"});
  const Config live = load_config("", {"robot.model=ur5", "robot.state.source=recorded"});
  EXPECT_EQ(live.robot_state.source, RobotStateOrigin::recorded);
  // Recorded joint states come from a bag source: the assembly says so, naming the key.
  try {
    (void)make_robot_state_source(live);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()),
              "configuration: robot.state.source recorded: the joint states come from the recording (source.type bag)");
  }
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

const std::string kSimArm = "robot.model=ur5";
const std::string kTwoPoints =
    "robot.trajectory={interpolation: cubic, waypoints: [{t_s: 0, joints_rad: [0, -1, 1, 0, 0, 0]}, "
    "{t_s: 2, joints_rad: [1, -1, 1, 0, 0, 0]}]}";

TEST(RobotTrajectoryConfig, ReadsWaypointsAndAllowsTheSimSourceWithoutJoints) {
  const Config c = load_config("", {kSimArm, "robot.state.source=sim", kTwoPoints});
  ASSERT_TRUE(c.robot_state.trajectory.has_value());
  const RobotTrajectory& t = *c.robot_state.trajectory;
  EXPECT_EQ(t.interpolation, TrajectoryInterpolation::cubic);
  EXPECT_FALSE(t.loop);
  ASSERT_EQ(t.waypoints.size(), 2u);
  EXPECT_EQ(t.waypoints[1].t_s, 2.0);
  EXPECT_EQ(t.waypoints[1].q_rad[0], 1.0);
  EXPECT_EQ(t.waypoints[0].q_rad[1], -1.0);
  EXPECT_NE(c.canonical_yaml.find("trajectory"), std::string::npos);
}

TEST(RobotTrajectoryConfig, NoTrajectoryNoKeyInTheCanonicalConfig) {
  const Config c = load_config("", {kSimArm, kZeroPose});
  EXPECT_FALSE(c.robot_state.trajectory.has_value());
  EXPECT_EQ(c.canonical_yaml.find("trajectory"), std::string::npos);
}

TEST(RobotTrajectoryConfig, ErrorsNameTheKeyAndTheWaypoint) {
  expect_config_error("", {kSimArm, "robot.state.source=sim"}, {"robot.trajectory", "required", "sim"});
  expect_config_error("", {"robot.state.source=sim"}, {"robot.state.source", "arm"});
  expect_config_error("", {kTwoPoints}, {"robot.trajectory", "only read with an arm"});
  expect_config_error("", {kSimArm, kZeroPose, "robot.trajectory={waypoints: [{t_s: 0, joints_rad: [0, 0, 0, 0, 0, 0]}]}"},
                      {"robot.trajectory.waypoints", "at least 2"});
  expect_config_error("", {kSimArm, kZeroPose,
                           "robot.trajectory={waypoints: [{t_s: 1, joints_rad: [0, 0, 0, 0, 0, 0]}, "
                           "{t_s: 1, joints_rad: [0, 0, 0, 0, 0, 0]}]}"},
                      {"robot.trajectory.waypoints[1].t_s", "strictly increasing"});
  expect_config_error("", {kSimArm, kZeroPose,
                           "robot.trajectory={waypoints: [{t_s: 0, joints_rad: [0, 0, 0, 0, 0, 0]}, "
                           "{t_s: 1, joints_rad: [0, 0, 7, 0, 0, 0]}]}"},
                      {"robot.trajectory.waypoints[1].joints_rad", "joint 3 (elbow)", "outside its limits"});
  expect_config_error("", {kSimArm, kZeroPose,
                           "robot.trajectory={waypoints: [{t_s: 0, joints_rad: [0, 0, 0, 0, 0, 0]}, "
                           "{t_s: 1, joints_rad: [0, 0, 0, 0, 0]}]}"},
                      {"robot.trajectory.waypoints[1].joints_rad", "6 joint angles"});
  expect_config_error("", {kSimArm, kZeroPose,
                           "robot.trajectory={loop: true, waypoints: [{t_s: 0, joints_rad: [0, 0, 0, 0, 0, 0]}, "
                           "{t_s: 1, joints_rad: [1, 0, 0, 0, 0, 0]}]}"},
                      {"robot.trajectory.waypoints[1].joints_rad", "closed cycle"});
  expect_config_error("", {kSimArm, kZeroPose, "robot.trajectory={interpolation: spline, waypoints: []}"},
                      {"robot.trajectory.interpolation", "linear or cubic"});
  expect_config_error("", {kSimArm, kZeroPose, "robot.trajectory={speed: 1, waypoints: []}"},
                      {"robot.trajectory", "speed"});
}

}  // namespace
}  // namespace hrcsense
