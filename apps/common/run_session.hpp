// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — one run of the configured cell, as `hrcsense run` and `hrcsense-view` both
// make it: source (and its recording), robot states, pipeline, background, the links to the
// controller (UDP, RTDE), JSON Lines and console output, the fault log, signal handling. The
// viewer joins through the hooks; nothing here knows it.
#pragma once

#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/sink.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace hrcsense::app {

struct SessionOptions {
  int64_t frames = -1;  ///< --frames N; -1: the source's length
  std::string out;      ///< --out FILE; empty: stdout
  std::string record;   ///< --record FILE.bag; empty: no recording
  bool overwrite = false;  ///< --overwrite: the recording may replace an existing file (check_record_output)
  /// Play the source as fast as processing goes, whatever source.pace says (headless
  /// snapshots). A live camera paces itself either way.
  bool unpaced = false;
  /// RunOptions::on_processed: a viewer's tap on the processing thread (the measurement, before
  /// the verdict is decided).
  std::function<void(const Frame&, const Pipeline&, const FrameResult&)> on_processed;
  /// Set: one more sink on the output thread, after all the others (the links, the JSON Lines,
  /// the console): a viewer's, which gets every result as decided. Must outlive the run.
  Sink* viewer_sink = nullptr;
  /// Set: the summary reports `viewer_frames_dropped` from it (read once the run has ended).
  std::function<int64_t()> viewer_frames_dropped;
  /// RunOptions::before_process: the viewer's requests to the pipeline, between frames.
  std::function<void(Pipeline&, const FrameResult&)> before_process;
  /// Recorded sources decode their colour frames too (the viewer shows them).
  bool with_color = false;
  /// Set: a recording (.bag or folder source) is replaced by what this makes of it, given
  /// the opened source and a way to open it again from its start (the viewer's playback).
  std::function<std::unique_ptr<Source>(std::unique_ptr<Source> opened, std::function<std::unique_ptr<Source>()> open)>
      wrap_recording;
};

/// Runs the configured cell to its end (source end, --frames, a signal or
/// request_session_stop()) and returns the process exit code; errors are logged to stderr.
int run_session(const Config& config, const SessionOptions& options);

/// Ends a running session as SIGINT would (a final stop line, then the summary): the viewer's
/// quit key and window close. Safe from any thread.
void request_session_stop();

}  // namespace hrcsense::app
