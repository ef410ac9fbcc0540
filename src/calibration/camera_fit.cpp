// SPDX-License-Identifier: Apache-2.0
// hrcsense — the camera's pose fitted to the arm's candidates (calibration.hpp): the coarse
// alignment by keyframe centroids, the robust point-to-surface refinement and its jackknife.
#include "hrcsense/calibration.hpp"

#include "hrcsense/number_text.hpp"
#include "hrcsense/pose_check.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

namespace hrcsense {
namespace {

constexpr double kDegPerRad = 57.29577951308232;

// One keyframe's part of the fit: its candidates (camera frame) and the arm's visual shapes
// at its joints (base frame).
struct KeyframeFit {
  std::vector<Eigen::Vector3f> points_camera;
  std::vector<Capsule> shapes_base;
  Eigen::Vector3d centroid_camera = Eigen::Vector3d::Zero();
};

// The rigid motion T ← T · Exp(ξ), ξ = (ω, v) in the camera frame.
Pose apply_camera_step(const Pose& T, const Eigen::Matrix<double, 6, 1>& xi) {
  Pose step = Pose::Identity();
  const Eigen::Vector3d omega = xi.head<3>();
  const double angle = omega.norm();
  if (angle > 0.0) step.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  step.translation() = xi.tail<3>();
  Pose out = T * step;
  // Keeps the rotation orthonormal over many small steps.
  out.linear() = Eigen::Quaterniond(out.rotation()).normalized().toRotationMatrix();
  return out;
}

// The difference b relative to a, in a's (the camera's) frame: rotation vector, translation.
Eigen::Matrix<double, 6, 1> camera_difference(const Pose& a, const Pose& b) {
  const Pose d = a.inverse() * b;
  const Eigen::AngleAxisd aa(d.rotation());
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = aa.axis() * aa.angle();
  out.tail<3>() = d.translation();
  return out;
}

// The arm's surface as the camera at T_base_camera would see it on the grid: the centroid of
// its visible points (camera frame) where they stand in front of the background, and their count.
size_t predicted_arm(const ArmSamples& samples, const KeyframeFit& key, const Pose& T_base_camera,
                     Eigen::Vector3d& centroid_camera) {
  const Intrinsics& in = samples.intrinsics();
  const int step = samples.params().grid_px;
  std::vector<ShapeInCamera> shapes;
  shapes_in_camera(in, T_base_camera, RobotModel{key.shapes_base}, shapes);
  centroid_camera.setZero();
  if (shapes.empty()) return 0;
  const ShapesPixelBox box = shapes_pixel_box(shapes, in);
  const int u_min = box.u0, u_max = box.u1, v_min = box.v0, v_max = box.v1;
  const auto cell = [step](int pixel, int cells) { return std::clamp(pixel / step, 0, cells - 1); };
  const float scale = samples.depth_scale_m();
  size_t count = 0;
  for (int gy = cell(v_min, samples.grid_height()); gy <= cell(v_max, samples.grid_height()); ++gy) {
    for (int gx = cell(u_min, samples.grid_width()); gx <= cell(u_max, samples.grid_width()); ++gx) {
      const int u = gx * step + step / 2;
      const int v = gy * step + step / 2;
      const Eigen::Vector3f ray((static_cast<float>(u) - in.ppx) / in.fx, (static_cast<float>(v) - in.ppy) / in.fy, 1.0F);
      const float nearest_m = nearest_shape_hit(shapes, u, v, ray).depth_m;
      if (nearest_m == 0.0F) continue;
      const uint16_t farthest =
          samples.farthest()[static_cast<size_t>(gy) * static_cast<size_t>(samples.grid_width()) + static_cast<size_t>(gx)];
      if (farthest != 0 &&
          static_cast<float>(farthest) * scale - nearest_m <= static_cast<float>(samples.margin_raw(farthest)) * scale) {
        continue;
      }
      centroid_camera += (ray * nearest_m).cast<double>();
      ++count;
    }
  }
  if (count > 0) centroid_camera /= static_cast<double>(count);
  return count;
}

// The rigid motion that takes the points `from` onto `to` best in least squares (Kabsch).
Pose kabsch(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_to = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    mean_from += from[i];
    mean_to += to[i];
  }
  mean_from /= static_cast<double>(from.size());
  mean_to /= static_cast<double>(to.size());
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) cross += (from[i] - mean_from) * (to[i] - mean_to).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  Pose T = Pose::Identity();
  T.linear() = svd.matrixV() * fix * svd.matrixU().transpose();
  T.translation() = mean_to - T.linear() * mean_from;
  return T;
}

