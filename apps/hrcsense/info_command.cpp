// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense info`: what a configured source would deliver.
#include "common/app_errors.hpp"
#include "commands.hpp"

#include "common/assembly.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace hrcsense::app {
namespace {

void print_scene(const Scene& scene) {
  std::printf("scene: %zu object(s)\n", scene.objects.size());
  for (const SceneObject& object : scene.objects) {
    std::string when;
    if (!object.is_static) {
      when = ", frames " + std::to_string(object.first_frame) + "-" +
             (object.last_frame < 0 ? std::string("end") : std::to_string(object.last_frame));
      if (!object.path.empty()) when += ", " + std::to_string(object.path.size()) + " waypoint(s)";
    }
    std::printf("  %s: %s%s, %zu shape(s)\n", object.name.c_str(), object.is_static ? "static" : "moving",
                when.c_str(), object.shapes.size());
  }
}

// The D435 effects in force (docs/SIMULATOR.md) and the fill rate they give this scene.
void print_sensor_effects(const Simulator& simulator) {
  const SimParams& p = simulator.params;
  const Intrinsics in = simulator.intrinsics();
  const double fxb_px_m = static_cast<double>(in.fx) * p.baseline_mm * 1e-3;
  const double min_range_m = p.min_range_m > 0.0F ? p.min_range_m
                             : p.max_disparity_px > 0.0F ? fxb_px_m / p.max_disparity_px
                                                        : 0.0;
  std::printf("stereo: left band %s, occlusion shadows %s, minimum range %.3f m\n", p.left_band ? "on" : "off",
              p.occlusion_shadows ? "on" : "off", min_range_m);
  // Only where set (structured light), so that a D435's lines read as before.
  if (p.max_range_m > 0.0F) {
    std::printf("working range: %.3f-%.3f m, far dropouts up to %.0f %% from %.3f m (new every frame)\n", min_range_m,
                static_cast<double>(p.max_range_m), 100.0 * p.range_dropout, static_cast<double>(p.range_dropout_start_m));
  }
  if (p.noise && p.edge_flicker > 0.0F) {
    std::printf("edge flicker: %.0f %% of the edge pixels with depth take the other side's, new every frame\n",
                100.0 * p.edge_flicker);
  }
  if (p.noise) {
    std::printf("dropouts: edges %.0f %%, flying pixels %.0f %%, speckle %.2f %%, dark %.0f %%, shiny %.0f %%, "
                "low texture %.0f %%; disparity step 1/%.0f px, correlated sigma %.3f px\n",
                100.0 * p.edge_dropout, 100.0 * p.flying_pixels, 100.0 * p.speckle, 100.0 * p.dark_dropout,
                100.0 * p.shiny_dropout, 100.0 * p.low_texture_dropout,
                p.disparity_step_px > 0.0F ? 1.0 / p.disparity_step_px : 0.0,
                static_cast<double>(p.correlated_noise_px));
  }
  // Valid pixels / pixels in the image over the first frames (the Depth Quality Tool's fill rate).
  const int64_t frames = std::min<int64_t>(p.frames, 10);
  std::printf("fill rate: %.1f %% (frames 0-%lld)\n", 100.0 * sim_fill_rate(simulator, 0, frames),
              static_cast<long long>(frames - 1));
}

int print_sim(const Config& config) {
  const Simulator simulator = make_simulator(config);
  const SimParams& sim = simulator.params;
  const Intrinsics in = simulator.intrinsics();
  std::printf("source: sim (seed %llu), %s\n", static_cast<unsigned long long>(sim.seed), config_where(config).c_str());
  std::printf("sensor: %s\n", sim_sensor_name(sim.sensor));
  std::printf("resolution: %dx%d at %.3g frames/s\n", in.width, in.height, sim.fps);
  std::printf("intrinsics: fx=%.4f fy=%.4f ppx=%.4f ppy=%.4f model=%s\n", static_cast<double>(in.fx),
              static_cast<double>(in.fy), static_cast<double>(in.ppx), static_cast<double>(in.ppy),
              std::string(distortion_name(in.model)).c_str());
  if (sim.noise) {
    std::printf("noise: stereo, disparity sigma %.3f px, baseline %.3f mm, depth quantised to %.3g mm\n",
                static_cast<double>(sim.disparity_noise_px), static_cast<double>(sim.baseline_mm),
                static_cast<double>(sim.depth_scale_m) * 1000.0);
  } else {
    std::printf("noise: none (exact depth quantised to %.3g mm)\n", static_cast<double>(sim.depth_scale_m) * 1000.0);
  }
  std::printf("frames: %lld (%.3f s)\n", static_cast<long long>(sim.frames), static_cast<double>(sim.frames) / sim.fps);
  print_sensor_effects(simulator);
  print_scene(config.scene);
  std::printf("robot: %s, %zu capsule(s)\n", robot_model_name(config.robot_model),
              fixed_robot_model(config).capsules.size());
  std::printf("config hash: %s\n", config_hash(config).c_str());
  return 0;
}

// A recording (.bag file or folder): what summarize_recording found, one line per fact.
int print_recording(const std::string& path) {
  const RecordingSummary s = summarize_recording(path);
  std::printf("recording: %s\n", s.path.c_str());
  std::printf("format: %s", recording_format_text(s).c_str());
  if (s.format == RecordingFormat::bag) {
    std::printf(" (%s, file version %d)", s.indexed ? "indexed" : "no usable index, scanned", s.file_version);
  }
  std::printf("\ncompression: %s\n", s.compression.c_str());
  for (const RecordingStream& stream : s.streams) {
    const Intrinsics& in = stream.intrinsics;
    const std::string size = in.width > 0 ? std::to_string(in.width) + "x" + std::to_string(in.height) : "size unknown";
    std::printf("stream %s: %s %s, %lld frame(s)", stream.name.c_str(), size.c_str(), stream.encoding.c_str(),
                static_cast<long long>(stream.frames));
    if (stream.last_ns > stream.first_ns) {
      std::printf(", %.3f s", static_cast<double>(stream.last_ns - stream.first_ns) * 1e-9);
    } else {
      std::printf(", duration unknown");
    }
    if (stream.fps > 0) std::printf(", stated %u frames/s", stream.fps);
    if (in.fx > 0.0F) {
      std::printf(", fx=%.4f fy=%.4f ppx=%.4f ppy=%.4f model=%s", static_cast<double>(in.fx),
                  static_cast<double>(in.fy), static_cast<double>(in.ppx), static_cast<double>(in.ppy),
                  std::string(distortion_name(in.model)).c_str());
    }
    std::printf("\n");
  }
  std::printf("depth units: %g m\n", static_cast<double>(s.depth_units_m));
  if (s.stereo_baseline_mm > 0.0F) std::printf("stereo baseline: %.3f mm\n", static_cast<double>(s.stereo_baseline_mm));
  if (s.T_color_depth) {
    const Eigen::Vector3d t = s.T_color_depth->translation();
    const Eigen::Quaterniond q(s.T_color_depth->linear());
    std::printf("extrinsics depth->color: t=[%.6f, %.6f, %.6f] m, q(xyzw)=[%.7f, %.7f, %.7f, %.7f]\n", t.x(), t.y(),
                t.z(), q.x(), q.y(), q.z(), q.w());
  }
  std::fflush(stdout);
  if (!s.damage.empty()) return report_error("damaged recording: " + s.damage, kExitRuntime);
  return 0;
}

// The background a `run` of this configuration starts with, and how much of it is unknown
// (never measured, or moving far from the robot while learnt): loaded from background.path
// when that file exists, else learnt from the source's first frames as `run` learns it (same
// filters; motion judged near the robot at its fixed or simulated state). A live robot state
// (rtde, udp_json, ros2) is not connected to from `info`: learning then judges motion everywhere,
// which can only refuse more batches than `run` would. At most `max_frames` frames (-1: until
// the source ends); nothing is saved.
void print_background(const Config& config, int64_t max_frames) {
  std::unique_ptr<Source> source = make_source(config);
  const SourceInfo info = source->info();
  Pipeline pipeline(config.pipeline);
  const auto print_share = [&pipeline](const char* what) {
    const BackgroundModel& model = pipeline.background();
    const size_t pixels = model.mean_m.size();
    const auto unknown = std::count_if(model.mean_m.begin(), model.mean_m.end(), [](float m) { return !(m > 0.0F); });
    std::printf("background: %s, %dx%d; unknown_background_share %.4f (%lld of %zu px; %zu unsettled)\n", what,
                model.width, model.height, pipeline.unknown_background_share(), static_cast<long long>(unknown),
                pixels, pipeline.unsettled_background_pixels());
  };
  if (load_background_file(config, info, pipeline)) {
    print_share(("loaded from " + config.background_path).c_str());
    return;
  }
  const RobotStateOrigin state_source = config.robot_state.source;
  const bool placed = state_source == RobotStateOrigin::fixed || state_source == RobotStateOrigin::sim;
  std::unique_ptr<RobotStateSource> robot_states = placed ? make_robot_state_source(config) : nullptr;
  Frame frame;
  FrameResult result;
  RobotState state;
  int64_t frames = 0;
  int64_t learnt = 0;  // frames the learner took (a frame with too little valid depth is not learnt)
  while ((max_frames < 0 || frames < max_frames) && !pipeline.background_ready()) {
    if (source->next(frame) != Source::Status::frame) break;
    // As run_pipeline for unpaced fixed and sim states: the robot state at the source time.
    state = RobotState{};
    if (robot_states) robot_states->state_at(frame.timestamp_ns, state);
    pipeline.process(frame, state, result);
    ++frames;
    learnt += result.withheld_code == ReasonCode::learning_background ? 1 : 0;
  }
  if (!placed) {
    std::printf("background: robot.state.source %s not connected: motion counted everywhere\n",
                robot_state_origin_name(state_source));
  }
  // Every refused batch is background.frames learnt frames (a change of image size, which also
  // restarts, cannot happen within one source).
  const int64_t batch = std::max(config.pipeline.background.frames, 1);
  const std::string& message = pipeline.background_message();
  if (!pipeline.background_ready()) {
    std::printf("background: not learnt in %lld frame(s), %lld batch(es) refused%s%s\n", static_cast<long long>(frames),
                static_cast<long long>(learnt / batch), message.empty() ? "" : "; last: ", message.c_str());
    return;
  }
  char what[96];
  std::snprintf(what, sizeof what, "learnt by frame %lld (%lld batch(es) refused before)",
                static_cast<long long>(frame.index), static_cast<long long>(learnt / batch - 1));
  print_share(what);
}

// A live camera's identity and stream, as it reports them.
void print_live_source(SourceType type, const SourceInfo& info) {
  if (type == SourceType::realsense) {
    std::printf("source: realsense, %s (serial %s, firmware %s)\n", info.camera_name.c_str(),
                info.camera_serial.c_str(), info.camera_firmware.c_str());
  } else {
    std::printf("source: %s, %s\n", source_type_name(type), info.description.c_str());
  }
  std::printf("resolution: %dx%d at %.3g frames/s\n", info.intrinsics.width, info.intrinsics.height,
              info.nominal_fps);
  std::printf("intrinsics: fx %.3f fy %.3f ppx %.3f ppy %.3f\n", info.intrinsics.fx, info.intrinsics.fy,
              info.intrinsics.ppx, info.intrinsics.ppy);
}

}  // namespace

