// SPDX-License-Identifier: Apache-2.0
// Acceptance (issue H2, multi-camera calibration): two cameras of the simulated three-camera
// cell (config/cell-ur5-3cam.yaml, 848x480, D435 noise, its first 110 frames before the person
// comes into view). `left`, told a pose 15 mm and 1 degree off, calibrates to within 5 mm and
// 0.2 degrees of the simulator's true pose; the two cameras at their true poses agree on the
// arm's surfaces within a bound derived from the sensor noise, and with `front` shifted by 20 mm
// they disagree by that shift, in its direction. The same with `left` at another frame rate, so
// that the two cameras' keyframes show other instants and pair by the nearest arm pose. From the
// command line, `calibrate --camera all --write-back` writes both poses into a copy of the cell's
// file, keeps the rest of it and its backup, and prints the agreement table. (Some 10 s each at 848x480: the `long` label.)

#include "../support/run_cli.hpp"
#include "../support/scenes.hpp"
#include "common/assembly.hpp"
#include "hrcsense/calibration.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace hrcsense::test {
namespace {

constexpr double kMultiLongPi = 3.14159265358979323846;

// ---- Two cameras of the simulated three-camera cell, at 848x480 with the D435's noise.

std::string multi_pose_text(const Pose& T) {
  const Eigen::Vector3d t = T.translation();
  const Eigen::Vector3d rpy = rotation_rpy_deg(T);
  std::ostringstream s;
  s.precision(10);
  s << "{translation_m: [" << t.x() << ", " << t.y() << ", " << t.z() << "], rotation_rpy_deg: [" << rpy.x() << ", "
    << rpy.y() << ", " << rpy.z() << "]}";
  return s.str();
}

// The cell's `front` and `left` (their poses from config/cell-ur5-3cam.yaml), `left` told
// `left_told` while the simulator renders it from its true pose.
std::vector<std::string> multi_cell_sets(const Pose& left_truth, const Pose& left_told) {
  return {"sim.color=false",
          "cameras=[{name: front, T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-133.3, 0, 90]}, "
          "source: {seed: 1}}, {name: left, T_base_camera: " +
              multi_pose_text(left_told) + ", source: {seed: 2}, sim: {camera_T_base_camera: " +
              multi_pose_text(left_truth) + "}}]"};
}

// The samples of one camera over its frames 0..frames−1 (frame i at i / fps s; the person enters
// the views at 4 s), with the joints the simulator moved the arm to: cameras at one rate render
// the same instants, cameras at other rates other instants.
ArmSamples multi_collect(const Config& config, const Simulator& sim, int frames) {
  ArmSamples samples(config.calibration, sim.intrinsics(), *config.pipeline.robot.arm, config.pipeline.robot.base_frame);
  Frame frame;
  for (int i = 0; i < frames; ++i) {
    sim.render(i, frame);
    samples.add(i, frame.depth, sim.arm_joints(i).q_rad, frame.stereo_baseline_mm);
  }
  return samples;
}

// The bound on two right poses' disagreement from the sensor noise (docs/SIMULATOR.md): a pixel's
// depth σ = Z² s / (fx B) at the farthest arm point either camera saw (s the disparity noise in
// pixels, B the baseline); a 5×5 median about 1.25 σ / 5; an offset fitted to N points whose
// normals span three directions about evenly has a σ of about √3 σ_point / √N per axis; the
// difference of two, 6 σ.
double multi_noise_bound_m(const ArmSamples& a, const Pose& a_truth, const ArmSamples& b, const Pose& b_truth,
                           const Config& config, const CameraAgreement& agreement) {
  double far_m = 0.0;
  for (const auto* views : {&a, &b}) {
    const Pose& T = views == &a ? a_truth : b_truth;
    for (const ArmView& view : arm_views(*views, T)) {
      for (const Eigen::Vector3f& p : view.points_base) {
        Eigen::Vector3f normal;
        if (std::abs(distance_to_shapes(view.shapes_base, p, normal)) > 0.06F) continue;  // not the arm
        far_m = std::max(far_m, (p.cast<double>() - T.translation()).norm());
      }
    }
  }
  const double fx = a.intrinsics().fx;
  const double sigma_pixel_m = far_m * far_m * config.sim.disparity_noise_px / (fx * kD435BaselineMm / 1000.0);
  const double sigma_patch_m = 1.25 * sigma_pixel_m / 5.0;
  const double bound_m = 6.0 * sigma_patch_m *
                         std::sqrt(3.0 * (1.0 / static_cast<double>(agreement.all.points_a) +
                                          1.0 / static_cast<double>(agreement.all.points_b)));
  std::printf("farthest arm point %.2f m: a pixel's sigma %.1f mm, the bound %.2f mm + 0.1 mm (+ 0.5 mm shifted)\n",
              far_m, sigma_pixel_m * 1000.0, bound_m * 1000.0);
  return bound_m;
}

TEST(MultiCameraCalibration, AWrongPoseLandsNearTheTruthAndTheCamerasAgreeOnTheArm) {
  const std::string cell = scene_path("cell-ur5-3cam.yaml");
  const Pose left_truth = load_config(cell, {}, "left").pipeline.T_base_camera;
  // Told 15 mm and 1 degree off (about an axis through the camera).
  Pose left_told = left_truth;
  left_told.linear() = Eigen::AngleAxisd(1.0 * kMultiLongPi / 180.0, Eigen::Vector3d(1, -2, 1).normalized()) * left_truth.linear();
  left_told.translation() += Eigen::Vector3d(0.009, -0.006, 0.0104);
  const std::vector<std::string> sets = multi_cell_sets(left_truth, left_told);
  const Config front_config = load_config(cell, sets, "front");
  const Config left_config = load_config(cell, sets, "left");
  const Simulator front_sim = make_simulator(front_config);
  const Simulator left_sim = make_simulator(left_config);
  // The simulator renders `left` where it truly is, whatever it was told.
  ASSERT_LT(translation_between_m(left_sim.T_base_camera, left_truth), 1e-9);
  ASSERT_NEAR(translation_between_m(left_config.pipeline.T_base_camera, left_truth), 0.015, 0.0005);
  const int frames = 110;
  const ArmSamples front = multi_collect(front_config, front_sim, frames);
  const ArmSamples left = multi_collect(left_config, left_sim, frames);

  // 1. `left` calibrated from the wrong pose lands near its true pose.
  const CameraCalibration fit = calibrate_camera(left, left_config.pipeline.T_base_camera);
  ASSERT_TRUE(fit.ok) << fit.problem;
  std::printf("left from 15 mm and 1 deg off: %.2f mm and %.3f deg from the truth, residual %.1f mm, %zu samples\n",
              translation_between_m(fit.T_base_camera, left_truth) * 1000.0,
              rotation_between_deg(fit.T_base_camera, left_truth), fit.residual_rms_m * 1000.0, fit.inliers);
  EXPECT_LT(translation_between_m(fit.T_base_camera, left_truth), 0.005);
  EXPECT_LT(rotation_between_deg(fit.T_base_camera, left_truth), 0.2);

  // 2. Two right poses (the simulator's truths) agree on the arm; the bound is from the sensor
  // noise (multi_noise_bound_m).
  const Pose& front_truth = front_sim.T_base_camera;
  const CameraAgreement right = camera_agreement(arm_views(front, front_truth), arm_views(left, left_truth));
  // 3. `front` told a pose shifted by 20 mm: the two cameras put the arm's surfaces that far apart,
  // in the shift's direction (front's offset minus left's).
  Pose front_shifted = front_truth;
  const Eigen::Vector3d shift(0.012, -0.016, 0.0);
  front_shifted.translation() += shift;
  const CameraAgreement shifted = camera_agreement(arm_views(front, front_shifted), arm_views(left, left_truth));
  // 4. The fitted pose of `left` against front's truth.
  const CameraAgreement fitted = camera_agreement(arm_views(front, front_truth), arm_views(left, fit.T_base_camera));
  std::printf("view pairs %d, links %zu, points %zu and %zu: right poses %.2f mm apart, front shifted 20 mm: %.2f mm "
              "(offset difference [%.1f, %.1f, %.1f] mm), left as fitted %.2f mm\n",
              right.paired_views, right.links.size(), right.all.points_a, right.all.points_b,
              right.all.disagreement_m * 1000.0, shifted.all.disagreement_m * 1000.0,
              (shifted.all.offset_a_base_m - shifted.all.offset_b_base_m).x() * 1000.0,
              (shifted.all.offset_a_base_m - shifted.all.offset_b_base_m).y() * 1000.0,
              (shifted.all.offset_a_base_m - shifted.all.offset_b_base_m).z() * 1000.0,
              fitted.all.disagreement_m * 1000.0);
  for (const LinkAgreement& link : right.links) {
    std::printf("  link %d: %d views, %zu and %zu points, %.2f mm apart (shifted: %.2f mm), %d axes\n", link.link,
                link.views, link.points_a, link.points_b, link.disagreement_m * 1000.0,
                shifted.links.size() == right.links.size() ? shifted.links[&link - right.links.data()].disagreement_m * 1000.0
                                                           : -1.0,
                link.constrained_axes);
  }
  ASSERT_GE(right.paired_views, 20);
  ASSERT_GE(right.links.size(), 2U);
  EXPECT_EQ(right.all.constrained_axes, 3);
  // Beside the noise bound the method's own error: 0.1 mm (a noise-free sweep gives 0.03 mm for
  // the right poses and 0.17 mm for the shifted one, whose 2 cm move some points of the arm
  // nearest the table through the candidate margin).
  const double noise_bound_m = multi_noise_bound_m(front, front_truth, left, left_truth, front_config, right);
  EXPECT_LT(right.all.disagreement_m, noise_bound_m + 0.0001);
  EXPECT_LT((shifted.all.offset_a_base_m - shifted.all.offset_b_base_m - shift).norm(), noise_bound_m + 0.0005);
  EXPECT_NEAR(shifted.all.disagreement_m, 0.020, noise_bound_m + 0.0005);
  for (const LinkAgreement& link : shifted.links) EXPECT_NEAR(link.disagreement_m, 0.020, 0.002) << link.link;
  // `left` as fitted: within the calibration's own error of the truth (1-2 mm, 0.03 degrees at 2-3 m).
  EXPECT_LT(fitted.all.disagreement_m, 0.005);
}

// The cell's `front` at 30 frames/s and `left` at `left_fps`, both told and rendered at their
// true poses (config/cell-ur5-3cam.yaml).
std::vector<std::string> multi_cell_rate_sets(const std::string& left_fps) {
  return {"sim.color=false",
          "cameras=[{name: front, T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-133.3, 0, 90]}, "
          "fps: 30, source: {seed: 1}}, {name: left, T_base_camera: {translation_m: [0.3, 2.2, 1.5], "
          "rotation_rpy_deg: [-124.3, 0, 180]}, fps: " +
              left_fps + ", source: {seed: 2}}]"};
}

TEST(MultiCameraCalibration, CamerasAtOtherInstantsArePairedByNearbyArmPosesAndAgree) {
  // `left` at 23.3 frames/s: its frames (i / 23.3 s) meet front's (j / 30 s) only at 0 s and every
  // 10 s (233 and 300 have no common factor), as two live cameras' frames hardly ever meet. Both
  // over the same 3.65 s before the person comes into view: 110 frames of `front`, 85 of `left`.
  const std::string cell = scene_path("cell-ur5-3cam.yaml");
  const std::vector<std::string> sets = multi_cell_rate_sets("23.3");
  const Config front_config = load_config(cell, sets, "front");
  const Config left_config = load_config(cell, sets, "left");
  ASSERT_DOUBLE_EQ(front_config.sim.fps, 30.0);
  ASSERT_DOUBLE_EQ(left_config.sim.fps, 23.3);
  const Simulator front_sim = make_simulator(front_config);
  const Simulator left_sim = make_simulator(left_config);
  const Pose& front_truth = front_sim.T_base_camera;
  const Pose& left_truth = left_sim.T_base_camera;
  const ArmSamples front = multi_collect(front_config, front_sim, 110);
  const ArmSamples left = multi_collect(left_config, left_sim, 85);

  // The premise: keyframes of the two with every joint within 1e-4 rad (the rule of exact instants)
  // are few: frame 0, and where both took a keyframe as the arm arrived at a pose it holds.
  int same_joints = 0;
  for (const ArmKeyframe& l : left.keyframes()) {
    for (const ArmKeyframe& f : front.keyframes()) {
      bool same = true;
      for (size_t j = 0; j < l.q_rad.size(); ++j) same = same && std::abs(l.q_rad[j] - f.q_rad[j]) <= 1e-4;
      if (!same) continue;
      ++same_joints;
      break;
    }
  }

  const CameraAgreement right = camera_agreement(arm_views(front, front_truth), arm_views(left, left_truth));
  // `left` told a pose shifted by 20 mm: the two cameras put the arm's surfaces that far apart, in
  // the shift's direction (left's offset minus front's).
  Pose left_shifted = left_truth;
  const Eigen::Vector3d shift(-0.016, 0.0, 0.012);
  left_shifted.translation() += shift;
  const CameraAgreement shifted = camera_agreement(arm_views(front, front_truth), arm_views(left, left_shifted));
  const Eigen::Vector3d shifted_difference = shifted.all.offset_b_base_m - shifted.all.offset_a_base_m;
  std::printf("keyframes with arm points %d and %d, %d of left's with a keyframe of front's of the same joints; "
              "view pairs %d (the arm's shapes %.1f mm apart at the median, %.1f mm at most, joints %.3f rad), "
              "links %zu, points %zu and %zu: right poses %.2f mm apart, left shifted 20 mm: %.2f mm "
              "(offset difference [%.1f, %.1f, %.1f] mm)\n",
              right.views_a, right.views_b, same_joints, right.paired_views, right.pair_travel_median_m * 1000.0,
              right.pair_travel_max_m * 1000.0, right.pair_joint_max_rad, right.links.size(), right.all.points_a,
              right.all.points_b, right.all.disagreement_m * 1000.0, shifted.all.disagreement_m * 1000.0,
              shifted_difference.x() * 1000.0, shifted_difference.y() * 1000.0, shifted_difference.z() * 1000.0);
  for (const LinkAgreement& link : right.links) {
    std::printf("  link %d: %d view pairs, %zu and %zu points, %.2f mm apart, %d axes\n", link.link, link.views,
                link.points_a, link.points_b, link.disagreement_m * 1000.0, link.constrained_axes);
  }
  EXPECT_LE(same_joints, 4);
  // (a) The table is filled: while the arm turns, front takes a keyframe every frame (the flange,
  // 0.66 m out, moves 3.5 cm per frame at 1.6 rad/s and 30 frames/s, more than the 2 cm of
  // keyframe_motion_m), so each keyframe of left has one of front's within half a frame's move,
  // about 2 cm: nearly every one pairs.
  ASSERT_GE(right.views_b, 40);
  EXPECT_GE(right.paired_views, right.views_b * 9 / 10);
  ASSERT_GE(right.links.size(), 2U);
  EXPECT_EQ(right.all.constrained_axes, 3);
  // (b) At the true poses the two agree within the noise's bound plus the method's 0.1 mm (a
  // noise-free sweep gives 0.03 mm here too: the pairs' few millimetres of travel add nothing).
  const double noise_bound_m = multi_noise_bound_m(front, front_truth, left, left_truth, front_config, right);
  EXPECT_LT(right.all.disagreement_m, noise_bound_m + 0.0001);
  // (c) Shifted by 20 mm: that far apart, in the shift's direction, within the noise's bound plus
  // the 0.5 mm of the first test for the points the shift moves through the candidate margin (a
  // noise-free sweep: 0.4 mm off the shift).
  EXPECT_LT((shifted_difference - shift).norm(), noise_bound_m + 0.0005);
  EXPECT_NEAR(shifted.all.disagreement_m, 0.020, noise_bound_m + 0.0005);
  for (const LinkAgreement& link : shifted.links) EXPECT_NEAR(link.disagreement_m, 0.020, 0.002) << link.link;
}

// The cell's text with its cameras: list replaced by `front` (its true pose) and `left` (told
// `left_told`, rendered at `left_truth`): a two-camera cell whose file the CLI edits.
std::string multi_two_camera_cell(const Pose& left_truth, const Pose& left_told) {
  std::ifstream in(scene_path("cell-ur5-3cam.yaml"));
  std::ostringstream text;
  text << in.rdbuf();
  std::string cell = text.str();
  const size_t begin = cell.find("\ncameras:\n");
  const size_t end = cell.find("# The shared seen-free grid");
  if (begin == std::string::npos || end == std::string::npos) return {};
  const std::string cameras = "\ncameras:\n  - name: front  # the door side\n"
                              "    T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-133.3, 0, 90]}\n"
                              "    source: {seed: 1}\n  - name: left\n    T_base_camera: " +
                              multi_pose_text(left_told) + "\n    source: {seed: 2}\n    sim: {camera_T_base_camera: " +
                              multi_pose_text(left_truth) + "}\n";
  return cell.substr(0, begin) + cameras + cell.substr(end);
}

TEST(MultiCameraCalibrationCli, CameraAllWritesEachPoseBackAndPrintsTheAgreement) {
  const std::string cell = scene_path("cell-ur5-3cam.yaml");
  const Pose front_truth = load_config(cell, {}, "front").pipeline.T_base_camera;
  const Pose left_truth = load_config(cell, {}, "left").pipeline.T_base_camera;
  Pose left_told = left_truth;
  left_told.linear() = Eigen::AngleAxisd(-1.0 * kMultiLongPi / 180.0, Eigen::Vector3d(2, 1, 0).normalized()) * left_truth.linear();
  left_told.translation() += Eigen::Vector3d(-0.01, 0.0, 0.015);
  const std::string dir = std::string(::testing::TempDir()) + "multi_calibrate_cli/";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = dir + "cell.yaml";
  const std::string original = multi_two_camera_cell(left_truth, left_told);
  ASSERT_FALSE(original.empty());
  std::ofstream(path, std::ios::binary) << original;

  const test::CliResult run = test::cli("calibrate --config " + path + " --camera all --write-back --out " + dir +
                                        "poses.yaml --frames 110 --set sim.color=false");
  ASSERT_EQ(run.exit_code, 0) << run.out;
  std::printf("%s", run.out.substr(run.out.find("agreement on the arm")).c_str());
  EXPECT_NE(run.out.find("front-left"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("(the old file kept as " + path + ".bak)"), std::string::npos) << run.out;

  // The written-back file: each entry's pose as calibrated (near its truth), the rest as it was.
  const Config after = load_config(path, {});
  ASSERT_EQ(after.cameras.size(), 2U);
  EXPECT_LT(translation_between_m(after.cameras[0].T_base_camera, front_truth), 0.005);
  EXPECT_LT(translation_between_m(after.cameras[1].T_base_camera, left_truth), 0.005);
  EXPECT_LT(rotation_between_deg(after.cameras[1].T_base_camera, left_truth), 0.2);
  EXPECT_GT(translation_between_m(after.cameras[1].T_base_camera, left_told), 0.01);
  // `--camera left` reads the new pose; the top-level camera is not an entry and stays.
  EXPECT_TRUE(load_config(path, {}, "left").pipeline.T_base_camera.isApprox(after.cameras[1].T_base_camera, 1e-12));
  EXPECT_TRUE(after.pipeline.T_base_camera.isApprox(load_config(cell, {}).pipeline.T_base_camera, 1e-12));
  // Line by line: only the two entries' T_base_camera lines changed; the backup is the original.
  std::ifstream edited_in(path);
  std::ifstream backup_in(path + ".bak");
  std::string edited_line;
  std::string backup_line;
  int changed = 0;
  int lines = 0;
  while (std::getline(backup_in, backup_line)) {
    ASSERT_TRUE(std::getline(edited_in, edited_line));
    ++lines;
    if (edited_line == backup_line) continue;
    ++changed;
    EXPECT_EQ(backup_line.rfind("    T_base_camera: {translation_m: [", 0), 0U) << backup_line;
  }
  EXPECT_FALSE(std::getline(edited_in, edited_line));
  EXPECT_EQ(changed, 2);
  std::ifstream backup_again(path + ".bak");
  std::ostringstream backup_text;
  backup_text << backup_again.rdbuf();
  EXPECT_EQ(backup_text.str(), original);
  // --out: a cameras: list of the same poses that load_config reads.
  const Config poses = load_config(dir + "poses.yaml", {});
  ASSERT_EQ(poses.cameras.size(), 2U);
  EXPECT_EQ(poses.cameras[1].name, "left");
  EXPECT_TRUE(poses.cameras[1].T_base_camera.isApprox(after.cameras[1].T_base_camera, 1e-12));

  // A second write-back keeps the first one's file as the next backup.
  const test::CliResult again = test::cli("calibrate --config " + path + " --camera left --write-back --frames 110 "
                                          "--set sim.color=false");
  ASSERT_EQ(again.exit_code, 0) << again.out;
  EXPECT_TRUE(std::filesystem::exists(path + ".bak2"));
}

}  // namespace
}  // namespace hrcsense::test
