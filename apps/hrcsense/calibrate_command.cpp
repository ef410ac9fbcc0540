// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense calibrate --config FILE --out POSE.yaml`: the camera's pose from the
// arm's own depth while it sweeps the workspace (docs/CALIBRATION.md). Reads the configured
// source and its joint states as `hrcsense record` does (live, a recording with joint states,
// the simulator), fits every kCheckEveryKeyframes keyframes once the background has settled,
// and stops when two fits in a row agree or the source ends. In a cell with several cameras,
// `--camera NAME` calibrates one `cameras:` entry and `--camera all` each in turn, then reports
// how the cameras agree on the arm; `--write-back` puts the poses into the file's entries.
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "common/cell.hpp"
#include "common/record_setup.hpp"
#include "common/stop_signals.hpp"

#include "hrcsense/calibration.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/number_text.hpp"
#include "hrcsense/robot.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

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

std::string pose_flow_text(const Pose& T) {
  return "{translation_m: " + vec3_text(T.translation(), 6) + ", rotation_rpy_deg: " +
         vec3_text(rotation_rpy_deg(T), 5) + "}";
}

// One camera's sweep and fit: `name` empty for the top-level camera of a one-camera cell.
struct CameraRun {
  std::string name;
  Pose T_told = Pose::Identity();
  std::optional<ArmSamples> samples;
  CameraCalibration fit;
  int64_t frames = 0;
  std::string ended;
  std::string source_error;  ///< set: the source failed before the arm was seen
};

std::string camera_label(const CameraRun& run) { return run.name.empty() ? std::string("camera") : run.name; }

// Reads the source until the fits converge, --frames, a signal or the source's end; then fits
// once more with the spread.
CameraRun sweep_and_fit(const Config& config, const CommandArgs& args, const std::string& name) {
  CameraRun run;
  run.name = name;
  run.T_told = config.pipeline.T_base_camera;
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

  run.samples.emplace(config.calibration, info.intrinsics, *config.pipeline.robot.arm, config.pipeline.robot.base_frame);
  ArmSamples& samples = *run.samples;
  spdlog::info("calibrate {}: reading {} ({}x{}) with robot.state.source {}; move the arm through its sweep",
               camera_label(run), info.type, info.intrinsics.width, info.intrinsics.height,
               robot_state_origin_name(cell->robot_states->origin()));

  std::optional<StopSignals> signals(std::in_place);
  Frame frame;
  int64_t without_joints = 0;
  int new_keyframes = 0;
  std::string source_error;
  std::optional<CameraCalibration> last;
  bool converged = false;
  const auto settled_changes =
      static_cast<int64_t>(kSettledBackgroundShare * static_cast<double>(samples.farthest().size()));
  while (!StopSignals::stop_requested() && (args.frames < 0 || run.frames < args.frames)) {
    const Source::Status status = source.next(frame);
    if (status == Source::Status::end) break;
    if (status == Source::Status::idle) continue;
    if (status == Source::Status::error) {
      source_error = source.error();
      break;
    }
    ++run.frames;
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
    const CameraCalibration fit = calibrate_camera(samples, last && last->ok ? last->T_base_camera : run.T_told, false);
    spdlog::info("calibrate {}: frame {}, {} keyframes: {} (residual {:.1f} mm over {} arm samples in {} poses)",
                 camera_label(run), frame.index, samples.keyframes().size(),
                 fit.ok ? "fitted" : "not yet: " + fit.problem, fit.residual_rms_m * 1000.0, fit.inliers, fit.poses);
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
    if (samples.keyframes().empty()) {
      run.source_error = source_error;
      return run;
    }
    spdlog::warn("calibrate {}: the source ended with an error: {}", camera_label(run), source_error);
  }
  if (without_joints > 0) {
    spdlog::warn("calibrate {}: {} of {} frames had no joint state and were not used", camera_label(run),
                 without_joints, run.frames);
  }
  // The final fit over everything read, with its spread: from the converged pose, or from the
  // told one when the source ended first.
  run.fit = calibrate_camera(samples, converged ? last->T_base_camera : run.T_told);
  run.ended = "source ended";
  if (converged) {
    run.ended = "converged";
  } else if (stopped_by_signal) {
    run.ended = "stopped by a signal";
  } else if (args.frames >= 0 && run.frames >= args.frames) {
    run.ended = "--frames reached";
  } else if (!source_error.empty()) {
    run.ended = "source failed";
  }
  return run;
}

