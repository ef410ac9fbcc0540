// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — one run of the configured cell (run_session.hpp).
#include "common/run_session.hpp"

#include "common/app_errors.hpp"
#include "common/assembly.hpp"
#include "common/background_start.hpp"
#include "common/cell.hpp"
#include "common/console_sink.hpp"
#include "common/fault_log.hpp"
#include "common/follow_link_sink.hpp"
#include "common/record_setup.hpp"
#include "common/tee_sink.hpp"
#include "common/truth_labeller.hpp"

#include "hrcsense/recordings/recorder.hpp"
#include "hrcsense/sinks/sinks.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <utility>

namespace hrcsense::app {
namespace {

// Set by SIGINT, SIGTERM (systemd's stop), SIGHUP (the terminal closed) or SIGTSTP (Ctrl-Z:
// a suspended process would look alive to its consumers while it decides nothing, so it ends
// instead); the pipeline polls it and ends the run with a final stop line and a summary.
std::atomic<bool> g_stop_requested{false};
std::atomic<int> g_stop_signal{0};

extern "C" void on_stop_signal(int signal) {
  g_stop_requested.store(true);
  g_stop_signal.store(signal);
  std::signal(signal, SIG_DFL);  // a second one kills, in case the run is stuck
}

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGTSTP};

// How long `run --camera NAME` of a simulated cell waits for the fuser's cell_clock: discovery on
// a network takes well under a second, and the fuser is started first.
constexpr double kCellClockWaitS = 5.0;

// SIGPIPE is ignored for the whole run: a reader that goes away makes the write fail (EPIPE),
// and the failed sink ends the run, instead of the signal killing it mid-line.
void install_signal_handlers() {
  g_stop_requested.store(false);
  g_stop_signal.store(0);
  for (int signal : kStopSignals) std::signal(signal, on_stop_signal);
  std::signal(SIGPIPE, SIG_IGN);
}

// What each part of the run can say is wrong while it runs (fault_log.hpp).
std::vector<FaultProbe> fault_probes(const RobotStateSource& robot_states, const Recorder* recorder,
                                     const UdpLinkSink* link, const RtdeLinkSink* rtde_link,
                                     const std::function<Ros2OutputsStatus()>& ros2_status) {
  std::vector<FaultProbe> probes;
  // A frame stopped for want of a state says why (the source's problem is in its reason);
  // samples rejected while frames still find a state are said as they come.
  auto rejected = when_rising(
      [&robot_states] {
        const RobotStateStats stats = robot_states.stats();
        return stats.samples.rejected() + stats.malformed;
      },
      [&robot_states] { return "samples rejected: " + robot_states.stats().last_problem; });
  probes.push_back({"robot state", [rejected](const FrameResult& newest) mutable {
                      const bool no_state = newest.withheld_code == ReasonCode::no_robot_state ||
                                            newest.withheld_code == ReasonCode::robot_state_stale;
                      if (newest.source_frame && !newest.valid && no_state) return newest.withheld_reason;
                      return rejected(newest);
                    }});
  // Learning that starts over (someone moving in the cell) says where the motion is.
  probes.push_back({"background", [](const FrameResult& newest) {
                      constexpr const char* kRestarted = "restarted: ";
                      const size_t at = newest.withheld_reason.find(kRestarted);
                      if (newest.withheld_code != ReasonCode::learning_background || at == std::string::npos) {
                        return std::string();
                      }
                      return newest.withheld_reason.substr(at + std::char_traits<char>::length(kRestarted));
                    }});
  if (recorder != nullptr) {
    auto dropped = when_rising([recorder] { return recorder->stats().frames_dropped; },
                               [recorder] {
                                 return std::to_string(recorder->stats().frames_dropped) +
                                        " frames not recorded so far (the disk is slower than the camera)";
                               });
    probes.push_back({"recording", [recorder, dropped](const FrameResult& newest) mutable {
                        const std::string error = recorder->stats().error;
                        return error.empty() ? dropped(newest) : "recording ended: " + error;
                      }});
  }
  if (link != nullptr) {
    probes.push_back({"link.udp", when_rising([link] { return link->counters().send_errors; },
                                              [link] { return link->counters().last_error; })});
  }
  if (rtde_link != nullptr) {
    auto failed = when_rising(
        [rtde_link] {
          const RtdeLinkCounters c = rtde_link->counters();
          return c.refusals + c.disconnects + c.malformed;
        },
        [rtde_link] { return rtde_link->counters().last_problem; });
    probes.push_back({"link.rtde", [rtde_link, failed](const FrameResult& newest) mutable {
                        const RtdeLinkCounters c = rtde_link->counters();
                        // Not streaming after a problem: the writes do not reach the controller.
                        if (!c.connected && !c.last_problem.empty()) return c.last_problem;
                        return failed(newest);
                      }});
  }
  if (ros2_status) {
    probes.push_back({"ros2", when_rising([ros2_status] { return ros2_status().failed_writes; },
                                          [ros2_status] { return ros2_status().last_error; })});
  }
  return probes;
}

void restore_signal_handlers() {
  for (int signal : kStopSignals) std::signal(signal, SIG_DFL);
}

struct SignalHandlers {
  SignalHandlers() { install_signal_handlers(); }
  ~SignalHandlers() { restore_signal_handlers(); }
  SignalHandlers(const SignalHandlers&) = delete;
  SignalHandlers& operator=(const SignalHandlers&) = delete;
};

const char* signal_name(int signal) {
  switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case SIGTSTP: return "SIGTSTP";
    default: return "a signal";
  }
}

