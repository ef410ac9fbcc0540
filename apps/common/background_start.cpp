// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — a run's background at start, and teaching a reference
// (background_start.hpp).
#include "common/background_start.hpp"
#include "common/cell.hpp"

#include "common/assembly.hpp"

#include "hrcsense/filters.hpp"
#include "hrcsense/io/io.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

namespace hrcsense {
namespace {

// The reference file: it must exist (a configuration that names one must never start without
// it), be undamaged and be of the filtered resolution the background is learnt at.
BackgroundModel load_reference(const Config& config, const SourceInfo& info) {
  const std::string& path = config.background_reference;
  if (!std::filesystem::exists(path)) {
    throw ConfigError(config_where(config) + ": key 'background.reference': no such file '" + path +
                      "'; teach one with the cell empty: hrcsense teach --config FILE --out " + path);
  }
  BackgroundModel model = load_background(path);  // IoError naming the file: damaged, a folder, a FIFO
  const Intrinsics filtered = filtered_intrinsics(config.pipeline.filters, info.intrinsics);
  if (model.width != filtered.width || model.height != filtered.height) {
    throw IoError(path + ": reference background is " + std::to_string(model.width) + "x" +
                  std::to_string(model.height) + " but the filtered source is " + std::to_string(filtered.width) +
                  "x" + std::to_string(filtered.height) + " (filters.preset " +
                  filter_preset_name(config.filters_preset) + "); teach it again with this configuration");
  }
  return model;
}

// Ignores every result: teaching writes a background, not verdicts.
class DiscardSink final : public Sink {
 public:
  void header(const RunHeader&) override {}
  void frame(const FrameResult&) override {}
  void summary(const RunSummary& summary) override { summary_ = summary; }
  const RunSummary& last_summary() const { return summary_; }

 private:
  RunSummary summary_;
};

}  // namespace

BackgroundStart start_background(const Config& config, const SourceInfo& info, Pipeline& pipeline) {
  if (!config.background_reference.empty()) {
    pipeline.set_reference(load_reference(config, info), "background.reference '" + config.background_reference + "'");
    if (!config.background_path.empty()) {
      spdlog::warn("background.path '{}' is ignored: with background.reference every start learns the background "
                   "afresh and checks it against the reference",
                   config.background_path);
    }
    spdlog::info("background: learnt afresh, checked against background.reference {} (objects within {:.2f} m of "
                 "the robot refuse it)",
                 config.background_reference, pipeline.reference_distance_m());
    return BackgroundStart::reference;
  }
  // Loaded first, so that a damaged file's error is the only line a failed start writes.
  const bool loaded = load_background_file(config, info, pipeline);
  spdlog::warn("no background.reference: a person standing still while the background is learnt becomes "
               "background and is never seen; with the cell confirmed empty, teach one with "
               "hrcsense teach --config FILE --out PATH and set background.reference (docs/SAFETY.md, "
               "\"Commissioning a cell\")");
  if (!loaded) return BackgroundStart::learnt;
  spdlog::info("background loaded from {}", config.background_path);
  return BackgroundStart::loaded;
}

// run_pipeline itself, paced as the source says, on the cell a run would assemble (without
// links or background files), so that the frames, the filters, the robot state at each frame
// and the learner are a run's; it is stopped as soon as the background is ready.
TeachResult teach_background(const Config& config, int64_t max_frames) {
  std::atomic<bool> stop{false};
  TeachResult result;
  app::CellOptions options;
  options.frames = max_frames;
  options.links = false;
  options.background_files = false;
  options.follow_link = false;
  // On the processing thread, after each frame: the frame that completed the background ends it.
  options.on_processed = [&](const Frame& frame, const Pipeline& p, const FrameResult&) {
    ++result.frames;
    if (result.last_frame < 0 && p.background_ready()) {
      result.last_frame = frame.index;
      stop.store(true);
    }
  };
  const std::unique_ptr<app::Cell> cell = app::assemble_cell(config, options);
  cell->run_options.stop_requested = &stop;
  const SourceInfo info = cell->source->info();
  result.source = info.description.empty() ? info.type : info.type + ", " + info.description;
  DiscardSink sink;
  const RunSummary summary =
      run_pipeline(cell->frames(), *cell->robot_states, *cell->pipeline, sink, cell->run_options, cell->header);
  if (!summary.error.empty()) throw std::runtime_error(summary.error);
  result.learnt = cell->pipeline->background_ready();
  result.message = cell->pipeline->background_message();
  if (result.learnt) result.background = cell->pipeline->background();
  return result;
}

}  // namespace hrcsense