// The second largest spread (m, RMS) of points about their mean: below a few centimetres they
// lie on a line, and centroids cannot fix the rotation about it.
double planar_spread_m(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : points) cov += (p - mean) * (p - mean).transpose();
  cov /= static_cast<double>(points.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  return std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
}

// Coarse: each keyframe's candidate centroid is where the camera saw the arm; the centroid of
// the arm's surface the pose would show is where it is. A wrong pose shifts the second by less
// than it moves the first, so a few rounds of Kabsch over the keyframes walk into the basin the
// refinement needs. Keyframes whose candidate count is far from the prediction's (a person in
// view, the arm half out of the image) are left out.
Pose coarse_align(const ArmSamples& samples, const std::vector<KeyframeFit>& keys, const Pose& T_told) {
  const auto min_samples = static_cast<size_t>(std::max(1, samples.params().min_samples_per_pose));
  // At most this many keyframes, evenly spread: the rays are the cost.
  constexpr size_t kMaxCoarseKeys = 120;
  const size_t stride = std::max<size_t>(1, (keys.size() + kMaxCoarseKeys - 1) / kMaxCoarseKeys);
  Pose T = T_told;
  for (int round = 0; round < 12; ++round) {
    std::vector<Eigen::Vector3d> seen_camera;
    std::vector<Eigen::Vector3d> predicted_base;
    for (size_t k = 0; k < keys.size(); k += stride) {
      const KeyframeFit& key = keys[k];
      if (key.points_camera.size() < min_samples) continue;
      Eigen::Vector3d predicted_camera;
      const size_t predicted = predicted_arm(samples, key, T, predicted_camera);
      if (predicted < min_samples) continue;
      const double ratio = static_cast<double>(key.points_camera.size()) / static_cast<double>(predicted);
      if (ratio < 0.5 || ratio > 2.0) continue;
      seen_camera.push_back(key.centroid_camera);
      predicted_base.push_back(T * predicted_camera);
    }
    if (seen_camera.size() < 3 || planar_spread_m(predicted_base) < 0.03) break;
    Pose next = kabsch(seen_camera, predicted_base);
    // Keyframes whose centroids disagree with the others' motion (something else in view, such as a
    // person the count test let through) are dropped once, and the motion solved again.
    std::vector<double> misfit_m;
    for (size_t i = 0; i < seen_camera.size(); ++i) misfit_m.push_back((next * seen_camera[i] - predicted_base[i]).norm());
    std::vector<double> sorted = misfit_m;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double keep_m = std::max(0.05, 3.0 * sorted[sorted.size() / 2]);
    std::vector<Eigen::Vector3d> kept_seen;
    std::vector<Eigen::Vector3d> kept_predicted;
    for (size_t i = 0; i < seen_camera.size(); ++i) {
      if (misfit_m[i] > keep_m) continue;
      kept_seen.push_back(seen_camera[i]);
      kept_predicted.push_back(predicted_base[i]);
    }
    if (kept_seen.size() < 3 || planar_spread_m(kept_predicted) < 0.03) break;
    next = kabsch(kept_seen, kept_predicted);
    const bool settled = translation_between_m(T, next) < 0.001 && rotation_between_deg(T, next) < 0.05;
    T = next;
    if (settled) break;
  }
  return T;
}

// The normal equations of one Gauss–Newton step over the kept keyframes.
struct NormalEquations {
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  double sum_r2 = 0.0;
  size_t inliers = 0;
  std::vector<size_t> inliers_per_key;
};

// A candidate farther than this (m) from the fitted arm is not the arm; a keyframe with more than
// this share of such candidates (or three times the typical share) shows something else that moved.
constexpr float kOffArmM = 0.1F;
constexpr double kMaxOffArmShare = 0.1;

