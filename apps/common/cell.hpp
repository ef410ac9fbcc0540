// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — the assembled cell: everything one run of a configuration needs, built in
// one place for `hrcsense run`, `record`, `teach`, `eval` and `hrcsense-view`. The callers
// differ only in what they add around it (their output sinks, signal handling, a window).
//
//   Cell cell = assemble_cell(config, options);   // source, robot states, pipeline, links, header
//   run_pipeline(cell.frames(), *cell.robot_states, *cell.pipeline, my_sinks, cell.run_options, cell.header);
#pragma once

#include "common/assembly.hpp"
#include "common/background_start.hpp"
#include "common/follow_link_sink.hpp"

#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/recordings/recorder.hpp"
#include "hrcsense/sim/sim.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace hrcsense::app {

/// How a caller wants its cell. The defaults are `hrcsense run`'s.
struct CellOptions {
  /// False: only the source and its robot states (`hrcsense record`, which decides nothing; a
  /// follow_link arm then plays its trajectory as programmed). Everything else stays empty.
  bool measure = true;
  int64_t frames = -1;          ///< RunOptions::max_frames (--frames N); -1: the source's length
  /// Play as fast as processing goes, whatever source.pace says (headless snapshots, teach). A
  /// live camera paces itself either way.
  bool unpaced = false;
  bool with_color = false;      ///< recorded sources decode their colour frames (a viewer, a recording)
  bool links = true;            ///< link.udp, link.rtde and ros2.publish as configured (the evaluation sends nothing)
  /// robot.trajectory.follow_link as configured; false: a simulated arm plays its trajectory as
  /// programmed (`teach`: nothing is sent, and the arm must not wait for a scale).
  bool follow_link = true;
  /// background.reference / background.path as configured (start_background); false: the
  /// background is learnt in the run and no file is read (the evaluation, `teach`).
  bool background_files = true;
  std::string record;           ///< --record FILE.bag: the delivered frames to a recording as they pass
  /// Ends a live camera's waits and the run (a signal handler's flag); null: never.
  std::atomic<bool>* stop_requested = nullptr;
  /// RunOptions::on_processed (a viewer's tap); the recorder's own hook runs first.
  std::function<void(const Frame&, const Pipeline&, const FrameResult&)> on_processed;
  /// RunOptions::before_process (a viewer's requests to the pipeline, between frames).
  std::function<void(Pipeline&, const FrameResult&)> before_process;
  /// Set: a recording (.bag or folder source) is replaced by what this makes of it, given the
  /// opened source and a way to open it again from its start (the viewer's playback).
  std::function<std::unique_ptr<Source>(std::unique_ptr<Source> opened, std::function<std::unique_ptr<Source>()> open)>
      wrap_recording;
};

/// One configured cell, ready to run. Members point at each other (the recording reads the
/// source, the pipeline's options its recorder), so a Cell is made once and never moved.
struct Cell {
  /// robot.trajectory.follow_link: the clock the simulated arm, its state and its truth share.
  std::shared_ptr<TrajectoryClock> trajectory_clock;
  std::unique_ptr<Source> source;
  /// False when a live source could not start (SourceStartError): `source` then only reports
  /// that error, and the run is its header, a stop and a summary naming it.
  bool source_started = true;
  std::unique_ptr<RobotStateSource> robot_states;
  std::unique_ptr<RobotStateSource> recorder_states;  ///< a recording's own state source, when it needs one
  std::unique_ptr<Recorder> recorder;                 ///< --record
  std::unique_ptr<RecordingSource> recording;         ///< the source seen through the recorder
  std::unique_ptr<Pipeline> pipeline;  ///< null without CellOptions::measure
  BackgroundStart background = BackgroundStart::learnt;
  std::unique_ptr<UdpLinkSink> udp_link;    ///< link.udp.address
  std::unique_ptr<RtdeLinkSink> rtde_link;  ///< link.rtde.write
  std::unique_ptr<FollowLinkSink> follow;   ///< follow_link: the arm takes the scale just sent
  /// ros2.publish: verdict, speed scaling, markers, foreground cloud and /tf_static over DDS
  /// (make_ros2_output_sink); its cloud tap is in run_options.on_processed.
  std::unique_ptr<Sink> ros2_outputs;
  std::function<Ros2OutputsStatus()> ros2_status;  ///< what ros2_outputs did (null without it)
  /// A camera of a cell with several (config.camera): its measurements for the fuser, in place
  /// of every link and ROS 2 output (make_measurement_sink); with ros2.publish, ros2_outputs
  /// holds only its previews for a viewer.
  std::unique_ptr<Sink> measurements;
  /// Simulated runs: the simulator that labels each result's truth (TruthLabeller).
  std::optional<Simulator> truth;
  RunHeader header;
  RunOptions run_options;

  Cell() = default;
  Cell(const Cell&) = delete;
  Cell& operator=(const Cell&) = delete;

  /// What run_pipeline reads: the recording when there is one, else the source.
  Source& frames() { return recording ? static_cast<Source&>(*recording) : *source; }
  /// The links in the order they get each result: the controller first, then the ROS 2 outputs
  /// (a cell camera: its measurement before its previews, so the fuser never waits for them).
  std::vector<Sink*> link_sinks() const {
    return {udp_link.get(), rtde_link.get(), follow.get(), measurements.get(), ros2_outputs.get()};
  }
};

/// Builds the cell `config` describes. Throws ConfigError for what the configuration gets
/// wrong (naming the file and key), IoError for a file that cannot be read, as make_source,
/// make_robot_state_source and start_background do; a live source that does not start is
/// not thrown but kept (Cell::source_started). With options.record, call check_record_output
/// first: nothing here replaces a file.
std::unique_ptr<Cell> assemble_cell(const Config& config, const CellOptions& options = {});

}  // namespace hrcsense::app