int info_command(const CommandArgs& args) {
  if (!args.input.empty() && args.config_path.empty()) {
    // A path that is not there is a mistake on the command line, not damaged data.
    if (!std::filesystem::exists(args.input)) {
      return report_error(args.input + ": no such recording (expected a .bag file or a folder)", kExitUsage);
    }
    // A FIFO or a device would block the reader forever: refuse it before opening.
    if (!std::filesystem::is_directory(args.input) && !not_regular_file(args.input).empty()) {
      return report_error(args.input + ": " + not_regular_file(args.input) + " (expected a .bag file or a folder)",
                          kExitUsage);
    }
    return print_recording(args.input);
  }
  const Config config = load_config(args.config_path, args.sets);
  if (is_recording(config.source.type)) {
    if (config.source.path.empty()) make_source(config);  // throws: source.path is required
    const int status = print_recording(config.source.path);
    if (status == 0) print_background(config, args.frames);
    return status;
  }
  if (config.source.type == SourceType::realsense || config.source.type == SourceType::ros2) {
    // Without the SDK or DDS: the ConfigError saying so. With it: what the camera reports (a
    // ros2 camera once its first depth CameraInfo has come).
    print_live_source(config.source.type, make_source(config)->info());
    return 0;
  }
  const int status = print_sim(config);
  std::fflush(stdout);
  if (status == 0) print_background(config, args.frames);
  return status;
}

}  // namespace hrcsense::app