std::string figures_text(const CameraRun& run) {
  return std::to_string(run.samples->frames()) + " frames, " + std::to_string(run.samples->keyframes().size()) +
         " keyframes, " + std::to_string(run.fit.poses) + " poses with the arm, " + std::to_string(run.fit.inliers) +
         " arm samples";
}

std::ofstream open_for_writing(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  return std::ofstream(path);
}

// The pose record of a one-camera cell (camera.T_base_camera and the fit's figures).
void write_pose(const std::string& path, const std::string& config_path, const CameraRun& run) {
  std::ofstream out = open_for_writing(path);
  out << "# hrcsense calibrate --config " << config_path << ": " << figures_text(run) << " (docs/CALIBRATION.md)\n"
      << "camera:\n  T_base_camera: " << pose_flow_text(run.fit.T_base_camera) << "\n"
      << "residual_rms_m: " << fixed_digits_text(run.fit.residual_rms_m, 6) << "\n"
      << "sigma_translation_m: " << fixed_digits_text(run.fit.sigma_translation_m, 6) << "\n"
      << "sigma_rotation_deg: " << fixed_digits_text(run.fit.sigma_rotation_deg, 5) << "\n";
  out.flush();
  if (!out) throw std::runtime_error(path + ": cannot write the calibration");
}

// The poses of named cameras as a `cameras:` list (a configuration fragment to merge into the
// cell's entries); the fit's figures are comments.
void write_camera_poses(const std::string& path, const std::string& config_path, const std::vector<CameraRun>& runs) {
  std::ofstream out = open_for_writing(path);
  out << "# hrcsense calibrate --config " << config_path << " (docs/CALIBRATION.md, \"Cells with several cameras\")\n";
  for (const CameraRun& run : runs) {
    out << "# " << run.name << ": " << figures_text(run) << "; residual_rms_m " << fixed_digits_text(run.fit.residual_rms_m, 6)
        << ", sigma_translation_m " << fixed_digits_text(run.fit.sigma_translation_m, 6) << ", sigma_rotation_deg "
        << fixed_digits_text(run.fit.sigma_rotation_deg, 5) << "\n";
  }
  out << "cameras:\n";
  for (const CameraRun& run : runs) {
    out << "  - name: " << run.name << "\n    T_base_camera: " << pose_flow_text(run.fit.T_base_camera) << "\n";
  }
  out.flush();
  if (!out) throw std::runtime_error(path + ": cannot write the calibration");
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw std::runtime_error(path + ": cannot read the configuration to write the poses back");
  return text.str();
}

// The first of PATH.bak, PATH.bak2, ... that does not exist: every write-back keeps the file it
// replaced.
std::string backup_path(const std::string& path) {
  for (int i = 1; i < 1000; ++i) {
    const std::string candidate = path + ".bak" + (i == 1 ? std::string() : std::to_string(i));
    if (!std::filesystem::exists(candidate)) return candidate;
  }
  throw std::runtime_error(path + ": 999 backups exist; remove some before writing the poses back");
}

// Writes the fitted poses into the configuration file's entries, keeping every other byte: the
// new text goes to a temporary file beside it, is read back with load_config and checked (each
// written entry's pose as fitted, every other entry's as before), the old file is kept as a
// backup, and the new one renamed over it. Returns the backup's path.
std::string write_back(const std::string& config_path, const std::vector<CameraRun>& runs) {
  const std::string old_text = read_text(config_path);
  std::string text = old_text;
  for (const CameraRun& run : runs) text = with_camera_pose_text(text, run.name, run.fit.T_base_camera, config_path);
  const std::string temporary = config_path + ".calibrate-new";
  {
    std::ofstream out(temporary, std::ios::binary);
    out << text;
    out.flush();
    if (!out) throw std::runtime_error(temporary + ": cannot write the configuration with the calibrated poses");
  }
  const Config before = load_config(config_path, {});
  const Config after = load_config(temporary, {});
  for (const CameraEntry& entry : after.cameras) {
    const auto fitted = std::find_if(runs.begin(), runs.end(), [&](const CameraRun& r) { return r.name == entry.name; });
    const auto old = std::find_if(before.cameras.begin(), before.cameras.end(),
                                  [&](const CameraEntry& e) { return e.name == entry.name; });
    const Pose& expected = fitted != runs.end() ? fitted->fit.T_base_camera : old->T_base_camera;
    // The written text's rounding: 1 µm and 1e-5 degrees.
    if (translation_between_m(entry.T_base_camera, expected) > 2e-6 ||
        rotation_between_deg(entry.T_base_camera, expected) > 1e-4) {
      std::filesystem::remove(temporary);
      throw std::runtime_error(config_path + ": the edited file does not read back camera '" + entry.name +
                               "' as expected; nothing written");
    }
  }
  const std::string backup = backup_path(config_path);
  std::filesystem::copy_file(config_path, backup);
  std::filesystem::rename(temporary, config_path);
  return backup;
}

