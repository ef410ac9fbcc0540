// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense run`: configured source → pipeline → JSON Lines (+ progress on stderr).
#include "app_errors.hpp"
#include "commands.hpp"
#include "console_sink.hpp"
#include "tee_sink.hpp"

#include "hrcsense/config.hpp"
#include "hrcsense/io.hpp"
#include "hrcsense/sinks.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace hrcsense::app {
namespace {

// Set by SIGINT, SIGTERM (systemd's stop) or SIGHUP (the terminal closed); the pipeline polls
// it and ends the run with a final stop line and a summary.
std::atomic<bool> g_stop_requested{false};
std::atomic<int> g_stop_signal{0};

extern "C" void on_stop_signal(int signal) {
  g_stop_requested.store(true);
  g_stop_signal.store(signal);
  std::signal(signal, SIG_DFL);  // a second one kills, in case the run is stuck
}

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

// SIGPIPE is ignored for the whole run: a reader that goes away makes the write fail (EPIPE),
// and the failed sink ends the run, instead of the signal killing it mid-line.
void install_signal_handlers() {
  g_stop_requested.store(false);
  g_stop_signal.store(0);
  for (int signal : kStopSignals) std::signal(signal, on_stop_signal);
  std::signal(SIGPIPE, SIG_IGN);
}

void restore_signal_handlers() {
  for (int signal : kStopSignals) std::signal(signal, SIG_DFL);
}

const char* signal_name(int signal) {
  switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

// Loads background.path when it exists. Returns false when there is nothing to load.
// The background is at the filtered resolution (after decimation), not the source's.
bool load_background_file(const Config& config, const SourceInfo& info, Pipeline& pipeline) {
  if (config.background_path.empty() || !std::filesystem::exists(config.background_path)) return false;
  BackgroundModel model = load_background(config.background_path);  // IoError: damaged file
  const Intrinsics filtered = filtered_intrinsics(config.pipeline.filters, info.intrinsics);
  if (model.width != filtered.width || model.height != filtered.height) {
    throw IoError(config.background_path + ": background is " + std::to_string(model.width) + "x" +
                  std::to_string(model.height) + " but the filtered source is " + std::to_string(filtered.width) +
                  "x" + std::to_string(filtered.height) + " (filters.preset " + config.filters_preset + ")");
  }
  pipeline.set_background(std::move(model), "background.path '" + config.background_path + "'");
  return true;
}

void save_learnt_background(const Config& config, const Pipeline& pipeline) {
  if (config.background_path.empty()) return;
  if (!pipeline.background_ready()) {
    spdlog::warn("background not saved to {}: learning did not finish", config.background_path);
    return;
  }
  const std::filesystem::path parent = std::filesystem::path(config.background_path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  save_background(config.background_path, pipeline.background());
  spdlog::info("background saved to {}", config.background_path);
}

// What the JSON Lines header says about the filters; the note explains a depth-domain run of a
// chain that asks for disparity.
RunHeader::Filters describe_filters(const Config& config, const SourceInfo& info) {
  RunHeader::Filters filters;
  const FilterChainParams& chain = config.pipeline.filters;
  filters.preset = config.filters_preset;
  filters.domain = filter_domain(chain, info.stereo_baseline_mm);
  const bool wants_disparity =
      std::find(chain.order.begin(), chain.order.end(), FilterBlock::to_disparity) != chain.order.end();
  if (wants_disparity && filters.domain == "depth") {
    filters.note = "no stereo baseline: to_disparity/to_depth skipped, spatial and temporal run on depth "
                   "(set source.stereo_baseline_mm)";
  }
  filters.intrinsics = filtered_intrinsics(chain, info.intrinsics);
  return filters;
}

}  // namespace

int run_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets);
  std::unique_ptr<Source> source = make_source(config);
  const SourceInfo info = source->info();

  Pipeline pipeline(config.pipeline);
  const bool background_loaded = load_background_file(config, info, pipeline);
  if (background_loaded) spdlog::info("background loaded from {}", config.background_path);

  std::ofstream file;
  if (!args.out.empty()) {
    const std::filesystem::path parent = std::filesystem::path(args.out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    file.open(args.out, std::ios::out | std::ios::trunc);
    if (!file) return report_error(args.out + ": cannot open for writing", kExitRuntime);
  }
  std::ostream& out = args.out.empty() ? std::cout : file;

  JsonLinesSink jsonl(out, config.pipeline.backend);
  ConsoleSink console;
  TeeSink sinks{&jsonl, &console};

  RunHeader header;  // version and commit: the sink fills in the build's own
  header.config_hash = config_hash(config);
  header.source = info;
  header.filters = describe_filters(config, info);
  if (!header.filters.note.empty()) spdlog::warn("filters: {}", header.filters.note);

  RunOptions options;
  options.pace = config.source.pace;
  options.max_frames = args.frames;
  options.stop_requested = &g_stop_requested;
  install_signal_handlers();
  const RunSummary summary = run_pipeline(*source, pipeline, sinks, options, header);
  restore_signal_handlers();
  if (g_stop_signal.load() != 0) spdlog::info("{} received: the run ended with a stop", signal_name(g_stop_signal.load()));

  if (!background_loaded) save_learnt_background(config, pipeline);
  const std::string out_name = args.out.empty() ? "stdout" : args.out;
  out.flush();
  if (!out) return report_error(out_name + ": write failed; the run ended there", kExitRuntime);
  // The output ends with a stop line and a summary either way (when it can still be written);
  // the exit code tells scripts that the source, the processing or the output failed.
  if (!summary.error.empty()) return report_error(summary.error, kExitRuntime);
  return 0;
}

}  // namespace hrcsense::app
