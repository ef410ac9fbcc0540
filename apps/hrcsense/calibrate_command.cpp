// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense calibrate --config FILE --out POSE.yaml`: the camera's pose from the
// arm's own depth while it sweeps the workspace (docs/CALIBRATION.md). Reads the configured
// source and its joint states as `hrcsense record` does (live, a recording with joint states,
// the simulator), fits every kCheckEveryKeyframes keyframes once the background has settled,
// and stops when two fits in a row agree or the source ends.
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "common/cell.hpp"
#include "common/record_setup.hpp"
#include "common/stop_signals.hpp"

#include "hrcsense/calibration.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/number_text.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

namespace hrcsense::app {
namespace {

// A fit is tried after this many new keyframes (a new one each 2 cm of arm motion: 0.8 m)...
constexpr int kCheckEveryKeyframes = 40;
// ...once fewer than this share of the grid's samples found a farther background since the
// last try (the sweep is still uncovering the background behind the arm's first poses).
constexpr double kSettledBackgroundShare = 0.002;
// Two fits in a row this close: the estimate has converged.
constexpr double kConvergedTranslationM = 0.0005;
constexpr double kConvergedRotationDeg = 0.01;

std::string vec3_text(const Eigen::Vector3d& v, int digits) {
  return "[" + fixed_digits_text(v.x(), digits) + ", " + fixed_digits_text(v.y(), digits) + ", " +
         fixed_digits_text(v.z(), digits) + "]";
}

// CONFIG.md's convention, R = Rz(yaw)·Ry(pitch)·Rx(roll), read back from the matrix.
Eigen::Vector3d rpy_deg(const Pose& pose) {
  const Eigen::Matrix3d R = pose.rotation();
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw) * (180.0 / 3.14159265358979323846);
}

void write_pose(const std::string& path, const std::string& config_path, const CameraCalibration& fit,
                const ArmSamples& samples) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream out(path);
  out << "# hrcsense calibrate --config " << config_path << ": " << samples.frames() << " frames, "
      << samples.keyframes().size() << " keyframes, " << fit.poses << " poses with the arm, " << fit.inliers
      << " arm samples (docs/CALIBRATION.md)\n"
      << "camera:\n  T_base_camera: {translation_m: " << vec3_text(fit.T_base_camera.translation(), 6)
      << ", rotation_rpy_deg: " << vec3_text(rpy_deg(fit.T_base_camera), 5) << "}\n"
      << "residual_rms_m: " << fixed_digits_text(fit.residual_rms_m, 6) << "\n"
      << "sigma_translation_m: " << fixed_digits_text(fit.sigma_translation_m, 6) << "\n"
      << "sigma_rotation_deg: " << fixed_digits_text(fit.sigma_rotation_deg, 5) << "\n";
  out.flush();
  if (!out) throw std::runtime_error(path + ": cannot write the calibration");
}

}  // namespace