// Below this distance (m) a residual weighs fully; beyond it, Huber's 1/|r| (D435 noise at 2 m).
constexpr float kHuberM = 0.01F;

NormalEquations accumulate(const std::vector<KeyframeFit>& keys, const std::vector<char>& use, const Pose& T,
                           float gate_m) {
  NormalEquations eq;
  eq.inliers_per_key.assign(keys.size(), 0);
  const Eigen::Matrix3f R = T.rotation().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  for (size_t k = 0; k < keys.size(); ++k) {
    if (!use[k]) continue;
    for (const Eigen::Vector3f& p_camera : keys[k].points_camera) {
      Eigen::Vector3f n_base;
      const float r = distance_to_shapes(keys[k].shapes_base, R * p_camera + t, n_base);
      if (!(std::abs(r) <= gate_m)) continue;
      const float w = std::abs(r) <= kHuberM ? 1.0F : kHuberM / std::abs(r);
      const Eigen::Vector3f n_camera = R.transpose() * n_base;
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = p_camera.cross(n_camera).cast<double>();
      J.tail<3>() = n_camera.cast<double>();
      eq.H.selfadjointView<Eigen::Upper>().rankUpdate(J, static_cast<double>(w));
      eq.g += static_cast<double>(w * r) * J;
      eq.sum_r2 += static_cast<double>(r) * static_cast<double>(r);
      ++eq.inliers;
      ++eq.inliers_per_key[k];
    }
  }
  eq.H = eq.H.selfadjointView<Eigen::Upper>();
  return eq;
}

constexpr double kMaxStepRad = 2.0 / kDegPerRad;
constexpr double kMaxStepM = 0.05;

// Gauss–Newton with each gate in turn until the step is below a micrometre and a microradian.
Pose refine(const std::vector<KeyframeFit>& keys, const std::vector<char>& use, Pose T,
            const std::vector<float>& gates_m, int& iterations) {
  for (const float gate_m : gates_m) {
    for (int i = 0; i < 30; ++i) {
      const NormalEquations eq = accumulate(keys, use, T, gate_m);
      if (eq.inliers < 6) return T;
      // A whisper of damping keeps a nearly free direction from running off; a constrained
      // direction does not feel it.
      Eigen::Matrix<double, 6, 6> H = eq.H;
      H.diagonal().array() += 1e-9 * H.trace();
      Eigen::Matrix<double, 6, 1> xi = H.ldlt().solve(-eq.g);
      if (!xi.allFinite()) return T;
      // A trust region: far from the answer, with few points inside the gate, a full step can
      // overshoot into a place with none; at most 2 degrees and 5 cm a step.
      const double shrink = std::max({1.0, xi.head<3>().norm() / kMaxStepRad, xi.tail<3>().norm() / kMaxStepM});
      xi /= shrink;
      T = apply_camera_step(T, xi);
      ++iterations;
      if (xi.head<3>().norm() < 1e-6 && xi.tail<3>().norm() < 1e-6) break;
    }
  }
  return T;
}

const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

}  // namespace

double rotation_between_deg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.rotation().transpose() * b.rotation()).angle() * kDegPerRad;
}

double translation_between_m(const Pose& a, const Pose& b) { return (a.translation() - b.translation()).norm(); }

