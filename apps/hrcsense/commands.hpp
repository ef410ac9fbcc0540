// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — the subcommands. Each returns the process exit code and logs to stderr.
#pragma once

#include "hrcsense/config/config.hpp"
#include "hrcsense/recordings/recorder.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hrcsense::app {

/// Flags shared by the subcommands (DESIGN.md "Names other tools rely on").
struct CommandArgs {
  std::string config_path;          ///< --config FILE
  std::vector<std::string> sets;    ///< repeatable --set KEY=VALUE
  int64_t frames = -1;              ///< --frames N; -1: the source's length
  std::string out;                  ///< --out FILE; empty: stdout
  std::string input;                ///< positional path (info on a recording)
  std::string shared;               ///< verify-filters --shared DIR; empty: ../shared
  std::string record;               ///< run --record FILE.bag; empty: no recording
  double duration_s = -1.0;         ///< record --duration-s S; < 0: until --frames or the source's end
  bool overwrite = false;           ///< record / run --record: --overwrite replaces an existing recording
  std::string camera;               ///< run / calibrate --camera NAME: one entry of the scene's cameras:
  bool write_back = false;          ///< calibrate --write-back: the poses into the --config file's entries
};

/// `hrcsense eval`'s flags (docs/EVALUATION.md).
struct EvalArgs {
  std::string config_path;          ///< --config FILE: the scene when no --scene is given
  std::vector<std::string> sets;    ///< --set KEY=VALUE, for every row
  std::vector<std::string> sweeps;  ///< --sweep KEY=LIST | KEY=A:B[:STEP], a grid
  std::vector<std::string> scenes;  ///< --scene FILE (configuration files)
  int64_t seeds = 0;                ///< --seeds N: source.seed 1..N; 0: each scene's own seed
  int64_t frames = -1;              ///< --frames N per row; -1: the source's length
  int jobs = 1;                     ///< --jobs N rows at once
  std::string out;                  ///< --out DIR
  std::string study;                ///< --study NAME: a ready-made study (docs/EVALUATION.md)
  std::string config_dir = "config";  ///< --config-dir DIR: where a study finds its scenes
  std::string report;               ///< --report FILE: the thesis study's report also here
};

/// `hrcsense echo`'s flags (docs/ROS2.md).
struct EchoArgs {
  std::string topic;        ///< TOPIC: a ROS 2 name, e.g. /hrcsense/verdict
  int domain = -1;          ///< --domain N; -1: ROS_DOMAIN_ID when set, else 0
  std::string type;         ///< --type NAME; empty: from the topic's name
  int64_t count = -1;       ///< --count N; -1: until interrupted
  double timeout_s = -1.0;  ///< --timeout-s S; < 0: none
};

int run_command(const CommandArgs& args);
/// fuse: the decision of a cell with several cameras from their measurements over DDS.
int fuse_command(const CommandArgs& args);
/// cell: a cell with several cameras on one host (a `run --camera` per camera and a `fuse`).
int cell_command(const CommandArgs& args);
/// echo TOPIC: the samples of one of hrcsense's ROS 2 topics (or /joint_states) as JSON lines.
int echo_command(const EchoArgs& args);
/// eval: the thesis's measures over a sweep (results.csv in --out, resumable).
int eval_command(const EvalArgs& args);
/// eval --study NAME: table-4.1 … table-4.4, moving-cell, or thesis (all, with the report).
int eval_study_command(const EvalArgs& args);
/// record --out FILE.bag [--frames N | --duration-s S]: the source's frames, unfiltered, to a bag.
int record_command(const CommandArgs& args);
/// publish: the configured source as realsense-ros topics over Cyclone DDS (publish.*).
int publish_command(const CommandArgs& args);
int info_command(const CommandArgs& args);
/// teach --out PATH: learns the background as a run does and writes it as a reference for
/// background.reference; exit 1 when the source ends (or --frames) before it is learnt.
int teach_command(const CommandArgs& args);
/// calibrate --out POSE.yaml: the camera's pose from the arm's own depth (docs/CALIBRATION.md);
/// --camera NAME | all [--write-back]: entries of a cell, with the cameras' agreement on the arm;
/// exit 1 when refused (the reason on stderr), nothing written then.
int calibrate_command(const CommandArgs& args);
/// devices: the RealSense cameras connected, with their depth profiles (docs/CAMERAS.md); in a
/// build without the SDK, the error saying how to get it.
int devices_command();
int bench_command(const CommandArgs& args);
/// verify-filters CASES_JSON [--shared DIR]: one stdout line per case, last "N/M cases bit-exact".
int verify_filters_command(const CommandArgs& args);

}  // namespace hrcsense::app
