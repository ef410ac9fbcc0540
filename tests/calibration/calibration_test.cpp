// SPDX-License-Identifier: Apache-2.0
// The camera calibration's parts (issue H3, part 1): the signed distance to the arm's shapes by
// hand, the farthest-depth background and keyframes on synthetic images, the candidates'
// deprojection by the pinhole formula, and whole fits on noise-free simulated sweeps, judged by
// the simulator's true camera pose.

#include "../support/sanitized.hpp"
#include "../support/scenes.hpp"
#include "common/assembly.hpp"
#include "hrcsense/calibration.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

// A depth image of one value everywhere (mm units).
DepthImage calib_flat_depth(int width, int height, uint16_t mm) {
  DepthImage depth;
  depth.resize(width, height);
  std::fill(depth.pixels.begin(), depth.pixels.end(), mm);
  return depth;
}

Intrinsics calib_small_intrinsics() {
  Intrinsics in;
  in.width = 80;
  in.height = 60;
  in.fx = 100.0F;
  in.fy = 100.0F;
  in.ppx = 40.0F;
  in.ppy = 30.0F;
  return in;
}

TEST(CalibrationGeometry, SignedDistanceToTheNearestShapeAndItsNormal) {
  const std::vector<Capsule> shapes = {
      Capsule{Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0), 0.1F, 2},
      Capsule{Eigen::Vector3f(0, 2, 0), Eigen::Vector3f(0, 2, 0), 0.5F, 3},  // a sphere
  };
  Eigen::Vector3f n;
  // Beside the segment: 0.3 from the axis, 0.2 outside the surface, normal along +y.
  EXPECT_NEAR(distance_to_shapes(shapes, Eigen::Vector3f(0.5F, 0.3F, 0.0F), n), 0.2F, 1e-6F);
  EXPECT_NEAR(n.y(), 1.0F, 1e-6F);
  // Beyond its end: 0.5 from b, 0.4 outside, normal along +x.
  EXPECT_NEAR(distance_to_shapes(shapes, Eigen::Vector3f(1.5F, 0.0F, 0.0F), n), 0.4F, 1e-6F);
  EXPECT_NEAR(n.x(), 1.0F, 1e-6F);
  // Inside: negative.
  EXPECT_NEAR(distance_to_shapes(shapes, Eigen::Vector3f(0.5F, 0.0F, 0.05F), n), -0.05F, 1e-6F);
  EXPECT_NEAR(n.z(), 1.0F, 1e-6F);
  // Nearer the sphere (|(0, 1.2, 0) − (0, 2, 0)| − 0.5 = 0.3) than the segment (1.2 − 0.1 = 1.1).
  EXPECT_NEAR(distance_to_shapes(shapes, Eigen::Vector3f(0.0F, 1.2F, 0.0F), n), 0.3F, 1e-6F);
  EXPECT_NEAR(n.y(), -1.0F, 1e-6F);
}

TEST(CalibrationSamples, FarthestMeanAndKeyframesFollowTheArmsMotion) {
  const Intrinsics in = calib_small_intrinsics();
  CalibrationParams params;
  params.grid_px = 4;
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  ArmSamples samples(params, in, ur5, BaseFrame::base);
  EXPECT_EQ(samples.grid_width(), 20);
  EXPECT_EQ(samples.grid_height(), 15);
  JointAngles q{0.0, -1.5, 1.4, -1.7, -1.5708, 0.0};
  EXPECT_TRUE(samples.add(0, calib_flat_depth(in.width, in.height, 2000), q));   // the first frame is one
  EXPECT_FALSE(samples.add(1, calib_flat_depth(in.width, in.height, 2500), q));  // held: none
  // The pan turned by 0.01 rad moves the flange (about 0.5 m out) by about 5 mm: still below 2 cm.
  q[0] += 0.01;
  EXPECT_FALSE(samples.add(2, calib_flat_depth(in.width, in.height, 1500), q));
  q[0] += 0.1;  // about 5 cm
  EXPECT_TRUE(samples.add(3, calib_flat_depth(in.width, in.height, 1800), q));
  EXPECT_EQ(samples.frames(), 4);
  ASSERT_EQ(samples.keyframes().size(), 2U);
  EXPECT_EQ(samples.keyframes()[1].frame_index, 3);
  for (const uint16_t d : samples.farthest()) ASSERT_EQ(d, 2500);
  // 2000 → 2500 mm is a change beyond the margin at every sample; nothing since.
  EXPECT_EQ(samples.take_background_changes(), static_cast<int64_t>(samples.farthest().size()));
  EXPECT_EQ(samples.take_background_changes(), 0);
  EXPECT_THROW(samples.add(4, calib_flat_depth(40, 30, 1000), q), std::invalid_argument);
}