int calibrate_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets);
  const std::string where = args.config_path.empty() ? "<defaults>" : args.config_path;
  if (!config.pipeline.robot.arm) {
    throw ConfigError(where + ": key 'robot.model': calibrate needs an arm (ur5, ur5e, ur10e or custom); points have "
                              "no body to see");
  }
  CellOptions options;
  options.measure = false;
  options.unpaced = true;
  options.follow_link = false;
  options.stop_requested = &StopSignals::flag();
  const std::unique_ptr<Cell> cell = assemble_cell(config, options);
  Source& source = *cell->source;
  const SourceInfo info = source.info();
  std::unique_ptr<RobotStateSource> own_states;
  const RecordStateLookup lookup = record_state_lookup(config, source, *cell->robot_states, false, own_states);

  ArmSamples samples(config.calibration, info.intrinsics, *config.pipeline.robot.arm, config.pipeline.robot.base_frame);
  const Pose& T_told = config.pipeline.T_base_camera;
  spdlog::info("calibrate: reading {} ({}x{}) with robot.state.source {}; move the arm through its sweep",
               info.type, info.intrinsics.width, info.intrinsics.height,
               robot_state_origin_name(cell->robot_states->origin()));

  std::optional<StopSignals> signals(std::in_place);
  Frame frame;
  int64_t frames = 0;
  int64_t without_joints = 0;
  int new_keyframes = 0;
  std::string source_error;
  std::optional<CameraCalibration> last;
  bool converged = false;
  const auto settled_changes =
      static_cast<int64_t>(kSettledBackgroundShare * static_cast<double>(samples.farthest().size()));
  while (!StopSignals::stop_requested() && (args.frames < 0 || frames < args.frames)) {
    const Source::Status status = source.next(frame);
    if (status == Source::Status::end) break;
    if (status == Source::Status::idle) continue;
    if (status == Source::Status::error) {
      source_error = source.error();
      break;
    }
    ++frames;
    const std::optional<RobotState> state = robot_state_for_recording(frame, lookup);
    if (!state) {
      ++without_joints;
      continue;
    }
    if (!samples.add(frame.index, frame.depth, state->q_rad, frame.stereo_baseline_mm)) continue;
    if (++new_keyframes < kCheckEveryKeyframes) continue;
    new_keyframes = 0;
    if (samples.take_background_changes() > settled_changes) continue;
    // The progress fits skip the spread; the final one below computes it.
    const CameraCalibration fit = calibrate_camera(samples, last && last->ok ? last->T_base_camera : T_told, false);
    spdlog::info("calibrate: frame {}, {} keyframes: {} (residual {:.1f} mm over {} arm samples in {} poses)",
                 frame.index, samples.keyframes().size(), fit.ok ? "fitted" : "not yet: " + fit.problem,
                 fit.residual_rms_m * 1000.0, fit.inliers, fit.poses);
    converged = fit.ok && last && last->ok &&
                translation_between_m(fit.T_base_camera, last->T_base_camera) < kConvergedTranslationM &&
                rotation_between_deg(fit.T_base_camera, last->T_base_camera) < kConvergedRotationDeg;
    last = fit;
    if (converged) break;
  }
  const bool stopped_by_signal = StopSignals::stop_requested();
  signals.reset();
  if (!source_error.empty()) {
    // A source that failed before the arm was seen leaves nothing to fit: its error is the answer.
    if (samples.keyframes().empty()) return report_error("calibrate: " + source_error, kExitRuntime);
    spdlog::warn("calibrate: the source ended with an error: {}", source_error);
  }
  if (without_joints > 0) {
    spdlog::warn("calibrate: {} of {} frames had no joint state and were not used", without_joints, frames);
  }
  // The final fit over everything read, with its spread: from the converged pose, or from the
  // told one when the source ended first.
  const CameraCalibration fit = calibrate_camera(samples, converged ? last->T_base_camera : T_told);
  if (!fit.ok) {
    return report_error("calibrate: refused after " + std::to_string(frames) + " frames: " + fit.problem +
                            "; nothing written to " + args.out,
                        kExitRuntime);
  }
  write_pose(args.out, where, fit, samples);
  std::string ended = "source ended";
  if (converged) {
    ended = "converged";
  } else if (stopped_by_signal) {
    ended = "stopped by a signal";
  } else if (args.frames >= 0 && frames >= args.frames) {
    ended = "--frames reached";
  } else if (!source_error.empty()) {
    ended = "source failed";
  }
  const Eigen::Vector3d t = fit.T_base_camera.translation();
  const Eigen::Vector3d rpy = rpy_deg(fit.T_base_camera);
  std::printf("camera pose written to %s (%s after %lld frames): residual %.1f mm RMS over %zu arm samples in %d "
              "poses, spread %.2f mm and %.3f deg; %.1f mm and %.2f deg from the configured pose\n",
              args.out.c_str(), ended.c_str(), static_cast<long long>(frames),
              fit.residual_rms_m * 1000.0, fit.inliers, fit.poses, fit.sigma_translation_m * 1000.0,
              fit.sigma_rotation_deg, translation_between_m(fit.T_base_camera, T_told) * 1000.0,
              rotation_between_deg(fit.T_base_camera, T_told));
  std::printf("apply it with:\n  --set camera.T_base_camera.translation_m='%s' --set "
              "camera.T_base_camera.rotation_rpy_deg='%s'\n",
              vec3_text(t, 6).c_str(), vec3_text(rpy, 5).c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace hrcsense::app
