// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense info`: what a configured source would deliver.
#include "app_errors.hpp"
#include "commands.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/config.hpp"

#include <cstdio>
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

int print_sim(const Config& config) {
  const Simulator simulator = make_simulator(config);
  const SimParams& sim = simulator.params;
  const Intrinsics in = simulator.intrinsics();
  std::printf("source: sim (seed %llu)%s\n", static_cast<unsigned long long>(sim.seed),
              config.file.empty() ? "" : (", " + config.file).c_str());
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
  print_scene(config.scene);
  std::printf("robot: %s, %zu capsule(s)\n", config.robot_model.c_str(), config.pipeline.robot.capsules.size());
  std::printf("config hash: %s\n", config_hash(config).c_str());
  return 0;
}

}  // namespace

int info_command(const CommandArgs& args) {
  if (!args.input.empty() && args.config_path.empty()) {
    return report_error("cannot read recording '" + args.input +
                            "': source types in this build: sim; not yet available: folder, bag, realsense",
                        kExitUsage);
  }
  const Config config = load_config(args.config_path, args.sets);
  if (config.source.type != "sim") {
    make_source(config);  // throws the "not available in this build yet" error
  }
  return print_sim(config);
}

}  // namespace hrcsense::app