// The agreement table over every pair of cameras with samples, for the configured poses and the
// calibrated ones (docs/CALIBRATION.md, "Cells with several cameras").
void print_agreement(const std::vector<CameraRun>& runs) {
  const AgreementParams params;
  std::printf("agreement on the arm (docs/CALIBRATION.md): per pair, how far apart the two cameras put the same link "
              "surfaces at nearby arm poses (keyframes paired within %.0f mm of the arm's travel), mm\n",
              params.pair_travel_m * 1000.0);
  std::printf("%-28s %6s %6s %9s %9s %12s %12s  %s\n", "pair", "pairs", "links", "points_a", "points_b", "configured",
              "calibrated", "worst link (calibrated)");
  for (size_t i = 0; i < runs.size(); ++i) {
    for (size_t j = i + 1; j < runs.size(); ++j) {
      const CameraRun& a = runs[i];
      const CameraRun& b = runs[j];
      const CameraAgreement told =
          camera_agreement(arm_views(*a.samples, a.T_told), arm_views(*b.samples, b.T_told), params);
      const bool fitted = a.fit.ok && b.fit.ok;
      const CameraAgreement calibrated =
          fitted ? camera_agreement(arm_views(*a.samples, a.fit.T_base_camera),
                                    arm_views(*b.samples, b.fit.T_base_camera), params)
                 : told;
      const std::string pair = a.name + "-" + b.name;
      spdlog::info("agreement {}: {} view pairs of {} and {} keyframes with arm points; the arm's shapes {:.1f} mm apart "
                   "between a pair's views at the median, {:.1f} mm at most; joints {:.3f} rad apart at most",
                   pair, calibrated.paired_views, calibrated.views_a, calibrated.views_b,
                   calibrated.pair_travel_median_m * 1000.0, calibrated.pair_travel_max_m * 1000.0,
                   calibrated.pair_joint_max_rad);
      if (calibrated.links.empty()) {
        std::printf("%-28s %6d %6s  no link seen by both at nearby arm poses\n", pair.c_str(), calibrated.paired_views,
                    "0");
        continue;
      }
      const auto worst = std::max_element(
          calibrated.links.begin(), calibrated.links.end(),
          [](const LinkAgreement& x, const LinkAgreement& y) { return x.disagreement_m < y.disagreement_m; });
      const std::string worst_text = link_name(worst->link) + " " + fixed_digits_text(worst->disagreement_m * 1000.0, 1);
      std::printf("%-28s %6d %6zu %9zu %9zu %12.1f %12s  %s\n", pair.c_str(), calibrated.paired_views,
                  calibrated.links.size(), calibrated.all.points_a, calibrated.all.points_b,
                  told.all.disagreement_m * 1000.0,
                  fitted ? fixed_digits_text(calibrated.all.disagreement_m * 1000.0, 1).c_str() : "-", worst_text.c_str());
      for (const LinkAgreement& link : calibrated.links) {
        spdlog::info("agreement {}: {} in {} view pairs, {} and {} points: offsets {} and {} mm, {:.1f} mm apart ({} axes)",
                     pair, link_name(link.link), link.views, link.points_a, link.points_b,
                     vec3_text(link.offset_a_base_m * 1000.0, 1), vec3_text(link.offset_b_base_m * 1000.0, 1),
                     link.disagreement_m * 1000.0, link.constrained_axes);
      }
    }
  }
}

