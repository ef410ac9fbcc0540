// SPDX-License-Identifier: Apache-2.0
// hrcsense — the Pipeline's checks that withhold a frame: background, camera, robot state and the reference check.

#include "hrcsense/pipeline.hpp"

#include "pipeline_detail.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

namespace hrcsense {
namespace {

using pipeline_detail::timed_stage;
using pipeline_detail::withhold;

bool same_size(const BackgroundModel& model, const DepthImage& depth) {
  return model.width == depth.width && model.height == depth.height;
}

}  // namespace

// The distance is taken over every pose the robot had while the batch was learnt: a person
// within reach of the arm at any of them counts, wherever the arm stands when learning ends.
void Pipeline::check_reference(const Frame& frame, const RobotPixels* robot_pixels) {
  ReferenceCheck& check = reference_check_;
  check.foreground = params_.foreground;
  check.detection_mm = params_.safety.ssm.detection_mm;
  check.max_distance_m = reference_distance_m();
  reference_finding_ = check.compare(learner_.model(), frame, params_.T_base_camera, learning_poses_, robot_pixels);
  not_empty_ = reference_finding_.found;
  if (!not_empty_) return;
  const ReferenceFinding& f = reference_finding_;
  char where[160];
  if (std::isfinite(f.distance_m)) {
    std::snprintf(where, sizeof where, "%.2f m from the robot (limit %.2f m)", static_cast<double>(f.distance_m),
                  static_cast<double>(check.max_distance_m));
  } else {
    std::snprintf(where, sizeof where, "distance to the robot unknown (no robot state while learning)");
  }
  char text[512];
  std::snprintf(text, sizeof text,
                "background not empty: %d object(s) nearer than %s; nearest at pixels u %d..%d, v %d..%d of the "
                "%dx%d filtered image, %.2f m from the camera, %.0f mm across, %s; clear the cell, learning goes on",
                f.blobs, reference_origin_.c_str(), f.u_min, f.u_max, f.v_min, f.v_max, frame.depth.width,
                frame.depth.height, static_cast<double>(f.depth_m), static_cast<double>(f.size_mm), where);
  not_empty_reason_.assign(text);
  learner_.refuse(not_empty_reason_);
}

void Pipeline::withhold_not_empty(Measurement& m) const {
  withhold(m, ReasonCode::background_not_empty, not_empty_reason_.c_str());
  char progress[64];
  std::snprintf(progress, sizeof progress, " (%d/%d frames)", learner_.frames_seen(), learner_.params.frames);
  m.withheld_reason.append(progress);
}

void Pipeline::set_reference(BackgroundModel reference, std::string origin) {
  reference_check_.set_reference(std::move(reference));
  reference_origin_ = std::move(origin);
  not_empty_ = false;
}

float Pipeline::reference_distance_m() const {
  const SafetyParams& safety = params_.safety;
  if (safety.mode != SafetyParams::Mode::ssm) return safety.slow_distance_m;
  SsmInput at_rest;
  // Beyond human_near_m: the walking speed, as for a frame without foreground. A blob nearer
  // than human_near_m is within this distance anyway.
  at_rest.distance_m = std::numeric_limits<float>::max();
  at_rest.frame_age_s = 0.0;
  return protective_distance(safety.ssm, at_rest, 0.0F).protective_distance_m;
}

bool Pipeline::background_usable(const Frame& frame, Measurement& m) {
  if (!same_size(background(), frame.depth)) {
    withhold(m, ReasonCode::background_mismatch, "background size mismatch");
    return false;
  }
  return background_checked(frame, m) && camera_sees_the_cell(frame, m);
}

// The robot's capsules at the frame's state; a missing, stale or non-finite state withholds.
bool Pipeline::robot_placed(const RobotState& robot_state, Measurement& m) {
  if (!robot_state.valid || !all_finite(robot_state.q_rad)) self_filter_.clear_poses();  // its poses are history
  if (!robot_state.valid) {
    // A state with a sample time had samples that are now too old; one without never had any.
    if (robot_state.sample_time_ns > 0) {
      char text[64];
      std::snprintf(text, sizeof text, "robot state stale (%.1f ms old)", m.robot_state_age_ms);
      withhold(m, ReasonCode::robot_state_stale, text);
    } else {
      withhold(m, ReasonCode::no_robot_state, "no robot state");
    }
    return false;
  }
  if (!all_finite(robot_state.q_rad)) {
    withhold(m, ReasonCode::non_finite_input, "non-finite joint angle in the robot state");
    return false;
  }
  robot_model_at(params_.robot, robot_state.q_rad, robot_);
  if (robot_.capsules.empty()) {
    withhold(m, ReasonCode::no_robot_model, "no robot model");
    return false;
  }
  return true;
}

// A person next to the arm may hide in depth the camera cannot measure there.
bool Pipeline::envelope_seen(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m) {
  if (robot_pixels == nullptr) return true;
  const EnvelopeCount envelope = envelope_invalid(frame.depth, background(), robot_pixels);
  if (!(envelope.share() > params_.checks.max_envelope_invalid_share)) return true;
  char text[96];
  std::snprintf(text, sizeof text, "%.0f %% of the robot's envelope without depth (max_envelope_invalid_share %.2f)",
                100.0 * envelope.share(), static_cast<double>(params_.checks.max_envelope_invalid_share));
  withhold(m, ReasonCode::envelope_invalid, text);
  return false;
}

// The arm's visual shapes at the frame's joints, seen from the told pose, against the filtered
// depth. Without an arm, with the check off or without a usable state (no_robot_state and the
// others stop then anyway) it says nothing; a frame without enough of the arm in view neither
// fires nor clears it (PoseCheck::add).
bool Pipeline::camera_pose_agrees(const Frame& frame, const RobotState& robot_state, Measurement& m) {
  if (!params_.robot.arm || !params_.pose_check.enabled) return true;
  if (!robot_state.valid || !all_finite(robot_state.q_rad)) return true;
  timed_stage(m, "pose_check", [&] {
    robot_render_capsules(*params_.robot.arm, robot_state.q_rad, params_.robot.base_frame, visual_);
    const PoseDisagreement now = pose_disagreement(params_.pose_check, frame.depth, frame.intrinsics,
                                                   params_.T_base_camera, visual_, pose_shapes_,
                                                   frame.stereo_baseline_mm * 1e-3F);
    pose_check_.params = params_.pose_check;
    pose_check_.add(now);
  });
  return !pose_check_.mismatch() || withhold_pose(m);
}

// Always false, so that a caller can return it.
bool Pipeline::withhold_pose(Measurement& m) const {
  char text[200];
  std::snprintf(text, sizeof text,
                "the arm is seen %.2f cm off its shapes beyond the depth noise on average over %d frames "
                "(pose_check_threshold_m %.4f): "
                "camera pose mismatch, check camera.T_base_camera",
                100.0 * static_cast<double>(pose_check_.window_mean_m()), params_.pose_check.window_frames,
                static_cast<double>(params_.pose_check.threshold_m));
  withhold(m, ReasonCode::camera_pose_mismatch, text);
  return false;
}

// A large surface right in front of the lens, or the static scene seen farther than it was
// learnt at the sparse reference pixels (the camera was knocked or moved): the background no
// longer describes what the camera sees, so nothing it says can be trusted.
bool Pipeline::camera_sees_the_cell(const Frame& frame, Measurement& m) {
  const CellCheckParams& checks = params_.checks;
  const float blocked = blocked_share(checks, frame.depth, background());
  if (blocked >= checks.blocked_share) {
    char text[96];
    std::snprintf(text, sizeof text, "%.0f %% of the image nearer than %.2f m: camera blocked", 100.0 * blocked,
                  static_cast<double>(checks.blocked_depth_m));
    withhold(m, ReasonCode::camera_blocked, text);
    return false;
  }
  if (!moved_reference_ready_) {
    moved_reference_ = moved_reference_pixels(checks, background());
    moved_reference_ready_ = true;
  }
  const MovedCount moved = moved_count(checks, frame.depth, background(), moved_reference_);
  if (moved.valid >= checks.moved_min_valid && moved.share() >= checks.moved_share) {
    char text[112];
    std::snprintf(text, sizeof text, "%.0f %% of %zu reference pixels farther than the background: camera moved",
                  100.0 * moved.share(), moved.valid);
    withhold(m, ReasonCode::camera_moved, text);
    return false;
  }
  return true;
}

// A background loaded from a file is compared with the first frames before it is trusted
// (BackgroundCheck); those frames are stops. A mismatch ends the run with an error.
bool Pipeline::background_checked(const Frame& frame, Measurement& m) {
  if (!preset_background_ || check_.done()) return true;
  const int seen = check_.add(preset_model_, frame.depth);
  if (check_.done() && check_.mismatch()) {
    char text[256];
    std::snprintf(text, sizeof text,
                  ": does not match the scene: %.1f %% of its reliable pixels are measured farther than it in "
                  "the first %d frames (at most %.1f %% allowed); the camera moved or the file is another "
                  "cell's: delete it to learn a new one",
                  100.0 * check_.farther_share(), seen, 100.0 * static_cast<double>(check_.max_farther_share));
    throw BackgroundMismatch(preset_origin_ + text);
  }
  char text[64];
  std::snprintf(text, sizeof text, "checking loaded background (%d/%d frames)", seen, check_.frames);
  withhold(m, ReasonCode::checking_background, text);
  return false;
}

}  // namespace hrcsense
