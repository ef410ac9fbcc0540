// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense eval`: sweeps configuration keys over scenes and seeds (the sweep
// runner, hrcsense/eval/runner.hpp), then draws the sweep's figures (eval/plots.hpp); `--study
// NAME` runs one of the ready-made studies that replicate the thesis's tables (eval/studies.hpp).
// The flags become requests to the evaluation library (hrcsense_eval), which writes nothing
// to the terminal; this file logs its notes and draws its progress.
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "hrcsense/eval/plots.hpp"
#include "hrcsense/eval/runner.hpp"
#include "hrcsense/eval/studies.hpp"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <cstdint>
#include <cstdio>
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

// The progress bar on stderr, redrawn in place when stderr is a terminal (a log file gets
// none); the library's notes go to the log.
eval::SweepObserver terminal_observer() {
  eval::SweepObserver observer;
  observer.note = [](const std::string& note) { spdlog::info("eval: {}", note); };
  if (::isatty(STDERR_FILENO) == 0) return observer;
  observer.progress = [](const eval::SweepProgress& p) {
    constexpr int kWidth = 24;
    const int filled = p.rows_total > 0 ? static_cast<int>(kWidth * p.rows_done / p.rows_total) : kWidth;
    std::string bar(static_cast<size_t>(filled), '#');
    bar.resize(kWidth, '.');
    const double fps = p.elapsed_s > 0.0 ? static_cast<double>(p.frames_done) / p.elapsed_s : 0.0;
    const std::string left = fps > 0.0 && p.frames_total > 0
                                 ? std::to_string(static_cast<int64_t>(
                                       static_cast<double>(p.frames_total - p.frames_done) / fps)) + " s"
                                 : "?";
    std::fprintf(stderr, "\r[%s] %lld/%lld rows  %s  %.0f frames/s  %s left   ", bar.c_str(),
                 static_cast<long long>(p.rows_done), static_cast<long long>(p.rows_total), p.current.c_str(), fps,
                 left.c_str());
    if (p.finished) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  };
  return observer;
}

}  // namespace

int eval_study_command(const EvalArgs& args) {
  StudyContext ctx;
  ctx.out_dir = args.out;
  ctx.config_dir = args.config_dir;
  ctx.jobs = args.jobs;
  ctx.frames = args.frames;
  ctx.sets = args.sets;
  ctx.observer = terminal_observer();
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
    request.observer = terminal_observer();
    const ResultTable table = eval::run_sweep(request);
    const std::vector<std::string> plots = eval::sweep_plots(table, axes, args.out);
    if (!plots.empty()) spdlog::info("eval: {} figures in {}", plots.size(), args.out);
    return 0;
  } catch (const std::exception& e) {
    return report_error(e);
  }
}

}  // namespace hrcsense::app
