// SPDX-License-Identifier: Apache-2.0
// Calibration in a cell with several cameras (issue H2): the agreement of two cameras on the arm
// by hand on made-up surfaces, their views paired by the nearest arm pose, and the written-back
// entry read by load_config with every other byte kept. The simulated cell's cameras: tests/acceptance_long/multi_camera_calibration_long_test.cpp.

#include "hrcsense/calibration.hpp"
#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

namespace hrcsense::test {
namespace {

constexpr double kMultiPi = 3.14159265358979323846;

// Points on the surface of capsule `c` (lateral surface between its ends, and both end caps),
// seen from the half-space n · `towards` ≥ 0, moved by `shift`.
void multi_capsule_points(const Capsule& c, const Eigen::Vector3f& towards, const Eigen::Vector3f& shift,
                          std::vector<Eigen::Vector3f>& out) {
  const Eigen::Vector3f axis = (c.b - c.a).norm() > 0.0F ? Eigen::Vector3f((c.b - c.a).normalized()) : Eigen::Vector3f::UnitX();
  const Eigen::Vector3f u = axis.unitOrthogonal();
  const Eigen::Vector3f w = axis.cross(u);
  for (int i = 0; i < 36; ++i) {
    const float phi = static_cast<float>(2.0 * kMultiPi * i / 36.0);
    const Eigen::Vector3f radial = std::cos(phi) * u + std::sin(phi) * w;
    // The lateral surface at 5 places along the axis.
    for (int k = 0; k <= 4; ++k) {
      const Eigen::Vector3f n = radial;
      if (n.dot(towards) < 0.0F) continue;
      out.push_back(c.a + (c.b - c.a) * (static_cast<float>(k) / 4.0F) + c.radius_m * n + shift);
    }
    // The caps: a few latitudes of each hemisphere.
    for (int lat = 1; lat <= 3; ++lat) {
      const float theta = static_cast<float>(kMultiPi / 2.0 * lat / 4.0);
      for (const float side : {-1.0F, 1.0F}) {
        const Eigen::Vector3f n = std::cos(theta) * radial + side * std::sin(theta) * axis;
        if (n.dot(towards) < 0.0F) continue;
        out.push_back((side < 0.0F ? c.a : c.b) + c.radius_m * n + shift);
      }
    }
  }
}

TEST(CameraAgreement, TwoCamerasSeeingOneSurfaceShiftedByDeltaDisagreeByDelta) {
  // Link 2: a capsule along x; link 5: a sphere. Camera a sees them from above (+z) where they
  // are; camera b from the side (+y), everything moved by δ (its pose off by δ).
  const Capsule arm_capsule{Eigen::Vector3f(0.0F, 0.0F, 0.0F), Eigen::Vector3f(0.4F, 0.0F, 0.0F), 0.05F, 2};
  const Capsule sphere{Eigen::Vector3f(0.0F, 0.5F, 0.2F), Eigen::Vector3f(0.0F, 0.5F, 0.2F), 0.04F, 5};
  const Eigen::Vector3f delta(0.004F, -0.012F, 0.009F);  // |δ| = √241 mm = 15.52 mm
  ArmView a;
  a.q_rad = {0.1, -1.0, 1.2, 0.0, 0.5, 0.0};
  a.shapes_base = {arm_capsule, sphere};
  ArmView b = a;
  multi_capsule_points(arm_capsule, Eigen::Vector3f(0.0F, 0.3F, 1.0F), Eigen::Vector3f::Zero(), a.points_base);
  multi_capsule_points(sphere, Eigen::Vector3f(0.0F, 0.3F, 1.0F), Eigen::Vector3f::Zero(), a.points_base);
  multi_capsule_points(arm_capsule, Eigen::Vector3f(0.2F, 1.0F, 0.0F), delta, b.points_base);
  multi_capsule_points(sphere, Eigen::Vector3f(0.2F, 1.0F, 0.0F), delta, b.points_base);
  // A view of another arm pose in a only (the arm's shapes 10 cm up, beyond the 4 cm a pair may
  // lie apart), its points 3 cm off those shapes: no view of b is near it, so it must not count.
  ArmView a_alone = a;
  a_alone.q_rad[1] += 0.2;
  for (Capsule& c : a_alone.shapes_base) {
    c.a.z() += 0.1F;
    c.b.z() += 0.1F;
  }
  for (Eigen::Vector3f& p : a_alone.points_base) p += Eigen::Vector3f(0.0F, 0.0F, 0.13F);

  AgreementParams params;
  params.min_link_points = 50;  // a hand-made link has some hundred points
  const CameraAgreement agreement = camera_agreement({a, a_alone}, {b}, params);
  EXPECT_EQ(agreement.views_a, 2);
  EXPECT_EQ(agreement.paired_views, 1);
  EXPECT_EQ(agreement.pair_travel_max_m, 0.0);
  ASSERT_EQ(agreement.links.size(), 2U);
  const double delta_m = std::sqrt(241.0) / 1000.0;
  for (const LinkAgreement& link : agreement.links) {
    SCOPED_TRACE(link.link);
    EXPECT_EQ(link.views, 1);
    EXPECT_EQ(link.constrained_axes, 3);
    EXPECT_LT(link.offset_a_base_m.norm(), 1e-6);
    EXPECT_LT((link.offset_b_base_m - delta.cast<double>()).norm(), 1e-5);
    EXPECT_NEAR(link.disagreement_m, delta_m, 1e-5);
  }
  EXPECT_EQ(agreement.links[0].link, 2);
  EXPECT_EQ(agreement.links[1].link, 5);
  EXPECT_EQ(agreement.all.points_a, agreement.links[0].points_a + agreement.links[1].points_a);
  EXPECT_NEAR(agreement.all.disagreement_m, delta_m, 1e-5);
  // The other way round the offsets swap.
  const CameraAgreement swapped = camera_agreement({b}, {a}, params);
  EXPECT_NEAR(swapped.all.disagreement_m, delta_m, 1e-5);
  EXPECT_LT((swapped.all.offset_a_base_m - delta.cast<double>()).norm(), 1e-5);

  // A link needs min_points of each camera: with more than b has on the sphere, only link 2.
  ArmView b_thin = b;  // every third of b's sphere points only
  b_thin.points_base.clear();
  size_t b_on_sphere = 0;
  for (const Eigen::Vector3f& p : b.points_base) {
    const bool on_sphere = (p - sphere.a).norm() < 0.1F;
    if (on_sphere && b_on_sphere++ % 3 != 0) continue;
    b_thin.points_base.push_back(p);
  }
  AgreementParams strict = params;
  strict.min_points = static_cast<int>((b_on_sphere + 2) / 3) + 1;
  ASSERT_GT(agreement.links[0].points_b, static_cast<size_t>(strict.min_points));
  ASSERT_GT(agreement.links[0].points_a, static_cast<size_t>(strict.min_points));
  const CameraAgreement fewer = camera_agreement({a}, {b_thin}, strict);
  ASSERT_EQ(fewer.links.size(), 1U);
  EXPECT_EQ(fewer.links[0].link, 2);
  // Points beyond the gate are not the arm: a gate below |δ|'s normal parts drops b's points.
  AgreementParams narrow = params;
  narrow.gate_m = 0.001F;
  EXPECT_TRUE(camera_agreement({a}, {b}, narrow).links.empty());
}

TEST(CameraAgreement, ALinkSeenAlongOneDirectionOnlyLeavesTheOthersUnconstrained) {
  // Points only on the top of a long capsule (normals all +z): only z is constrained; b's shift
  // along x and y cannot be seen and counts 0, its z part is the disagreement.
  const Capsule c{Eigen::Vector3f(0.0F, 0.0F, 0.0F), Eigen::Vector3f(1.0F, 0.0F, 0.0F), 0.05F, 3};
  ArmView a;
  a.shapes_base = {c};
  ArmView b = a;
  for (int k = 0; k <= 20; ++k) {
    const Eigen::Vector3f top(0.05F * static_cast<float>(k) - 0.0F, 0.0F, 0.05F);
    if (top.x() <= 0.0F || top.x() >= 1.0F) continue;
    a.points_base.push_back(top);
    b.points_base.push_back(top + Eigen::Vector3f(0.01F, 0.0F, 0.005F));
  }
  AgreementParams params;
  params.min_points = 5;
  params.min_link_points = 5;
  const CameraAgreement agreement = camera_agreement({a}, {b}, params);
  ASSERT_EQ(agreement.links.size(), 1U);
  EXPECT_EQ(agreement.links[0].constrained_axes, 1);
  EXPECT_NEAR(agreement.links[0].disagreement_m, 0.005, 1e-6);
}

// The arm of the next test at base angle θ (rad): link 2 a capsule from the base out to 0.5 m,
// link 5 a sphere 0.7 m out and 0.15 m up; both turn about z with θ.
std::vector<Capsule> multi_turning_arm(double theta_rad) {
  const Eigen::Vector3f radial(static_cast<float>(std::cos(theta_rad)), static_cast<float>(std::sin(theta_rad)), 0.0F);
  const Eigen::Vector3f sphere_centre = 0.7F * radial + Eigen::Vector3f(0.0F, 0.0F, 0.15F);
  return {Capsule{Eigen::Vector3f::Zero(), 0.5F * radial, 0.05F, 2}, Capsule{sphere_centre, sphere_centre, 0.04F, 5}};
}

// A view of that arm at θ seen from `towards`, the points moved by `shift` (the camera's pose error).
ArmView multi_turning_view(double theta_rad, const Eigen::Vector3f& towards, const Eigen::Vector3f& shift) {
  ArmView view;
  view.q_rad = {theta_rad, -1.0, 1.6, -2.17, -1.57, 0.0};
  view.shapes_base = multi_turning_arm(theta_rad);
  for (const Capsule& c : view.shapes_base) multi_capsule_points(c, towards, shift, view.points_base);
  return view;
}

TEST(CameraAgreement, CamerasAtOtherInstantsArePairedByTheNearestArmPoseEachViewOnce) {
  // Camera a sees the arm turning about its base every 0.06 rad (θ = 0, 0.06, ..., 0.54); camera
  // b at other instants, 0.02 rad later (θ = 0.02, 0.08, ..., 0.32), and once at θ = 2, far from
  // every view of a. No joint of a view of b equals one of a. b's pose is off by δ.
  const Eigen::Vector3f from_a(0.0F, 0.3F, 1.0F);
  const Eigen::Vector3f from_b(0.2F, 1.0F, 0.3F);
  const Eigen::Vector3f delta(-0.008F, 0.011F, 0.006F);  // |δ| = √221 mm = 14.87 mm
  std::vector<ArmView> a;
  for (int i = 0; i < 10; ++i) a.push_back(multi_turning_view(0.06 * i, from_a, Eigen::Vector3f::Zero()));
  std::vector<ArmView> b;
  for (int i = 0; i < 6; ++i) b.push_back(multi_turning_view(0.06 * i + 0.02, from_b, delta));
  b.push_back(multi_turning_view(2.0, from_b, delta));

  AgreementParams params;
  params.min_link_points = 50;
  const CameraAgreement agreement = camera_agreement(a, b, params);
  // Each view of b lies 0.02 rad from a view of a and 0.04 rad from the next: the nearer pairs,
  // the sphere's centre (0.7 m out, the farthest end of any shape) 2 · 0.7 m · sin(0.01) apart.
  const double pair_travel_m = 2.0 * 0.7 * std::sin(0.01);  // 14.0 mm
  EXPECT_EQ(agreement.views_a, 10);
  EXPECT_EQ(agreement.views_b, 7);
  EXPECT_EQ(agreement.paired_views, 6);
  EXPECT_NEAR(agreement.pair_travel_max_m, pair_travel_m, 2e-6);
  EXPECT_NEAR(agreement.pair_travel_median_m, pair_travel_m, 2e-6);
  EXPECT_NEAR(agreement.pair_joint_max_rad, 0.02, 1e-12);
  // Each camera's offset is to the arm's shapes at its own view's joints: a's are 0 and b's are δ
  // although no pair shows the same pose.
  ASSERT_EQ(agreement.links.size(), 2U);
  for (const LinkAgreement& link : agreement.links) {
    SCOPED_TRACE(link.link);
    EXPECT_EQ(link.views, 6);
    EXPECT_LT(link.offset_a_base_m.norm(), 1e-5);
    EXPECT_LT((link.offset_b_base_m - delta.cast<double>()).norm(), 1e-5);
  }
  EXPECT_EQ(agreement.all.constrained_axes, 3);
  EXPECT_NEAR(agreement.all.disagreement_m, std::sqrt(221.0) / 1000.0, 1e-5);

  // Below the pairs' 14 mm apart nothing pairs, and nothing is compared.
  AgreementParams tight = params;
  tight.pair_travel_m = 0.013;
  const CameraAgreement none = camera_agreement(a, b, tight);
  EXPECT_EQ(none.paired_views, 0);
  EXPECT_TRUE(none.links.empty());

  // b at twice a's rate (θ = 0, 0.03, ..., 0.57): its even views show a's poses exactly and pair
  // with them; its odd views, 0.03 rad from two views of a each, find both taken and stay out. A
  // view of a is never counted twice.
  std::vector<ArmView> twice;
  for (int k = 0; k < 20; ++k) twice.push_back(multi_turning_view(0.03 * k, from_b, delta));
  const CameraAgreement doubled = camera_agreement(a, twice, params);
  EXPECT_EQ(doubled.paired_views, 10);
  EXPECT_EQ(doubled.pair_travel_max_m, 0.0);
  ASSERT_EQ(doubled.links.size(), 2U);
  EXPECT_EQ(doubled.links[0].views, 10);
  // The same pairs whichever camera comes first.
  EXPECT_EQ(camera_agreement(twice, a, params).paired_views, 10);

  // A tie goes to the earlier view: b saw the arm twice in the same pose (a sweep's next cycle),
  // the second time with its points another 3 cm up. a's one view, 0.02 rad away, pairs with the
  // first given, and that one's points are compared.
  const ArmView one = multi_turning_view(0.1, from_a, Eigen::Vector3f::Zero());
  const ArmView first = multi_turning_view(0.12, from_b, delta);
  const ArmView again = multi_turning_view(0.12, from_b, delta + Eigen::Vector3f(0.0F, 0.0F, 0.03F));
  params.min_link_points = 20;
  const CameraAgreement tie = camera_agreement({one}, {first, again}, params);
  EXPECT_EQ(tie.paired_views, 1);
  EXPECT_NEAR(tie.all.disagreement_m, std::sqrt(221.0) / 1000.0, 1e-5);
  const CameraAgreement tie_swapped = camera_agreement({one}, {again, first}, params);
  EXPECT_EQ(tie_swapped.paired_views, 1);
  EXPECT_NEAR(tie_swapped.all.disagreement_m, std::sqrt(64.0 + 121.0 + 36.0 * 36.0) / 1000.0, 1e-5);  // δ + 30 mm up
}

// ---- Writing a calibrated pose back into the cell's file.

const char* const kMultiCellText =
    "# A two-camera cell (a comment kept)\n"
    "source: {type: sim, seed: 1}\n"
    "camera:\n"
    "  T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-133.3, 0, 90]}\n"
    "cameras:\n"
    "  - name: front   # the door side\n"
    "    T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-133.3, 0, 90]}\n"
    "    source: {seed: 1}\n"
    "  - name: left\n"
    "    T_base_camera:\n"
    "      translation_m: [ 0.3, 2.2,\n"
    "                       1.5 ]   # measured by tape\n"
    "      rotation_rpy_deg: [-124.3, 0, 180]\n"
    "    source: {seed: 2}\n"
    "robot: {model: ur5, joints_rad: [0, -1.5, 1.4, -1.7, -1.5708, 0]}\n";

std::string multi_write_temp(const std::string& name, const std::string& text) {
  const std::string path = std::string(::testing::TempDir()) + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(CalibrationWriteBack, TheEntrysPoseIsReplacedAndEveryOtherByteKept) {
  Pose fitted = Pose::Identity();
  fitted.linear() = (Eigen::AngleAxisd(180.4 * kMultiPi / 180.0, Eigen::Vector3d::UnitZ()) *
                     Eigen::AngleAxisd(0.3 * kMultiPi / 180.0, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(-124.9 * kMultiPi / 180.0, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
  fitted.translation() = Eigen::Vector3d(0.3123456, 2.1876543, 1.5012346);
  const std::string text = kMultiCellText;
  const std::string edited = with_camera_pose_text(text, "left", fitted, "cell.yaml");
  // Only the two lists of `left` changed: the text up to the first and after the second is the
  // same, and so is what lies between them.
  const std::string t_old = "[ 0.3, 2.2,\n                       1.5 ]";
  const std::string r_old = "[-124.3, 0, 180]";
  const size_t t_at = text.find(t_old);
  const size_t r_at = text.find(r_old, t_at);
  ASSERT_NE(r_at, std::string::npos);
  const std::string t_new = "[0.312346, 2.187654, 1.501235]";
  // Rz(180.4°) = Rz(−179.6°): read back as yaw −179.6.
  const std::string r_new = "[-124.90000, 0.30000, -179.60000]";
  const std::string expected = text.substr(0, t_at) + t_new + text.substr(t_at + t_old.size(), r_at - t_at - t_old.size()) +
                               r_new + text.substr(r_at + r_old.size());
  EXPECT_EQ(edited, expected);

  // load_config reads the fitted pose for `left` (to the written digits) and `front` as it was.
  const std::string path = multi_write_temp("multi_write_back.yaml", edited);
  const Config config = load_config(path, {});
  ASSERT_EQ(config.cameras.size(), 2U);
  EXPECT_EQ(config.cameras[1].name, "left");
  EXPECT_LT(translation_between_m(config.cameras[1].T_base_camera, fitted), 1e-6);
  EXPECT_LT(rotation_between_deg(config.cameras[1].T_base_camera, fitted), 2e-5);
  const Config before = load_config(multi_write_temp("multi_write_before.yaml", text), {});
  EXPECT_TRUE(config.cameras[0].T_base_camera.isApprox(before.cameras[0].T_base_camera, 1e-12));
  EXPECT_TRUE(load_config(path, {}, "left").pipeline.T_base_camera.isApprox(config.cameras[1].T_base_camera, 1e-12));

  // The first entry's flow map on one line: the same.
  const std::string front = with_camera_pose_text(text, "front", fitted, "cell.yaml");
  const Config front_config = load_config(multi_write_temp("multi_write_front.yaml", front), {});
  EXPECT_LT(translation_between_m(front_config.cameras[0].T_base_camera, fitted), 1e-6);
  EXPECT_TRUE(front_config.pipeline.T_base_camera.isApprox(before.pipeline.T_base_camera, 1e-12));  // top level kept
  EXPECT_NE(front.find("# the door side"), std::string::npos);
}

TEST(CalibrationWriteBack, FormsItCannotEditAreRefusedNamingTheKey) {
  const auto message = [](const std::string& text, const std::string& camera) {
    try {
      with_camera_pose_text(text, camera, Pose::Identity(), "cell.yaml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(kMultiCellText, "back").find("no camera named 'back'"), std::string::npos);
  EXPECT_NE(message("camera: {}\n", "left").find("no cameras: list"), std::string::npos);
  // A block list.
  const std::string block = "cameras:\n  - name: a\n    T_base_camera:\n      translation_m:\n        - 1\n        - 2\n"
                            "        - 3\n      rotation_rpy_deg: [0, 0, 0]\n";
  EXPECT_NE(message(block, "a").find("'cameras[0].T_base_camera.translation_m'"), std::string::npos) << message(block, "a");
  // An alias of a list written elsewhere (editing it would change the other use too).
  const std::string alias = "camera: {T_base_camera: {translation_m: &t [1, 2, 3], rotation_rpy_deg: [0, 0, 0]}}\n"
                            "cameras:\n  - name: a\n    T_base_camera: {translation_m: *t, rotation_rpy_deg: [0, 0, 0]}\n";
  EXPECT_NE(message(alias, "a").find("alias"), std::string::npos) << message(alias, "a");
  // A comment inside the list.
  const std::string commented = "cameras:\n  - name: a\n    T_base_camera:\n      translation_m: [1, # x\n 2, 3]\n"
                                "      rotation_rpy_deg: [0, 0, 0]\n";
  EXPECT_NE(message(commented, "a").find("holds '#'"), std::string::npos) << message(commented, "a");
  EXPECT_NE(message("cameras: [\n", "a").find("not YAML"), std::string::npos);
}

}  // namespace
}  // namespace hrcsense::test
