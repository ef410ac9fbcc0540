// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — one run of the configured cell (run_session.hpp).
#include "common/run_session.hpp"

#include "common/app_errors.hpp"
#include "common/assembly.hpp"
#include "common/background_start.hpp"
#include "common/console_sink.hpp"
#include "common/fault_log.hpp"
#include "common/follow_link_sink.hpp"
#include "common/record_setup.hpp"
#include "common/tee_sink.hpp"
#include "common/truth_label_sink.hpp"

#include "hrcsense/recorder.hpp"
#include "hrcsense/sinks.hpp"

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

// SIGPIPE is ignored for the whole run: a reader that goes away makes the write fail (EPIPE),
// and the failed sink ends the run, instead of the signal killing it mid-line.
void install_signal_handlers() {
  g_stop_requested.store(false);
  g_stop_signal.store(0);
  for (int signal : kStopSignals) std::signal(signal, on_stop_signal);
  std::signal(SIGPIPE, SIG_IGN);
}

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

// Adds the recorder's counters to the summary. The summary comes after the run's final stop, so
// closing the recording here (writing what is still queued) never delays a verdict.
class RecordCountersSink final : public Sink {
 public:
  RecordCountersSink(Sink& inner, Recorder& recorder) : inner_(inner), recorder_(recorder) {}
  void header(const RunHeader& header) override { inner_.header(header); }
  void frame(const FrameResult& result) override { inner_.frame(result); }
  void summary(const RunSummary& summary) override {
    RunSummary with_record = summary;
    const RecorderStats stats = recorder_.close();
    with_record.record = RecordCounters{stats.frames_recorded, stats.frames_dropped, stats.files, stats.error};
    inner_.summary(with_record);
  }
  bool failed() const override { return inner_.failed(); }
  std::string failure() const override { return inner_.failure(); }

 private:
  Sink& inner_;
  Recorder& recorder_;
};

// Adds the viewer's drops to the summary (the viewer's mailbox, read after the run).
class ViewerCountersSink final : public Sink {
 public:
  ViewerCountersSink(Sink& inner, std::function<int64_t()> dropped) : inner_(inner), dropped_(std::move(dropped)) {}
  void header(const RunHeader& header) override { inner_.header(header); }
  void frame(const FrameResult& result) override { inner_.frame(result); }
  void summary(const RunSummary& summary) override {
    RunSummary with_viewer = summary;
    with_viewer.viewer_frames_dropped = dropped_();
    inner_.summary(with_viewer);
  }
  bool failed() const override { return inner_.failed(); }
  std::string failure() const override { return inner_.failure(); }

 private:
  Sink& inner_;
  std::function<int64_t()> dropped_;
};

// What each part of the run can say is wrong while it runs (fault_log.hpp).
std::vector<FaultProbe> fault_probes(const RobotStateSource& robot_states, const Recorder* recorder,
                                     const UdpLinkSink* link, const RtdeLinkSink* rtde_link) {
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

}  // namespace

void request_session_stop() { g_stop_requested.store(true); }