TEST(CalibrationSamples, CandidatesAreTheSamplesStandingOffTheBackgroundAtTheirPinholePoints) {
  const Intrinsics in = calib_small_intrinsics();
  CalibrationParams params;
  params.grid_px = 4;
  params.keyframe_motion_m = 0.0;  // every frame a keyframe
  ArmSamples samples(params, in, builtin_robot(BuiltinArm::ur5), BaseFrame::base);
  const JointAngles q{};
  samples.add(0, calib_flat_depth(in.width, in.height, 2000), q);
  // Frame 1: a 1.5 m block over pixels u 20..39, v 10..29; elsewhere the 2 m wall.
  DepthImage depth = calib_flat_depth(in.width, in.height, 2000);
  for (int v = 10; v < 30; ++v) {
    for (int u = 20; u < 40; ++u) depth.pixels[static_cast<size_t>(v * in.width + u)] = 1500;
  }
  samples.add(1, depth, q);
  const std::vector<Eigen::Vector3f> points = arm_candidates(samples, samples.keyframes()[1]);
  // Grid samples sit at pixels 2, 6, 10, ...: a sample is a candidate when more than half of its
  // 5×5 patch is block (the median then the block's 1.5 m; the mean is then 20 cm or more off
  // 2 m). Columns u 22..38 (at u = 38 four of the five patch columns) and rows v 10..26 (at
  // v = 10 three of the five patch rows): 5 × 5 samples, less the corner (38, 10), whose patch
  // holds 4 × 3 = 12 block pixels of 25, so its median is the wall's.
  ASSERT_EQ(points.size(), 24U);
  for (const Eigen::Vector3f& p : points) {
    EXPECT_FLOAT_EQ(p.z(), 1.5F);
    // The pinhole point of the pixel that holds its patch's median: x = (u − ppx) z / fx, at a
    // whole pixel of the block.
    const float u = p.x() * in.fx / p.z() + in.ppx;
    const float v = p.y() * in.fy / p.z() + in.ppy;
    EXPECT_NEAR(u, std::round(u), 1e-3F);
    EXPECT_NEAR(v, std::round(v), 1e-3F);
    EXPECT_GE(u, 20.0F);
    EXPECT_LE(u, 39.0F);
    EXPECT_GE(v, 10.0F);
    EXPECT_LE(v, 29.0F);
  }
  // The wall frame shows nothing.
  EXPECT_TRUE(arm_candidates(samples, samples.keyframes()[0]).empty());
}

TEST(CalibrationGeometry, PoseDifferences) {
  Pose a = Pose::Identity();
  Pose b = Pose::Identity();
  b.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
  b.translation() = Eigen::Vector3d(0.003, 0.004, 0.0);
  EXPECT_NEAR(rotation_between_deg(a, b), 0.01 * 180.0 / 3.14159265358979323846, 1e-9);
  EXPECT_NEAR(translation_between_m(a, b), 0.005, 1e-12);
}

