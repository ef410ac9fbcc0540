// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — the `hrcsense` executable: parses the command line and runs a subcommand.
#include "common/app_errors.hpp"
#include "commands.hpp"

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <exception>
#include <string>

namespace {

using hrcsense::app::CommandArgs;

constexpr int64_t kMaxFrames = 10'000'000'000;

// The flags every subcommand shares (DESIGN.md "Names other tools rely on").
void add_common_flags(CLI::App& command, CommandArgs& args) {
  command.add_option("--config", args.config_path, "YAML configuration file (docs/CONFIG.md)");
  command.add_option("--set", args.sets, "override a key, KEY=VALUE with VALUE in YAML (repeatable)")
      ->allow_extra_args(false);
  // Bounded so that a typo cannot ask for absurd preallocations: 10^10 frames are three
  // centuries at the D435's 90 frames/s.
  command.add_option("--frames", args.frames, "stop after N source frames, 1 to 10^10 (default: the source's length)")
      ->check(CLI::Range(int64_t{1}, kMaxFrames));
}

// The subcommands in the order `--help` lists them; CLI11's `app` owns them.
struct Subcommands {
  CLI::App* run = nullptr;
  CLI::App* fuse = nullptr;
  CLI::App* cell = nullptr;
  CLI::App* record = nullptr;
  CLI::App* publish = nullptr;
  CLI::App* echo = nullptr;
  CLI::App* info = nullptr;
  CLI::App* teach = nullptr;
  CLI::App* calibrate = nullptr;
  CLI::App* devices = nullptr;
  CLI::App* bench = nullptr;
  CLI::App* eval = nullptr;
  CLI::App* verify_filters = nullptr;
};

CLI::App* add_run_command(CLI::App& app, CommandArgs& args) {
  CLI::App* run = app.add_subcommand("run", "process a source and write JSON Lines (docs/OUTPUT.md)");
  add_common_flags(*run, args);
  run->add_option("--out", args.out, "JSON Lines output file (default: stdout)");
  run->add_option("--record", args.record, "also record the source's frames to this RealSense .bag (docs/RECORDINGS.md)");
  run->add_flag("--overwrite", args.overwrite, "with --record: replace an existing recording (never the source itself)");
  run->add_option("--camera", args.camera,
                  "measure one camera of the scene's cameras: and publish its measurements for `hrcsense fuse` "
                  "(docs/MULTICAMERA.md)");
  return run;
}

// `fuse` and `cell`: a cell with several cameras (docs/MULTICAMERA.md), flags as `run`'s.
CLI::App* add_fused_command(CLI::App& app, CommandArgs& args, const char* name, const char* help) {
  CLI::App* command = app.add_subcommand(name, help);
  add_common_flags(*command, args);
  command->add_option("--out", args.out, "JSON Lines output file (default: stdout)");
  return command;
}

CLI::App* add_record_command(CLI::App& app, CommandArgs& args) {
  CLI::App* record = app.add_subcommand("record", "record the configured source to a RealSense .bag (docs/RECORDINGS.md)");
  add_common_flags(*record, args);
  record->add_option("--out", args.out, "the .bag file (with record.split_mb: FILE-000.bag, ...)")->required();
  record->add_flag("--overwrite", args.overwrite, "replace an existing recording (never the source itself)");
  record->add_option("--camera", args.camera,
                     "record one camera of the scene's cameras: (its pose, source and sim settings; docs/MULTICAMERA.md)");
  // A day at most: longer recordings are split files of a service, not one command.
  record->add_option("--duration-s", args.duration_s, "stop after S seconds of source time, 0.001 to 86400")
      ->check(CLI::Range(0.001, 86400.0))
      ->excludes(record->get_option("--frames"));
  return record;
}

// `eval` has flags of its own (EvalArgs): a sweep spans rows, each with its own configuration.
CLI::App* add_eval_command(CLI::App& app, hrcsense::app::EvalArgs& eval_args) {
  CLI::App* eval = app.add_subcommand("eval", "the thesis's measures over sweeps, scenes and seeds (docs/EVALUATION.md)");
  eval->add_option("--config", eval_args.config_path, "the scene's configuration file when no --scene is given");
  eval->add_option("--set", eval_args.sets, "override a key in every row, KEY=VALUE (repeatable)")->allow_extra_args(false);
  eval->add_option("--sweep", eval_args.sweeps, "KEY=V1,V2,... or KEY=A:B[:STEP]; several span a grid (repeatable)")
      ->allow_extra_args(false);
  eval->add_option("--scene", eval_args.scenes, "a scene's configuration file (repeatable)")->allow_extra_args(false);
  eval->add_option("--seeds", eval_args.seeds, "run each row with source.seed 1..N, 1 to 1000")->check(CLI::Range(1, 1000));
  eval->add_option("--frames", eval_args.frames, "source frames per row, 1 to 10^10 (default: the source's length)")
      ->check(CLI::Range(int64_t{1}, kMaxFrames));
  eval->add_option("--jobs", eval_args.jobs, "rows at once, 1 to 64 (rates then say parallel)")->check(CLI::Range(1, 64));
  eval->add_option("--out", eval_args.out, "folder for results.csv, results.md and the figures")->required();
  eval->add_option("--study", eval_args.study,
                   "a ready-made study: table-4.1, table-4.2, table-4.3, table-4.4, moving-cell or thesis (all)");
  eval->add_option("--config-dir", eval_args.config_dir, "where a study finds its scenes (default: config)");
  eval->add_option("--report", eval_args.report, "with --study thesis: write the report here too (its figures beside it)");
  return eval;
}

CLI::App* add_echo_command(CLI::App& app, hrcsense::app::EchoArgs& echo_args) {
  CLI::App* echo = app.add_subcommand(
      "echo", "print the samples of one of hrcsense's ROS 2 topics (or /joint_states) as JSON lines (docs/ROS2.md)");
  echo->add_option("topic", echo_args.topic, "e.g. /hrcsense/verdict, /hrcsense/markers, /tf_static, /joint_states")
      ->required();
  echo->add_option("--domain", echo_args.domain, "DDS domain, 0 to 232 (default: ROS_DOMAIN_ID, else 0)")
      ->check(CLI::Range(0, 232));
  echo->add_option("--type", echo_args.type,
                   "verdict, speed_scaling, markers, point_cloud, tf, joint_state or float64 (default: from the topic)");
  echo->add_option("--count", echo_args.count, "exit after N samples")->check(CLI::Range(int64_t{1}, kMaxFrames));
  echo->add_option("--timeout-s", echo_args.timeout_s, "exit after S seconds")->check(CLI::Range(0.0, 86400.0));
  return echo;
}

// Every subcommand, added in the order `--help` lists them; `args`, `eval_args` and `echo_args`
// receive the parsed flags.
Subcommands add_subcommands(CLI::App& app, CommandArgs& args, hrcsense::app::EvalArgs& eval_args,
                            hrcsense::app::EchoArgs& echo_args) {
  Subcommands commands;
  commands.run = add_run_command(app, args);
  commands.fuse = add_fused_command(app, args, "fuse",
                                    "decide for a cell with several cameras from their measurements over DDS "
                                    "(docs/MULTICAMERA.md)");
  commands.cell = add_fused_command(app, args, "cell",
                                    "run a cell with several cameras on this host: a measuring process per camera "
                                    "and the fuser (docs/MULTICAMERA.md)");
  commands.record = add_record_command(app, args);
  commands.publish = app.add_subcommand(
      "publish", "publish the configured source as a realsense-ros camera's ROS 2 topics (docs/CAMERAS.md)");
  add_common_flags(*commands.publish, args);
  commands.echo = add_echo_command(app, echo_args);
  commands.info = app.add_subcommand("info", "describe a configured source or a recording");
  add_common_flags(*commands.info, args);
  commands.info->add_option("path", args.input, "a recording: a RealSense .bag file or a folder of depth PNGs");
  commands.teach = app.add_subcommand(
      "teach", "learn the background with the cell empty and write it for background.reference (docs/SAFETY.md)");
  add_common_flags(*commands.teach, args);
  commands.teach->add_option("--out", args.out, "the reference background file (the background.path format)")->required();
  commands.calibrate = app.add_subcommand(
      "calibrate", "the camera's pose from the arm's own depth while it sweeps the workspace (docs/CALIBRATION.md)");
  add_common_flags(*commands.calibrate, args);
  commands.calibrate->add_option("--out", args.out,
                                 "the pose file (camera.T_base_camera and the fit's figures; with --camera a cameras: "
                                 "list)");
  commands.calibrate->add_option("--camera", args.camera,
                                 "calibrate one camera of the scene's cameras:, or `all` in turn with their agreement "
                                 "on the arm (docs/CALIBRATION.md)");
  commands.calibrate->add_flag("--write-back", args.write_back,
                               "with --camera: write the poses into the --config file's entries (the old file kept "
                               "as FILE.bak)");
  commands.devices = app.add_subcommand("devices", "list the RealSense cameras connected and their depth profiles");
  commands.bench = app.add_subcommand("bench", "time the processing path on pre-rendered frames");
  add_common_flags(*commands.bench, args);
  commands.eval = add_eval_command(app, eval_args);
  commands.verify_filters =
      app.add_subcommand("verify-filters", "compare hrcsense's depth filters with RealSense SDK goldens");
  commands.verify_filters->add_option("cases", args.input, "cases.json of an SDK golden set")->required();
  commands.verify_filters->add_option("--shared", args.shared,
                                      "folder the cases' input paths are relative to (default ../shared)");
  return commands;
}

// CLI11 would only say "a subcommand is required" for a misspelt one; main names it instead.
bool is_unknown_command(const std::string& first) {
  return !first.empty() && first[0] != '-' && first != "run" && first != "fuse" && first != "cell" && first != "record" && first != "publish" &&
         first != "echo" && first != "info" && first != "devices" && first != "bench" && first != "verify-filters" &&
         first != "eval" && first != "teach" && first != "calibrate";
}

// Runs the one subcommand CLI11 parsed (require_subcommand(1)); `bench` is the one left.
int run_parsed_command(const Subcommands& commands, const CommandArgs& args, const hrcsense::app::EvalArgs& eval_args,
                       const hrcsense::app::EchoArgs& echo_args) {
  if (commands.run->parsed()) return hrcsense::app::run_command(args);
  if (commands.fuse->parsed()) return hrcsense::app::fuse_command(args);
  if (commands.cell->parsed()) return hrcsense::app::cell_command(args);
  if (commands.record->parsed()) return hrcsense::app::record_command(args);
  if (commands.publish->parsed()) return hrcsense::app::publish_command(args);
  if (commands.echo->parsed()) return hrcsense::app::echo_command(echo_args);
  if (commands.info->parsed()) return hrcsense::app::info_command(args);
  if (commands.teach->parsed()) return hrcsense::app::teach_command(args);
  if (commands.calibrate->parsed()) return hrcsense::app::calibrate_command(args);
  if (commands.devices->parsed()) return hrcsense::app::devices_command();
  if (commands.verify_filters->parsed()) return hrcsense::app::verify_filters_command(args);
  if (commands.eval->parsed()) return hrcsense::app::eval_command(eval_args);
  return hrcsense::app::bench_command(args);
}

}  // namespace

int main(int argc, char** argv) {
  // Logs go to stderr so that stdout carries only results.
  spdlog::set_default_logger(spdlog::stderr_color_mt("hrcsense"));
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  CLI::App app{"hrcsense: safety distances in a human-robot collaboration cell from a depth camera"};
  app.require_subcommand(1);
  CommandArgs args;
  hrcsense::app::EvalArgs eval_args;
  hrcsense::app::EchoArgs echo_args;
  const Subcommands commands = add_subcommands(app, args, eval_args, echo_args);

  if (is_unknown_command(argc > 1 ? argv[1] : "")) {
    return hrcsense::app::report_error(std::string("unknown command '") + argv[1] +
                                           "'; expected run, fuse, cell, record, publish, echo, info, teach, calibrate, devices, bench, eval or "
                                           "verify-filters",
                                       hrcsense::app::kExitUsage);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    return hrcsense::app::report_error(e.what(), hrcsense::app::kExitUsage);
  }

  try {
    return run_parsed_command(commands, args, eval_args, echo_args);
  } catch (const std::exception& e) {
    return hrcsense::app::report_error(e);
  }
}