int run_session(const Config& config, const SessionOptions& args) {
  const bool paced = config.source.pace && !args.unpaced;
  // Before anything is opened: a recording never silently replaces a file, nor the source.
  if (!args.record.empty()) check_record_output(config, args.record, args.overwrite);
  SourceOptions source_options;
  source_options.stop_requested = &g_stop_requested;
  // A recording keeps the source's colour, so --record decodes it even where processing does not.
  source_options.with_color = args.with_color || !args.record.empty();
  // robot.trajectory.follow_link: the simulated arm, its state and its truth obey what is sent.
  const std::shared_ptr<TrajectoryClock> trajectory_clock = make_trajectory_clock(config);
  if (trajectory_clock) trajectory_clock->set_lockstep(!paced);
  source_options.trajectory_clock = trajectory_clock;
  // From here a signal ends the run with a stop line and a summary, also while a live camera
  // is still awaited; the handlers go when the session does, however it ends.
  const SignalHandlers signal_handlers;
  std::unique_ptr<Source> source;
  bool source_started = true;
  try {
    source = make_source(config, source_options);
  } catch (const SourceStartError& e) {
    // The run still says so as every run does: header, stop, summary (source_error, exit 1).
    source = std::make_unique<UnstartedSource>(source_type_name(config.source.type), e.what());
    source_started = false;
  }
  std::unique_ptr<RobotStateSource> robot_states = make_robot_state_source(config, *source, nullptr, trajectory_clock);
  if (args.wrap_recording && is_recording(config.source.type)) {
    // The robot states may come from the first source: the wrapper keeps it alive.
    source = args.wrap_recording(std::move(source), [config, source_options] { return make_source(config, source_options); });
  }
  const SourceInfo info = source->info();
  // --record: the source's frames, as delivered, to a bag on a writer thread (never blocking),
  // each with the robot state processing will measure it against.
  std::unique_ptr<RobotStateSource> recorder_states;
  std::optional<Recorder> recorder;
  std::optional<RecordingSource> recording;
  if (!args.record.empty()) {
    RecorderParams params = recorder_params(config, args.record, info);
    const RecordOnError on_error = params.on_error;
    recorder.emplace(std::move(params));
    RecordStateLookup lookup =
        record_state_lookup(config, *source, *robot_states, paced, recorder_states, trajectory_clock);
    lookup.from_processing = true;  // the state each frame was measured against (on_processed below)
    recording.emplace(*source, *recorder, on_error, lookup);
  }
  Source& frames = recording ? static_cast<Source&>(*recording) : *source;

  Pipeline pipeline(config.pipeline);
  const BackgroundStart background_start = start_background(config, info, pipeline);

  std::ofstream file;
  if (!args.out.empty()) {
    const std::filesystem::path parent = std::filesystem::path(args.out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    file.open(args.out, std::ios::out | std::ios::trunc);
    if (!file) return report_error(args.out + ": cannot open for writing", kExitRuntime);
  }
  std::ostream& out = args.out.empty() ? std::cout : file;

  JsonLinesSink jsonl(out, proximity_backend_name(config.pipeline.backend));
  ConsoleSink console;
  // Simulated runs: truth.contact_label from the simulator's own labels (TruthLabelSink).
  std::optional<TruthLabelSink> labelled;
  if (config.source.type == SourceType::sim) labelled.emplace(make_simulator(config, trajectory_clock), jsonl);
  // link.udp.address: the verdicts to the controller, first, so that no file or console write
  // delays a datagram.
  const std::unique_ptr<UdpLinkSink> link = make_udp_link_sink(config);
  if (link) {
    spdlog::info("link: verdicts to {} ({}, heartbeat {} Hz)", link->address(), udp_format_name(config.link.udp_format),
                 config.link.heartbeat_hz);
  }
  // link.rtde.write: the speed scale to the controller's RTDE inputs (its own connection).
  const std::unique_ptr<RtdeLinkSink> rtde_link = make_rtde_link_sink(config);
  if (rtde_link) spdlog::info("link: speed scale to RTDE {}:{} ({})", config.robot_state.host, config.robot_state.port,
                              rtde_link->input_names());
  // follow_link: the simulated arm takes the scale the links have just sent.
  std::optional<FollowLinkSink> follow;
  if (trajectory_clock) follow.emplace(trajectory_clock);
  // A viewer's sink last: the controller, the files and the console have each result first.
  TeeSink tee{link.get(), rtde_link.get(), follow ? &*follow : nullptr,
              labelled ? static_cast<Sink*>(&*labelled) : &jsonl, &console, args.viewer_sink};
  std::optional<RecordCountersSink> with_record;
  if (recorder) with_record.emplace(tee, *recorder);
  Sink& recorded = with_record ? static_cast<Sink&>(*with_record) : tee;
  std::optional<ViewerCountersSink> with_viewer;
  if (args.viewer_frames_dropped) with_viewer.emplace(recorded, args.viewer_frames_dropped);
  Sink& counted = with_viewer ? static_cast<Sink&>(*with_viewer) : recorded;
  // Faults said when they start and when they clear, not only in the summary.
  FaultLogSink sinks(counted, fault_probes(*robot_states, recorder ? &*recorder : nullptr, link.get(), rtde_link.get()),
                     [] { return SteadyClock().now_ns(); });

  RunHeader header = make_run_header(config, info);
  header.unknown_background_share = pipeline.unknown_background_share();  // a loaded background's
  if (!header.filters.note.empty()) spdlog::warn("filters: {}", header.filters.note);

  RunOptions options;
  options.pace = paced;
  options.camera_latency_s = config.robot_state.camera_latency_s;
  options.max_frames = args.frames;
  // A source that never started has nothing to stop: its error, not the signal that ended the
  // wait, is how the run ends.
  options.stop_requested = source_started ? &g_stop_requested : nullptr;
  options.on_processed = args.on_processed;
  if (recorder) {
    // The recording holds the state processing used, so its replay decides as this run did.
    options.on_processed = [&recorder, &args](const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
      recorder->state_used(frame.index, result.robot_state);
      if (args.on_processed) args.on_processed(frame, pipeline, result);
    };
  }
  options.before_process = args.before_process;
  const RunSummary summary = run_pipeline(frames, *robot_states, pipeline, sinks, options, header);
  if (g_stop_signal.load() != 0) spdlog::info("{} received: the run ended with a stop", signal_name(g_stop_signal.load()));

  if (link) {
    if (link->counters().send_errors > 0) {
      spdlog::warn("{}", describe_link_counters(*link));
    } else {
      spdlog::info("{}", describe_link_counters(*link));
    }
  }
  if (rtde_link) {
    const RtdeLinkCounters counters = rtde_link->counters();
    if (counters.disconnects + counters.refusals + counters.malformed > 0 || counters.writes == 0) {
      spdlog::warn("{}", describe_link_counters(*rtde_link));
    } else {
      spdlog::info("{}", describe_link_counters(*rtde_link));
    }
  }
  if (recorder) log_recording(recorder->close());
  // With a reference, background.path is ignored, so nothing is saved there either.
  if (background_start == BackgroundStart::learnt) save_learnt_background(config, pipeline);
  const std::string out_name = args.out.empty() ? "stdout" : args.out;
  out.flush();
  if (!out) return report_error(out_name + ": write failed; the run ended there", kExitRuntime);
  // The output ends with a stop line and a summary either way (when it can still be written);
  // the exit code tells scripts that the source, the processing or the output failed.
  if (!summary.error.empty()) return report_error(summary.error, kExitRuntime);
  return 0;
}

}  // namespace hrcsense::app