// Samples of `frames` frames of the moving UR5 cell, noise-free, rendered from its true pose, with
// the joints the simulator moved the arm to at each frame.
struct SimSweep {
  Config config;
  Simulator sim;
};
// A sample every 8 pixels unless `fine`: a quarter of the work, the same code (these run under
// the sanitizers too).
SimSweep calib_sim_sweep(const std::vector<std::string>& extra_sets, bool fine = false) {
  // The person enters the view after frame 120: the sweeps below end before.
  std::vector<std::string> sets = {"sim.noise=false", "sim.color=false"};
  if (!fine) sets.push_back("calibration.grid_px=8");
  sets.insert(sets.end(), extra_sets.begin(), extra_sets.end());
  SimSweep sweep{load_config(test::scene_path("cell-ur5-moving.yaml"), sets), {}};
  sweep.sim = make_simulator(sweep.config);
  return sweep;
}

ArmSamples calib_collect(const SimSweep& sweep, int frames, const RobotDescription& arm) {
  ArmSamples samples(sweep.config.calibration, sweep.sim.intrinsics(), arm, BaseFrame::base);
  Frame frame;
  for (int i = 0; i < frames; ++i) {
    sweep.sim.render(i, frame);
    samples.add(i, frame.depth, sweep.sim.arm_joints(i).q_rad, frame.stereo_baseline_mm);
  }
  return samples;
}

// A pose `translation_m` and `angle_deg` about `axis` away from `T` (the rotation about the camera).
Pose calib_perturbed(const Pose& T, const Eigen::Vector3d& translation_m, const Eigen::Vector3d& axis, double angle_deg) {
  Pose out = T;
  out.linear() = Eigen::AngleAxisd(angle_deg * 3.14159265358979323846 / 180.0, axis.normalized()) * T.linear();
  out.translation() += translation_m;
  return out;
}

TEST(CameraCalibration, ANoiseFreeSweepFindsTheTruePoseFromFifteenDegreesAndTwentyCentimetresOff) {
  const SimSweep sweep = calib_sim_sweep({});
  const ArmSamples samples = calib_collect(sweep, 110, builtin_robot(BuiltinArm::ur5));
  const Pose& truth = sweep.sim.T_base_camera;
  const Pose told = calib_perturbed(truth, Eigen::Vector3d(0.12, -0.1, 0.12), Eigen::Vector3d(1, 2, -1), 15.0);
  ASSERT_NEAR(translation_between_m(told, truth), 0.2, 0.01);
  const CameraCalibration fit = calibrate_camera(samples, told);
  ASSERT_TRUE(fit.ok) << fit.problem;
  EXPECT_LT(translation_between_m(fit.T_base_camera, truth), 0.0005);
  EXPECT_LT(rotation_between_deg(fit.T_base_camera, truth), 0.01);
  EXPECT_LT(fit.residual_rms_m, 0.001);  // 1 mm depth steps only
  EXPECT_GE(fit.poses, 50);
  EXPECT_LT(fit.sigma_translation_m, 0.0005);
}

TEST(CameraCalibration, AnArmHeldStillIsRefusedForItsPoses) {
  // The moving cell's arm held at its pick pose: a fixed state, one pose.
  const SimSweep sweep = calib_sim_sweep({"robot.trajectory={interpolation: linear, loop: false, waypoints: [{t_s: 0, "
                                          "joints_rad: [-2.741593, -1.0, 1.6, -2.1708, -1.5708, 0.0]}, {t_s: 1, "
                                          "joints_rad: [-2.741593, -1.0, 1.6, -2.1708, -1.5708, 0.0]}]}"});
  const ArmSamples samples = calib_collect(sweep, 60, builtin_robot(BuiltinArm::ur5));
  EXPECT_EQ(samples.keyframes().size(), 1U);
  const CameraCalibration fit = calibrate_camera(samples, sweep.sim.T_base_camera);
  EXPECT_FALSE(fit.ok);
  EXPECT_NE(fit.problem.find("distinct pose"), std::string::npos) << fit.problem;
  EXPECT_NE(fit.problem.find("six degrees of freedom"), std::string::npos) << fit.problem;
}