// "<what> (converged after N frames): residual ..., spread ...; ... from the configured pose".
void print_result(const CameraRun& run, const std::string& what) {
  std::printf("%s (%s after %lld frames): residual %.1f mm RMS over %zu arm samples in %d poses, spread "
              "%.2f mm and %.3f deg; %.1f mm and %.2f deg from the configured pose\n",
              what.c_str(), run.ended.c_str(), static_cast<long long>(run.frames),
              run.fit.residual_rms_m * 1000.0, run.fit.inliers, run.fit.poses, run.fit.sigma_translation_m * 1000.0,
              run.fit.sigma_rotation_deg, translation_between_m(run.fit.T_base_camera, run.T_told) * 1000.0,
              rotation_between_deg(run.fit.T_base_camera, run.T_told));
}

// One camera of a one-camera cell: today's pose record and the --set lines that apply it.
int calibrate_single(const CommandArgs& args, const std::string& where) {
  if (args.out.empty()) throw ConfigError("calibrate: --out POSE.yaml is needed (--write-back takes --camera)");
  const Config config = load_config(args.config_path, args.sets);
  const CameraRun run = sweep_and_fit(config, args, "");
  if (!run.source_error.empty()) return report_error("calibrate: " + run.source_error, kExitRuntime);
  if (!run.fit.ok) {
    return report_error("calibrate: refused after " + std::to_string(run.frames) + " frames: " + run.fit.problem +
                            "; nothing written to " + args.out,
                        kExitRuntime);
  }
  write_pose(args.out, where, run);
  print_result(run, "camera pose written to " + args.out);
  std::printf("apply it with:\n  --set camera.T_base_camera.translation_m='%s' --set "
              "camera.T_base_camera.rotation_rpy_deg='%s'\n",
              vec3_text(run.fit.T_base_camera.translation(), 6).c_str(),
              vec3_text(rotation_rpy_deg(run.fit.T_base_camera), 5).c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace

int calibrate_command(const CommandArgs& args) {
  const Config top = load_config(args.config_path, args.sets);
  const std::string where = args.config_path.empty() ? "<defaults>" : args.config_path;
  if (!top.pipeline.robot.arm) {
    throw ConfigError(where + ": key 'robot.model': calibrate needs an arm (ur5, ur5e, ur10e or custom); points have "
                              "no body to see");
  }
  if (args.camera.empty()) {
    if (args.write_back) throw ConfigError("calibrate: --write-back needs --camera NAME or --camera all");
    return calibrate_single(args, where);
  }
  if (args.out.empty() && !args.write_back) {
    throw ConfigError("calibrate --camera: give --out POSES.yaml, --write-back or both");
  }
  if (args.write_back && args.config_path.empty()) throw ConfigError("calibrate: --write-back needs --config FILE");
  std::vector<std::string> names;
  if (args.camera == "all") {
    for (const CameraEntry& entry : top.cameras) names.push_back(entry.name);
    if (names.empty()) throw ConfigError(where + ": --camera all: the configuration has no cameras: list");
  } else {
    names.push_back(args.camera);
  }
  if (args.write_back) {
    // A form the edit cannot take is refused before the sweeps, not after them.
    const std::string text = read_text(args.config_path);
    for (const std::string& name : names) with_camera_pose_text(text, name, Pose::Identity(), args.config_path);
  }
  std::vector<CameraRun> runs;
  for (const std::string& name : names) {
    if (StopSignals::stop_requested()) break;
    runs.push_back(sweep_and_fit(load_config(args.config_path, args.sets, name), args, name));
    if (!runs.back().source_error.empty()) {
      return report_error("calibrate " + name + ": " + runs.back().source_error, kExitRuntime);
    }
  }
  if (runs.size() >= 2) print_agreement(runs);
  std::string refused;
  for (const CameraRun& run : runs) {
    if (!run.fit.ok) refused += "; " + run.name + ": " + run.fit.problem;
  }
  if (runs.size() != names.size()) refused += "; stopped by a signal before every camera was calibrated";
  if (!refused.empty()) {
    return report_error("calibrate: refused, nothing written" + refused, kExitRuntime);
  }
  std::string written_to;
  if (!args.out.empty()) {
    write_camera_poses(args.out, where, runs);
    written_to = "written to " + args.out;
  }
  if (args.write_back) {
    const std::string backup = write_back(args.config_path, runs);
    written_to += std::string(written_to.empty() ? "" : " and ") + "written back into " + args.config_path +
                  " (the old file kept as " + backup + ")";
  }
  for (const CameraRun& run : runs) print_result(run, run.name + ": calibrated");
  std::printf("%s\n", ("poses " + written_to).c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace hrcsense::app