CameraCalibration calibrate_camera(const ArmSamples& samples, const Pose& T_base_camera_told, bool with_spread) {
  const CalibrationParams& params = samples.params();
  CameraCalibration out;
  out.T_base_camera = T_base_camera_told;
  out.T_base_camera_coarse = T_base_camera_told;
  std::vector<KeyframeFit> keys;
  RobotModel shapes;
  for (const ArmKeyframe& keyframe : samples.keyframes()) {
    KeyframeFit key;
    key.points_camera = arm_candidates(samples, keyframe);
    if (key.points_camera.empty()) continue;
    for (const Eigen::Vector3f& p : key.points_camera) key.centroid_camera += p.cast<double>();
    key.centroid_camera /= static_cast<double>(key.points_camera.size());
    robot_render_capsules(samples.arm(), keyframe.q_rad, samples.base_frame(), shapes);
    key.shapes_base = shapes.capsules;
    out.candidates += key.points_camera.size();
    keys.push_back(std::move(key));
  }
  const auto min_per_pose = static_cast<size_t>(std::max(1, params.min_samples_per_pose));
  const std::string sweep_hint = " (docs/CALIBRATION.md, \"The sweep\")";
  const auto count_poses = [&](const std::vector<size_t>& per_key) {
    int poses = 0;
    for (const size_t n : per_key) poses += n >= min_per_pose ? 1 : 0;
    return poses;
  };

  if (!keys.empty()) {
    std::vector<char> all(keys.size(), 1);
    const float gate = params.inlier_gate_m;
    // Two starts, the told pose and the coarse alignment's; the one that puts more candidates on
    // the arm wins. Point-to-surface alone reaches far (the arm's many poses average its wrong
    // matches out), the coarse step further where the arm fills little of the image.
    out.T_base_camera_coarse = coarse_align(samples, keys, T_base_camera_told);
    const std::vector<char> every(keys.size(), 1);
    size_t best_inliers = 0;
    for (const Pose& start : {T_base_camera_told, out.T_base_camera_coarse}) {
      int iterations = 0;
      const Pose fitted = refine(keys, every, start, {0.4F, 0.2F, 0.1F, 0.05F, gate}, iterations);
      const size_t inliers = accumulate(keys, every, fitted, gate).inliers;
      out.iterations += iterations;
      if (inliers > best_inliers) {
        best_inliers = inliers;
        out.T_base_camera = fitted;
      }
      if (translation_between_m(start, out.T_base_camera_coarse) < 1e-6 &&
          rotation_between_deg(start, out.T_base_camera_coarse) < 1e-6) {
        break;  // the coarse step stayed where it began: one start
      }
    }
    // A keyframe with many candidates off the fitted arm shows something else that moved (a
    // person): its points beside the arm would pull the fit, so it is left out whole. "Many" is
    // relative to the typical keyframe, so that a fit still far off leaves nothing out.
    for (int pass = 0; pass < 2; ++pass) {
      const NormalEquations near_eq = accumulate(keys, all, out.T_base_camera, kOffArmM);
      std::vector<double> off_share(keys.size(), 0.0);
      std::vector<double> used_shares;
      for (size_t k = 0; k < keys.size(); ++k) {
        off_share[k] = 1.0 - static_cast<double>(near_eq.inliers_per_key[k]) /
                                 static_cast<double>(keys[k].points_camera.size());
        if (all[k]) used_shares.push_back(off_share[k]);
      }
      if (used_shares.empty()) break;
      std::nth_element(used_shares.begin(), used_shares.begin() + static_cast<std::ptrdiff_t>(used_shares.size() / 2),
                       used_shares.end());
      const double limit = std::max(kMaxOffArmShare, 3.0 * used_shares[used_shares.size() / 2]);
      size_t left_out = 0;
      for (size_t k = 0; k < keys.size(); ++k) {
        if (all[k] && off_share[k] > limit) {
          all[k] = 0;
          ++left_out;
        }
      }
      out.keyframes_left_out += left_out;
      if (left_out == 0) break;
      out.T_base_camera = refine(keys, all, out.T_base_camera, {0.05F, gate}, out.iterations);
    }
    const NormalEquations final_eq = accumulate(keys, all, out.T_base_camera, gate);
    out.inliers = final_eq.inliers;
    out.poses = count_poses(final_eq.inliers_per_key);
    out.residual_rms_m = final_eq.inliers > 0 ? std::sqrt(final_eq.sum_r2 / static_cast<double>(final_eq.inliers)) : 0.0;

    // The jackknife: each group leaves out every G-th keyframe with the arm seen.
    const int groups = std::max(2, params.jackknife_groups);
    std::vector<int> group_of(keys.size(), -1);
    int seen = 0;
    for (size_t k = 0; k < keys.size(); ++k) {
      if (all[k] && final_eq.inliers_per_key[k] >= min_per_pose) group_of[k] = seen++ % groups;
    }
    if (!with_spread) {
      // Only the fit: the spread and its refusal are left to the final call.
    } else if (seen >= groups) {
      std::vector<Eigen::Matrix<double, 6, 1>> thetas;
      for (int g = 0; g < groups; ++g) {
        std::vector<char> use(keys.size(), 0);
        for (size_t k = 0; k < keys.size(); ++k) use[k] = group_of[k] >= 0 && group_of[k] != g ? 1 : 0;
        int unused = 0;
        const Pose T_g = refine(keys, use, out.T_base_camera, {gate}, unused);
        thetas.push_back(camera_difference(out.T_base_camera, T_g));
      }
      Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
      for (const auto& th : thetas) mean += th;
      mean /= static_cast<double>(groups);
      Eigen::Matrix<double, 6, 1> var = Eigen::Matrix<double, 6, 1>::Zero();
      for (const auto& th : thetas) var += (th - mean).cwiseAbs2();
      const Eigen::Matrix<double, 6, 1> sigma =
          (var * (static_cast<double>(groups - 1) / static_cast<double>(groups))).cwiseSqrt();
      int worst_rotation = 0;
      int worst_translation = 0;
      out.sigma_rotation_deg = sigma.head<3>().maxCoeff(&worst_rotation) * kDegPerRad;
      out.sigma_translation_m = sigma.tail<3>().maxCoeff(&worst_translation);
      if (out.poses >= params.min_poses && out.inliers >= static_cast<size_t>(params.min_arm_samples) &&
          out.residual_rms_m <= params.max_residual_rms_m &&
          (out.sigma_translation_m > params.max_sigma_translation_m ||
           out.sigma_rotation_deg > params.max_sigma_rotation_deg)) {
        out.problem = "the poses do not pin the camera down: its " +
                      (out.sigma_rotation_deg > params.max_sigma_rotation_deg
                           ? "rotation about its " + std::string(axis_name(worst_rotation)) + " axis varies by " +
                                 fixed_digits_text(out.sigma_rotation_deg, 3) + " deg (at most " +
                                 fixed_digits_text(params.max_sigma_rotation_deg, 3) + ")"
                           : "position along its " + std::string(axis_name(worst_translation)) + " axis varies by " +
                                 fixed_digits_text(out.sigma_translation_m * 1000.0, 2) + " mm (at most " +
                                 fixed_digits_text(params.max_sigma_translation_m * 1000.0, 2) + ")") +
                      " between groups of poses; sweep the arm through more of the workspace, in depth and across "
                      "the image" + sweep_hint;
      }
    } else if (out.poses >= params.min_poses) {
      out.problem = "only " + std::to_string(seen) + " poses show the arm; the spread needs at least " +
                    std::to_string(groups) + sweep_hint;
    }
  }
  // The refusals, the most basic first: each names what to change.
  if (out.poses < params.min_poses) {
    out.problem = "the arm was seen in " + std::to_string(out.poses) + " distinct pose(s) (" +
                  std::to_string(samples.keyframes().size()) + " keyframes from " + std::to_string(samples.frames()) +
                  " frames), at least " + std::to_string(params.min_poses) + " with " + std::to_string(min_per_pose) +
                  " arm samples each are needed: an arm held still is part of the farthest-depth background and "
                  "cannot constrain the camera's six degrees of freedom; move it through the sweep" +
                  sweep_hint;
  } else if (out.inliers < static_cast<size_t>(params.min_arm_samples)) {
    out.problem = "only " + std::to_string(out.inliers) + " arm samples lie within " +
                  fixed_digits_text(params.inlier_gate_m * 1000.0, 0) + " mm of the arm's shapes (at least " +
                  std::to_string(params.min_arm_samples) + " needed): bring the arm nearer the camera or into view" +
                  sweep_hint;
  } else if (out.residual_rms_m > params.max_residual_rms_m) {
    out.problem = "the arm's pixels lie " + fixed_digits_text(out.residual_rms_m * 1000.0, 1) +
                  " mm RMS from its shapes (at most " + fixed_digits_text(params.max_residual_rms_m * 1000.0, 1) +
                  " mm): a wrong robot.model or base_frame, a tool or dress pack that is not described, or a told "
                  "pose beyond the coarse alignment's reach (0.2 m, 15 deg)";
  }
  out.ok = out.problem.empty();
  return out;
}

}  // namespace hrcsense
