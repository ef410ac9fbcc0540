// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense eval`: sweeps configuration keys over scenes and seeds (the sweep
// runner, hrcsense/eval/runner.hpp), then draws the sweep's figures (eval/plots.hpp); `--study
// NAME` runs one of the ready-made studies that replicate the thesis's tables (eval/studies.hpp).
// The flags become requests to the evaluation library (hrcsense_eval); this file only logs.
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "hrcsense/eval/plots.hpp"
#include "hrcsense/eval/runner.hpp"
#include "hrcsense/eval/studies.hpp"

#include <spdlog/spdlog.h>

#include <exception>
#include <string>
#include <vector>

namespace hrcsense::app {
namespace {

using eval::ResultTable;
using eval::StudyContext;
using eval::StudySection;
using eval::SweepRequest;

// The command that made the report, as the user would type it.
std::string command_line(const EvalArgs& args) {
  std::string line = "hrcsense eval --study " + args.study;
  if (args.jobs != 1) line += " --jobs " + std::to_string(args.jobs);
  if (args.frames > 0) line += " --frames " + std::to_string(args.frames);
  for (const std::string& set : args.sets) line += " --set " + set;
  if (args.config_dir != "config") line += " --config-dir " + args.config_dir;
  line += " --out " + args.out;
  if (!args.report.empty()) line += " --report " + args.report;
  return line;
}

}  // namespace

int eval_study_command(const EvalArgs& args) {
  StudyContext ctx;
  ctx.out_dir = args.out;
  ctx.config_dir = args.config_dir;
  ctx.jobs = args.jobs;
  ctx.frames = args.frames;
  ctx.sets = args.sets;
  if (!eval::is_study(args.study)) {
    return report_error("eval: --study '" + args.study +
                            "' is no study; expected table-4.1, table-4.2, table-4.3, table-4.4, moving-cell or thesis",
                        kExitUsage);
  }
  const std::vector<StudySection> sections = eval::run_studies(args.study, ctx);
  if (!args.report.empty() && args.study != "thesis") {
    return report_error("eval: --report goes with --study thesis", kExitUsage);
  }
  const std::string report = eval::write_thesis_report(args.out, command_line(args), sections);
  spdlog::info("eval: the report is {}", report);
  if (!args.report.empty()) {
    eval::write_thesis_report_copy(args.report, args.out, command_line(args), sections);
    spdlog::info("eval: and {}", args.report);
  }
  return 0;
}

int eval_command(const EvalArgs& args) {
  try {
    if (args.out.empty()) return report_error("eval: --out DIR is required", kExitUsage);
    if (!args.study.empty()) return eval_study_command(args);
    SweepRequest request;
    request.scenes = args.scenes;
    if (request.scenes.empty() && !args.config_path.empty()) request.scenes.push_back(args.config_path);
    if (request.scenes.empty()) return report_error("eval: give --config FILE or --scene FILE (one or more)", kExitUsage);
    std::vector<eval::SweepAxis> axes;
    for (const std::string& sweep : args.sweeps) axes.push_back(eval::parse_sweep(sweep));
    request.points = eval::sweep_grid(axes);
    request.sets = args.sets;
    request.seeds = args.seeds;
    request.frames = args.frames;
    request.jobs = args.jobs;
    request.out_dir = args.out;
    const ResultTable table = eval::run_sweep(request);
    const std::vector<std::string> plots = eval::sweep_plots(table, axes, args.out);
    if (!plots.empty()) spdlog::info("eval: {} figures in {}", plots.size(), args.out);
    return 0;
  } catch (const std::exception& e) {
    return report_error(e);
  }
}

}  // namespace hrcsense::app
