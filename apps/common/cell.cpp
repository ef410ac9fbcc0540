// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — the assembled cell (cell.hpp).
#include "common/cell.hpp"

#include "common/record_setup.hpp"

#include <spdlog/spdlog.h>

#include <utility>

namespace hrcsense::app {
namespace {

// A live source that could not start: the run's one event is its error.
class UnstartedSource final : public Source {
 public:
  UnstartedSource(std::string type, std::string error) : error_(std::move(error)) {
    info_.type = std::move(type);
    info_.live = true;
    info_.frame_count = -1;
  }
  SourceInfo info() const override { return info_; }
  Status next(Frame&) override { return Status::error; }
  std::string error() const override { return error_; }

 private:
  SourceInfo info_;
  std::string error_;
};

// The source and the robot states it brings or needs (a bag's joint states), wrapped for a
// viewer's playback when asked.
void open_source(Cell& cell, const Config& config, const CellOptions& options, bool paced) {
  SourceOptions source_options;
  source_options.stop_requested = options.stop_requested;
  // A recording keeps the source's colour, so --record decodes it even where processing does not.
  source_options.with_color = options.with_color || !options.record.empty();
  if (options.measure && options.follow_link) cell.trajectory_clock = make_trajectory_clock(config);
  if (cell.trajectory_clock) cell.trajectory_clock->set_lockstep(!paced);
  source_options.trajectory_clock = cell.trajectory_clock;
  try {
    cell.source = make_source(config, source_options);
  } catch (const SourceStartError& e) {
    cell.source = std::make_unique<UnstartedSource>(source_type_name(config.source.type), e.what());
    cell.source_started = false;
  }
  cell.robot_states = make_robot_state_source(config, *cell.source, nullptr, cell.trajectory_clock);
  if (options.wrap_recording && is_recording(config.source.type)) {
    // The robot states may come from the first source: the wrapper keeps it alive.
    cell.source = options.wrap_recording(std::move(cell.source),
                                         [config, source_options] { return make_source(config, source_options); });
  }
}

// --record: the source's frames, as delivered, to a bag on a writer thread (never blocking),
// each with the robot state processing measures it against.
void add_recording(Cell& cell, const Config& config, const CellOptions& options, bool paced) {
  RecorderParams params = recorder_params(config, options.record, cell.source->info());
  const RecordOnError on_error = params.on_error;
  cell.recorder = std::make_unique<Recorder>(std::move(params));
  RecordStateLookup lookup = record_state_lookup(config, *cell.source, *cell.robot_states, paced,
                                                 cell.recorder_states, cell.trajectory_clock);
  lookup.from_processing = true;  // the state each frame was measured against (run_options below)
  cell.recording = std::make_unique<RecordingSource>(*cell.source, *cell.recorder, on_error, lookup);
}

// The controller's links, first among the sinks, so that no file or console write delays them.
void add_links(Cell& cell, const Config& config) {
  cell.udp_link = make_udp_link_sink(config);
  if (cell.udp_link) {
    spdlog::info("link: verdicts to {} ({}, heartbeat {} Hz)", cell.udp_link->address(), udp_format_name(config.link.udp_format),
                 config.link.heartbeat_hz);
  }
  cell.rtde_link = make_rtde_link_sink(config);
  if (cell.rtde_link) {
    spdlog::info("link: speed scale to RTDE {}:{} ({})", config.robot_state.host, config.robot_state.port,
                 cell.rtde_link->input_names());
  }
}

// ros2.publish: after the controller's links in the sinks' order; its cloud tap beside the
// caller's (a viewer's) on the processing thread.
std::function<void(const Frame&, const Pipeline&, const FrameResult&)> add_ros2_outputs(Cell& cell, const Config& config) {
  Ros2Outputs outputs = make_ros2_output_sink(config);
  cell.ros2_outputs = std::move(outputs.sink);
  cell.ros2_status = std::move(outputs.status);
  return std::move(outputs.on_processed);
}

// Both taps, the caller's first (null when neither is set).
std::function<void(const Frame&, const Pipeline&, const FrameResult&)> both_taps(
    std::function<void(const Frame&, const Pipeline&, const FrameResult&)> first,
    std::function<void(const Frame&, const Pipeline&, const FrameResult&)> second) {
  if (!first) return second;
  if (!second) return first;
  return [first = std::move(first), second = std::move(second)](const Frame& frame, const Pipeline& pipeline,
                                                                const FrameResult& result) {
    first(frame, pipeline, result);
    second(frame, pipeline, result);
  };
}

RunOptions run_options(const Config& config, const CellOptions& options, Cell& cell, bool paced,
                       std::function<void(const Frame&, const Pipeline&, const FrameResult&)> ros2_tap) {
  RunOptions run;
  run.pace = paced;
  run.camera_latency_s = config.robot_state.camera_latency_s;
  run.max_frames = options.frames;
  // A source that never started has nothing to stop: its error, not the signal that ended the
  // wait, is how the run ends.
  run.stop_requested = cell.source_started ? options.stop_requested : nullptr;
  run.before_process = options.before_process;
  run.on_processed = both_taps(options.on_processed, std::move(ros2_tap));
  if (cell.recorder) {
    // The recording holds the state processing used, so its replay decides as this run did.
    Recorder* recorder = cell.recorder.get();
    run.on_processed = [recorder, tap = run.on_processed](const Frame& frame, const Pipeline& pipeline,
                                                          const FrameResult& result) {
      recorder->state_used(frame.index, result.robot_state);
      if (tap) tap(frame, pipeline, result);
    };
  }
  return run;
}

}  // namespace

std::unique_ptr<Cell> assemble_cell(const Config& config, const CellOptions& options) {
  const bool paced = config.source.pace && !options.unpaced;
  auto cell = std::make_unique<Cell>();
  open_source(*cell, config, options, paced);
  if (!options.measure) return cell;
  const SourceInfo info = cell->source->info();
  if (!options.record.empty()) add_recording(*cell, config, options, paced);
  cell->pipeline = std::make_unique<Pipeline>(config.pipeline);
  if (options.background_files) cell->background = start_background(config, info, *cell->pipeline);
  std::function<void(const Frame&, const Pipeline&, const FrameResult&)> ros2_tap;
  if (options.links && !config.camera.empty()) {
    // One camera of several: it measures for the fuser, which alone decides and sends.
    cell->measurements = make_measurement_sink(config);
    ros2_tap = add_ros2_outputs(*cell, config);  // ros2.publish: the camera's previews only
  } else if (options.links) {
    add_links(*cell, config);
    ros2_tap = add_ros2_outputs(*cell, config);
  }
  // follow_link: the simulated arm takes the scale the links have just sent.
  if (cell->trajectory_clock) cell->follow = std::make_unique<FollowLinkSink>(cell->trajectory_clock);
  // Simulated runs: truth.contact_label from the simulator's own labels.
  if (config.source.type == SourceType::sim) cell->truth.emplace(make_simulator(config, cell->trajectory_clock));
  cell->header = make_run_header(config, info);
  cell->header.unknown_background_share = cell->pipeline->unknown_background_share();  // a loaded background's
  if (!cell->header.filters.note.empty()) spdlog::warn("filters: {}", cell->header.filters.note);
  for (const std::string& warning : config.warnings) spdlog::warn("config: {}", warning);
  cell->run_options = run_options(config, options, *cell, paced, std::move(ros2_tap));
  return cell;
}

}  // namespace hrcsense::app
