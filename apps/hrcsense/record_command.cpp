// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense record`: the configured source's frames, as delivered (before any
// filter), to a RealSense .bag (docs/RECORDINGS.md, "Recording").
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "common/cell.hpp"
#include "common/record_setup.hpp"
#include "common/stop_signals.hpp"

#include "hrcsense/config/config.hpp"
#include "hrcsense/recordings/recorder.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <optional>

namespace hrcsense::app {
namespace {

// How long push_wait gives the writer before a frame counts as dropped: a disk that stalls
// this long is failing anyway.
constexpr int kRecordWaitMs = 5000;

}  // namespace

int record_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets, args.camera);
  // Before anything is opened: never replace a file unasked, never the source being played.
  check_record_output(config, args.out, args.overwrite);
  CellOptions options;
  options.measure = false;
  options.stop_requested = &StopSignals::flag();
  options.with_color = true;  // a recording keeps what the source has: a folder's or bag's colour frames too
  const std::unique_ptr<Cell> cell = assemble_cell(config, options);
  Source& source = *cell->source;
  const SourceInfo info = source.info();
  // The robot's joints at each frame go to /hrcsense/joint_states beside it, looked up as an
  // unpaced `hrcsense run` of the configuration would.
  std::unique_ptr<RobotStateSource> recorder_states;
  const RecordStateLookup lookup = record_state_lookup(config, source, *cell->robot_states, false, recorder_states);
  Recorder recorder(recorder_params(config, args.out, info));

  std::optional<StopSignals> signals(std::in_place);
  Frame frame;
  int64_t frames = 0;
  int64_t first_ns = 0;
  std::string source_error;
  const auto duration_ns = static_cast<int64_t>(args.duration_s * 1e9);
  while (!StopSignals::stop_requested() && (args.frames < 0 || frames < args.frames) && !recorder.failed()) {
    const Source::Status status = source.next(frame);
    if (status == Source::Status::end) break;
    if (status == Source::Status::error) {
      source_error = source.error();
      break;
    }
    if (frames == 0) {
      first_ns = frame.timestamp_ns;
      if (frame.color && !color_recordable(frame)) {
        spdlog::warn("record: the source's colour frames have no calibration (a folder without rgb_K): recording "
                     "depth only");
      }
    }
    // --duration-s counts source time: the frame at first + S is the first one left out.
    if (args.duration_s > 0.0 && frame.timestamp_ns - first_ns >= duration_ns) break;
    // No processing to protect: wait rather than drop.
    recorder.push_wait(frame, kRecordWaitMs, robot_state_for_recording(frame, lookup));
    ++frames;
  }
  signals.reset();
  const RecorderStats stats = recorder.close();
  log_recording(stats);
  if (!stats.error.empty()) return report_error("recording: " + stats.error, kExitRuntime);
  if (!source_error.empty()) return report_error(source_error, kExitRuntime);
  return 0;
}

}  // namespace hrcsense::app