TEST(CameraCalibration, TheWrongArmIsRefusedForItsResidualOrItsSamples) {
  // A UR5 rendered, a UR10e (longer links) fitted: its shapes cannot take the UR5's pixels.
  const SimSweep sweep = calib_sim_sweep({});
  const ArmSamples samples = calib_collect(sweep, 110, builtin_robot(BuiltinArm::ur10e));
  const CameraCalibration fit = calibrate_camera(samples, sweep.sim.T_base_camera);
  EXPECT_FALSE(fit.ok);
  EXPECT_TRUE(fit.problem.find("mm RMS from its shapes") != std::string::npos ||
              fit.problem.find("arm samples lie within") != std::string::npos ||
              fit.problem.find("do not pin") != std::string::npos)
      << fit.problem;
}

TEST(CameraCalibration, TooFewArmSamplesAreRefusedNamingTheLimit) {
  const SimSweep sweep = calib_sim_sweep({"calibration.min_arm_samples=100000000"});
  const ArmSamples samples = calib_collect(sweep, 110, builtin_robot(BuiltinArm::ur5));
  const CameraCalibration fit = calibrate_camera(samples, sweep.sim.T_base_camera);
  EXPECT_FALSE(fit.ok);
  EXPECT_NE(fit.problem.find("(at least 100000000 needed)"), std::string::npos) << fit.problem;
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// What the nominal DH table costs: the simulator renders a UR5 whose kinematics differ from the
// nominal table by what a controller's factory calibration typically corrects (millimetres in
// the lengths, tenths of a degree in the twists and joint zeros), while the calibration fits
// the nominal table's shapes. The result is off by about as much as the arm is; docs/CALIBRATION.md
// quotes the numbers this prints.
TEST(CameraCalibration, TheNominalDhTableOfAnUncalibratedArmCostsMillimetres) {
  if (test::kSanitized) GTEST_SKIP() << "a measurement at the default grid, 60 s under the sanitizers: release builds";
  SimSweep sweep = calib_sim_sweep({}, true);
  RobotDescription& rendered = *sweep.sim.arm->robot.arm;
  const double kDeg = 3.14159265358979323846 / 180.0;
  const std::array<double, 6> d_mm = {0.8, -1.2, 1.5, -0.6, 1.0, -0.9};
  const std::array<double, 6> a_mm = {0.0, 2.0, -1.5, 0.0, 0.0, 0.0};
  const std::array<double, 6> alpha_deg = {0.05, -0.08, 0.06, -0.05, 0.07, 0.0};
  for (int j = 0; j < kJointCount; ++j) {
    rendered.dh[static_cast<size_t>(j)].d_m += d_mm[static_cast<size_t>(j)] / 1000.0;
    rendered.dh[static_cast<size_t>(j)].a_m += a_mm[static_cast<size_t>(j)] / 1000.0;
    rendered.dh[static_cast<size_t>(j)].alpha_rad += alpha_deg[static_cast<size_t>(j)] * kDeg;
  }
  const ArmSamples samples = calib_collect(sweep, 110, builtin_robot(BuiltinArm::ur5));
  const CameraCalibration fit = calibrate_camera(samples, sweep.sim.T_base_camera);
  ASSERT_TRUE(fit.ok) << fit.problem;
  const double error_mm = translation_between_m(fit.T_base_camera, sweep.sim.T_base_camera) * 1000.0;
  const double error_deg = rotation_between_deg(fit.T_base_camera, sweep.sim.T_base_camera);
  std::printf("DH errors of up to 2 mm and 0.08 deg: calibrated %.2f mm and %.3f deg off, residual %.2f mm\n", error_mm,
              error_deg, fit.residual_rms_m * 1000.0);
  // Not more than the arm's own error gives at the camera's 2 m.
  EXPECT_LT(error_mm, 10.0);
  EXPECT_LT(error_deg, 0.3);
}

}  // namespace
}  // namespace hrcsense
