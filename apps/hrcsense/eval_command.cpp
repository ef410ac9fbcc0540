// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense eval`: sweeps configuration keys over scenes and seeds (the sweep
// runner, eval_runner.hpp), then draws the sweep's figures (eval_plots.hpp); `--study NAME`
// runs one of the ready-made studies that replicate the thesis's tables (eval_studies.cpp).
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "eval_plots.hpp"
#include "eval_runner.hpp"

#include <spdlog/spdlog.h>

#include <exception>

namespace hrcsense::app {

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
    const ResultTable table = run_sweep(request);
    const std::vector<std::string> plots = sweep_plots(table, axes, args.out);
    if (!plots.empty()) spdlog::info("eval: {} figures in {}", plots.size(), args.out);
    return 0;
  } catch (const std::exception& e) {
    return report_error(e);
  }
}

}  // namespace hrcsense::app