CellOptions cell_options(const SessionOptions& args) {
  CellOptions options;
  options.frames = args.frames;
  options.unpaced = args.unpaced;
  options.with_color = args.with_color;
  options.record = args.record;
  options.stop_requested = &g_stop_requested;
  options.on_processed = args.on_processed;
  options.before_process = args.before_process;
  options.wrap_recording = args.wrap_recording;
  return options;
}

// What the run writes and tells, in order: the controller's links, the JSON Lines (with the
// truth labels of a simulated run and the recorder's and viewer's counters in the summary),
// the console, a viewer; the fault log around them all.
class SessionSinks {
 public:
  SessionSinks(Cell& cell, std::ostream& out, const Config& config, const SessionOptions& args)
      : jsonl_(out, proximity_backend_name(config.pipeline.backend), extras(cell, args)),
        tee_(sinks(cell, args)),
        faults_(tee_, fault_probes(*cell.robot_states, cell.recorder.get(), cell.udp_link.get(), cell.rtde_link.get(),
                             cell.ros2_status),
                [] { return SteadyClock().now_ns(); }) {}
  Sink& sink() { return faults_; }

 private:
  JsonLinesExtras extras(Cell& cell, const SessionOptions& args) {
    JsonLinesExtras extras;
    if (cell.truth) {
      labeller_.emplace(std::move(*cell.truth), cell.header);
      extras.contact_label = [this](const FrameResult& result) { return labeller_->contact_label(result); };
    }
    // Asked when the summary is written, after the run's final stop: closing the recording here
    // (writing what is still queued) never delays a verdict.
    extras.app_counters = [recorder = cell.recorder.get(), dropped = args.viewer_frames_dropped] {
      AppCounters counters;
      if (recorder != nullptr) {
        const RecorderStats stats = recorder->close();
        counters.record = RecordCounters{stats.frames_recorded, stats.frames_dropped, stats.files, stats.error};
      }
      if (dropped) counters.viewer_frames_dropped = dropped();
      return counters;
    };
    return extras;
  }
  std::vector<Sink*> sinks(const Cell& cell, const SessionOptions& args) {
    std::vector<Sink*> all = cell.link_sinks();
    all.push_back(&jsonl_);
    all.push_back(&console_);
    all.push_back(args.viewer_sink);
    return all;
  }

  std::optional<TruthLabeller> labeller_;  // before jsonl_, which asks it
  JsonLinesSink jsonl_;
  ConsoleSink console_;
  TeeSink tee_;
  FaultLogSink faults_;
};

// The links' counters, as a warning when something went wrong.
void report_links(const Cell& cell) {
  if (cell.udp_link) {
    const bool failed = cell.udp_link->counters().send_errors > 0;
    spdlog::log(failed ? spdlog::level::warn : spdlog::level::info, "{}", describe_link_counters(*cell.udp_link));
  }
  if (cell.rtde_link) {
    const RtdeLinkCounters c = cell.rtde_link->counters();
    const bool failed = c.disconnects + c.refusals + c.malformed > 0 || c.writes == 0;
    spdlog::log(failed ? spdlog::level::warn : spdlog::level::info, "{}", describe_link_counters(*cell.rtde_link));
  }
  if (cell.ros2_status) {
    const Ros2OutputsStatus status = cell.ros2_status();
    spdlog::log(status.failed_writes > 0 ? spdlog::level::warn : spdlog::level::info, "{}", describe_ros2_outputs(status));
  }
}

}  // namespace

void request_session_stop() { g_stop_requested.store(true); }

int run_session(const Config& given, const SessionOptions& args) {
  // Before anything is opened: a recording never silently replaces a file, nor the source.
  if (!args.record.empty()) check_record_output(given, args.record, args.overwrite);
  // From here a signal ends the run with a stop line and a summary, also while a live camera
  // is still awaited; the handlers go when the session does, however it ends.
  const SignalHandlers signal_handlers;
  // A simulated camera of a cell without sim.epoch plays the fuser's scene clock (cell_clock).
  const Config config = with_cell_clock(given, kCellClockWaitS, &g_stop_requested);
  const std::unique_ptr<Cell> cell = assemble_cell(config, cell_options(args));
  std::ofstream file;
  if (!args.out.empty()) {
    const std::filesystem::path parent = std::filesystem::path(args.out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    file.open(args.out, std::ios::out | std::ios::trunc);
    if (!file) return report_error(args.out + ": cannot open for writing", kExitRuntime);
  }
  std::ostream& out = args.out.empty() ? std::cout : file;
  SessionSinks sinks(*cell, out, config, args);

  const RunSummary summary =
      run_pipeline(cell->frames(), *cell->robot_states, *cell->pipeline, sinks.sink(), cell->run_options, cell->header);
  if (g_stop_signal.load() != 0) spdlog::info("{} received: the run ended with a stop", signal_name(g_stop_signal.load()));
  report_links(*cell);
  if (cell->recorder) log_recording(cell->recorder->close());
  // With a reference, background.path is ignored, so nothing is saved there either.
  if (cell->background == BackgroundStart::learnt) save_learnt_background(config, *cell->pipeline);
  const std::string out_name = args.out.empty() ? "stdout" : args.out;
  out.flush();
  if (!out) return report_error(out_name + ": write failed; the run ended there", kExitRuntime);
  // The output ends with a stop line and a summary either way (when it can still be written);
  // the exit code tells scripts that the source, the processing or the output failed.
  if (!summary.error.empty()) return report_error(summary.error, kExitRuntime);
  return 0;
}

}  // namespace hrcsense::app
