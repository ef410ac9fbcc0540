// SPDX-License-Identifier: Apache-2.0
// hrcsense — the three threads around the processing path: capture, processing and output,
// joined by single-slot mailboxes, with a watchdog and a stop result at the end of every run.
// Every time decision asks the run's clock (RunOptions::clock), in integer nanoseconds.

#include "hrcsense/pipeline.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace hrcsense {
namespace {

double ns_to_seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// A frame with the run-clock time at which the source delivered it, for the frame's age.
struct Captured {
  Frame frame;
  int64_t captured_ns = 0;
  /// The frame's age counts from here on the run's clock: its host time when the source set
  /// one (a live camera's capture time), else the delivery (captured_ns).
  int64_t seen_ns = 0;
  const char* timestamp_warning = nullptr;  ///< static text; null when the timestamp is in order
};

// Why capture ended: the reason of the final stop result and the summary's end_reason.
struct CaptureOutcome {
  int64_t frames_in = 0;
  ReasonCode end_code = ReasonCode::source_ended;
  std::string final_reason = "source ended";
  std::string end_reason = "end of source";
  std::string error;  ///< the source's error; empty when it ended or was stopped
  TimestampCounts timestamps;
};

// Latencies kept for the percentiles. Preallocated; beyond its capacity the oldest entries
// are overwritten, so the percentiles then describe the most recent frames.
struct LatencyLog {
  std::vector<float> us;
  size_t next = 0;
  bool wrapped = false;

  explicit LatencyLog(size_t capacity) : us(std::max<size_t>(capacity, 1)) {}
  void add(double latency_us) {
    us[next] = static_cast<float>(latency_us);
    next = (next + 1) % us.size();
    wrapped = wrapped || next == 0;
  }
  /// Nearest-rank percentile, q in [0, 1]; 0 when empty. Reorders the log (end of run only).
  double percentile(double q) {
    const size_t n = wrapped ? us.size() : next;
    if (n == 0) return 0.0;
    const size_t rank = std::min(n - 1, static_cast<size_t>(q * static_cast<double>(n)));
    std::nth_element(us.begin(), us.begin() + static_cast<std::ptrdiff_t>(rank), us.begin() + static_cast<std::ptrdiff_t>(n));
    return us[rank];
  }
};

// Classifies a frame's timestamp step from the previous frame: backwards, repeated, a jump
// beyond max_frame_age_s, or a gap of more than 1.5 nominal periods (frames the source
// skipped); counts it and returns the warning for the frame (static text), null when in order.
const char* check_timestamp_step(int64_t step_ns, double nominal_fps, double max_frame_age_s, TimestampCounts& counts) {
  if (step_ns < 0) {
    ++counts.backwards;
    return "timestamp went backwards";
  }
  if (step_ns == 0) {
    ++counts.repeated;
    return "timestamp repeated";
  }
  const double step_s = static_cast<double>(step_ns) * 1e-9;
  if (step_s > max_frame_age_s) {
    ++counts.jumps;
    return "timestamp jumped by more than max_frame_age_s";
  }
  if (nominal_fps > 0.0 && step_s * nominal_fps > 1.5) {
    ++counts.gaps;
    counts.frames_skipped += static_cast<int64_t>(step_s * nominal_fps + 0.5) - 1;
    return "timestamp gap: frames skipped";
  }
  return nullptr;
}

// When paced, each frame is due one timestamp step after the previous one. A step that is not
// positive (repeated or backwards timestamps, sources without timestamps) takes the nominal
// period; a step longer than max_frame_age_s (a jump in the recording) is cut to
// max_frame_age_s, so a replay never sleeps for days.
int64_t pacing_step_ns(int64_t step_ns, double nominal_fps, int64_t max_frame_age_ns) {
  if (step_ns <= 0) step_ns = nominal_fps > 0.0 ? seconds_to_ns(1.0 / nominal_fps) : 0;
  return std::min(step_ns, max_frame_age_ns);
}

bool stop_requested(const RunOptions& options) {
  return options.stop_requested != nullptr && options.stop_requested->load();
}

// Whether capture is to end before frame n: a stop request or the frame limit (max_frames);
// `outcome` then says which.
bool capture_should_end(const RunOptions& options, int64_t n, CaptureOutcome& outcome) {
  if (stop_requested(options)) {
    outcome.end_code = ReasonCode::stop_requested;
    outcome.final_reason = outcome.end_reason = "stop requested";
    return true;
  }
  if (options.max_frames >= 0 && n >= options.max_frames) {
    outcome.end_code = ReasonCode::frame_limit_reached;
    outcome.final_reason = outcome.end_reason = "frame limit reached";
    return true;
  }
  return false;
}

// The source's next frame into `frame`; a source that throws has failed, with the exception's
// text as its error.
Source::Status read_frame(Source& source, Frame& frame, std::string& error) {
  Source::Status status = Source::Status::error;
  frame.host_time_ns = 0;  // the buffer is reused: only a live source sets it again
  try {
    status = source.next(frame);
    if (status == Source::Status::error) error = source.error();
  } catch (const std::exception& e) {
    error = e.what();
  }
  return status;
}

// Stamps a frame with its delivery on the run's clock; the frame's age counts from its host
// time when the source set one, and a frame without one gets the source's or the run's time.
void stamp_delivery(Captured& slot, int64_t captured_ns, bool host_time_is_source_time) {
  slot.captured_ns = captured_ns;
  slot.seen_ns = slot.frame.host_time_ns != 0 ? std::min(slot.frame.host_time_ns, slot.captured_ns) : slot.captured_ns;
  if (slot.frame.host_time_ns == 0) {
    slot.frame.host_time_ns = host_time_is_source_time ? slot.frame.timestamp_ns : slot.captured_ns;
  }
}

// Reads the source until it ends, fails, or the run is stopped; then closes `frames`. Paced
// waits are the clock's sleep_until, which a stop request (SIGINT, SIGTERM) ends. With
// `latest_wins` (paced or live) a frame processing has not yet taken is replaced and counted;
// else the source waits for processing.
void capture_loop(Source& source, const RunOptions& options, RunClock& clock, double max_frame_age_s,
                  bool host_time_is_source_time, bool latest_wins, Mailbox<Captured>& frames,
                  CaptureOutcome& outcome) {
  const double nominal_fps = source.info().nominal_fps;
  const int64_t max_frame_age_ns = seconds_to_ns(max_frame_age_s);
  Captured slot;
  int64_t due_ns = 0;  // paced: when the current frame is to be delivered
  int64_t previous_ns = 0;
  bool resync = true;  // pace from now: at the first frame and after a silence (a paused replay)
  for (int64_t n = 0;; ++n) {
    if (capture_should_end(options, n, outcome)) break;
    std::string error;
    const Source::Status status = read_frame(source, slot.frame, error);
    if (status == Source::Status::end) {
      // A live source's wait (an unplugged camera) ends with `end` on a stop request: say so.
      if (stop_requested(options)) {
        outcome.end_code = ReasonCode::stop_requested;
        outcome.final_reason = outcome.end_reason = "stop requested";
      }
      break;  // otherwise the defaults say "source ended"
    }
    if (status == Source::Status::idle) {  // no frame yet: the output loop's watchdog stops the cell
      --n;
      resync = true;  // else the frames after the silence would all be due at once
      continue;
    }
    if (status == Source::Status::error) {
      outcome.end_code = ReasonCode::source_error;
      outcome.error = "source error: " + (error.empty() ? std::string("unknown") : error);
      outcome.final_reason = outcome.end_reason = outcome.error;
      break;
    }
    ++outcome.frames_in;
    const int64_t step_ns = slot.frame.timestamp_ns - previous_ns;
    previous_ns = slot.frame.timestamp_ns;
    slot.timestamp_warning =
        n == 0 ? nullptr : check_timestamp_step(step_ns, nominal_fps, max_frame_age_s, outcome.timestamps);
    if (options.pace) {
      due_ns = resync ? clock.now_ns() : due_ns + pacing_step_ns(step_ns, nominal_fps, max_frame_age_ns);
      resync = false;
      clock.sleep_until(due_ns, options.stop_requested);
    }
    stamp_delivery(slot, clock.now_ns(), host_time_is_source_time);
    // Paced or live: latest wins, a frame not yet taken is dropped and counted (a live camera
    // does not wait, and a frame held back would only grow older). Unpaced files and the
    // simulator: wait for processing. Either fails once processing is gone.
    if (!(latest_wins ? frames.put(slot) : frames.put_wait(slot))) break;
  }
  frames.close();
}

// What the processing thread counts.
struct ProcessingStats {
  int64_t processed = 0;
  LatencyLog latencies;
  std::string error;
};

// A frame withheld for want of a robot state says what the source knows about it (a refused
// connection, a rejected sample, nothing received), so that the fault shows on the frame.
void say_why_no_robot_state(const RobotStateSource& robot_states, Measurement& m) {
  if (m.withheld_code != ReasonCode::no_robot_state && m.withheld_code != ReasonCode::robot_state_stale) return;
  std::string why = robot_states.error();
  if (why.empty()) why = robot_states.stats().last_problem;
  if (!why.empty()) m.withheld_reason += ": " + why;
}

// Measures every frame it takes and hands the measurement to the output, where the monitor
// decides it. With `latest_wins`, a measurement that replaces one not yet taken carries that
// one's verdict (carry_replaced), so a stop is never dropped unseen. Closes `results` when
// `frames` is closed and drained.
void processing_loop(Pipeline& pipeline, RobotStateSource& robot_states, const RunOptions& options,
                     bool latest_wins, const RunClock& clock, const SafetyMonitor& monitor,
                     Mailbox<Captured>& frames, Mailbox<FrameResult>& results, ProcessingStats& stats) {
  const int64_t camera_latency_ns = robot_state_lookup_offset_ns(robot_states.origin(), options.camera_latency_s);
  const auto carry = [&](const FrameResult& replaced, FrameResult& next) {
    carry_replaced(monitor, replaced, clock.now_ns(), next);
  };
  Captured in;
  FrameResult result;
  FrameResult previous;  // for before_process; its buffers are reused
  RobotState robot_state;
  try {
    while (frames.take(in)) {
      if (options.before_process) options.before_process(pipeline, previous);
      // The robot as it was when the camera saw the frame; none withholds it (Pipeline::process).
      if (!robot_states.state_at(in.frame.host_time_ns - camera_latency_ns, robot_state)) robot_state.valid = false;
      pipeline.process(in.frame, robot_state, result);
      if (!robot_state.valid) say_why_no_robot_state(robot_states, result);
      result.timestamp_warning = in.timestamp_warning;
      result.clocked = true;
      result.delivered_ns = in.captured_ns;
      result.seen_ns = in.seen_ns;
      result.replaced.count = 0;
      if (options.on_processed) options.on_processed(in.frame, pipeline, result);
      if (options.before_process) previous = result;  // put() swaps `result` with an older buffer
      ++stats.processed;
      stats.latencies.add(result.latency_us);
      if (!(latest_wins ? results.put(result, carry) : results.put_wait(result))) break;  // the output ended
    }
  } catch (const std::exception& e) {
    stats.error = "processing error at frame " + std::to_string(in.frame.index) + ": " + e.what();
  }
  frames.close();  // the capture thread must not wait for a consumer that is gone
  results.close();
}

// A stop result that stands for no source frame (watchdog, end of run): it repeats the last
// frame's index and timestamp, so that the output's frame numbers never go backwards.
void write_stop(Sink& sink, FrameResult& scratch, const FrameResult& last, Verdict verdict) {
  scratch.source_frame = false;
  scratch.frame = last.frame;
  scratch.timestamp_ns = last.timestamp_ns;
  scratch.host_time_ns = last.host_time_ns;
  scratch.robot_state = RobotState{};  // a stop that stands for no frame measured against no robot
  scratch.robot_state_age_ms = 0.0;
  scratch.valid = false;
  scratch.verdict = std::move(verdict);
  scratch.withheld_code = scratch.verdict.code;
  scratch.contact = Contact{};
  scratch.links.clear();
  scratch.ssm.reset();
  scratch.governing_link = -1;
  scratch.link_protective_distance_m.clear();
  scratch.distance_uncertainty_m = std::numeric_limits<float>::quiet_NaN();
  scratch.robot_speed_towards_mps = std::numeric_limits<float>::quiet_NaN();
  scratch.robot_speed_fraction = std::numeric_limits<double>::quiet_NaN();
  scratch.unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
  scratch.truth_links.clear();
  scratch.foreground_points = 0;
  scratch.invalid_pixels = 0;
  scratch.valid_share = 0.0F;
  scratch.timings.clear();
  scratch.truth.reset();
  scratch.latency_us = 0.0;
  scratch.timestamp_warning = nullptr;
  sink.frame(scratch);
}

void tally(RunSummary& summary, const FrameResult& result) {
  summary.frames_valid += result.valid ? 1 : 0;
  switch (result.verdict.state) {
    case VerdictState::run: ++summary.verdict_run; break;
    case VerdictState::slow: ++summary.verdict_slow; break;
    case VerdictState::stop: ++summary.verdict_stop; break;
  }
  summary.robot_status.add(result.robot_state.status);  // reported only: the verdict is made without it
  if (result.contact.valid && (summary.min_distance_m < 0.0F || result.contact.distance_m < summary.min_distance_m)) {
    summary.min_distance_m = result.contact.distance_m;
  }
}

// Takes the next result into `out`, waiting until `deadline_ns` on `clock`. The wait is in
// real-time slices of at most 10 ms with a look at the clock after each, so that the clock (a
// fake one too) decides when the time is up; on the steady clock the last slice ends at the
// deadline, as one wait would. A result that is there at the deadline still counts. False when
// the deadline passed without one, or when `results` is closed and empty.
bool take_until(Mailbox<FrameResult>& results, FrameResult& out, const RunClock& clock, int64_t deadline_ns) {
  constexpr int64_t kSliceNs = 10'000'000;
  for (;;) {
    const int64_t left_ns = deadline_ns - clock.now_ns();
    if (left_ns <= 0) return results.take_for(out, 0.0);
    if (results.take_for(out, ns_to_seconds(std::min(left_ns, kSliceNs)))) return true;
    if (results.closed()) return false;
  }
}

// Writes every result; when none arrives within the watchdog's limit (on the run clock), writes
// a watchdog stop (with the source's reason for the silence: no_frame, or camera_disconnected),
// and another each limit after it. The wait for the next result
// starts when the last write ended, at the one clock reading after each write (tests rely on
// it). Ends early when the sink fails (a closed pipe, a full disk): closes `results` so that
// processing and capture end too, and says why in `error`. Returns the last result written
// (for the final stop's frame index).
FrameResult output_loop(Sink& sink, const Source& source, const RunClock& clock, SafetyMonitor& monitor,
                        Mailbox<FrameResult>& results, RunSummary& summary, std::string& error) {
  const int64_t max_frame_age_ns = monitor.watchdog_after_ns();
  FrameResult result, last, watchdog;
  int64_t last_arrival_ns = clock.now_ns();
  int64_t waiting_since_ns = last_arrival_ns;
  try {
    for (;;) {
      if (sink.failed()) {
        error = "output failed: " + sink.failure();
        break;
      }
      if (take_until(results, result, clock, waiting_since_ns + max_frame_age_ns)) {
        // Decided here, immediately before the write, at the frame's age as it is now.
        monitor.decide(result, clock.now_ns());
        sink.frame(result);
        tally(summary, result);
        last_arrival_ns = waiting_since_ns = clock.now_ns();
        std::swap(last, result);
        continue;
      }
      if (results.closed()) break;
      const ReasonCode silence = source.silence_reason();
      char reason[128];
      std::snprintf(reason, sizeof reason, "%sno frame for %.3f s (%s)",
                    silence == ReasonCode::camera_disconnected ? "camera disconnected: " : "",
                    ns_to_seconds(clock.now_ns() - last_arrival_ns), monitor.watchdog_rule());
      write_stop(sink, watchdog, last, monitor.silence(silence, reason));
      waiting_since_ns = clock.now_ns();
    }
  } catch (const std::exception& e) {
    error = std::string("output error: ") + e.what();
  }
  results.close();
  return last;
}

// The first failure is the run's error: the output's, else processing's, else the source's;
// it is then the final stop's reason and the summary's end_reason too.
void settle_run_error(const std::string& output_error, const ProcessingStats& stats, CaptureOutcome& outcome,
                      RunSummary& summary) {
  summary.end_code = outcome.end_code;
  if (!output_error.empty()) {
    summary.end_code = ReasonCode::output_error;
    summary.error = output_error;
  } else if (!stats.error.empty()) {
    summary.end_code = ReasonCode::processing_error;
    summary.error = stats.error;
  } else {
    summary.error = outcome.error;
  }
  if (!summary.error.empty()) outcome.final_reason = outcome.end_reason = summary.error;
}

// Fail safe: whatever ended the run, the last word to the robot is a stop (a failed sink
// gets it too: it may still reach a file whose pipe reader left); the summary follows it.
void write_run_end(Sink& sink, const FrameResult& last, const std::string& final_reason, const RunClock& clock,
                   int64_t start_ns, RunSummary& summary) {
  try {
    FrameResult scratch;
    write_stop(sink, scratch, last, stop_verdict(summary.end_code, final_reason));
    summary.wall_s = ns_to_seconds(clock.now_ns() - start_ns);
    summary.fps = summary.wall_s > 0.0 ? static_cast<double>(summary.frames_processed) / summary.wall_s : 0.0;
    sink.summary(summary);
  } catch (const std::exception& e) {
    if (summary.error.empty()) summary.error = std::string("output error: ") + e.what();
  }
  if (summary.error.empty() && sink.failed()) summary.error = "output failed: " + sink.failure();
}

}  // namespace

bool host_time_is_source_time(RobotStateOrigin origin, bool paced) {
  // The simulated arm lives on the simulator's timeline and a recorded one on the recording's,
  // and so do unpaced runs against a fixed arm; paced runs and live robot states live on the host's.
  return origin == RobotStateOrigin::sim || origin == RobotStateOrigin::recorded ||
         (!paced && origin == RobotStateOrigin::fixed);
}

int64_t robot_state_lookup_offset_ns(RobotStateOrigin origin, double camera_latency_s) {
  if (origin == RobotStateOrigin::recorded) return 0;
  return std::llround(camera_latency_s * 1e9);
}

RunSummary run_pipeline(Source& source, RobotStateSource& robot_states, Pipeline& pipeline, Sink& sink,
                        const RunOptions& options, const RunHeader& header) {
  SteadyClock steady;
  RunClock& clock = options.clock != nullptr ? *options.clock : steady;
  const int64_t start_ns = clock.now_ns();
  const double max_frame_age_s = pipeline.params().safety.max_frame_age_s;
  const int64_t expected = options.max_frames >= 0 ? options.max_frames : source.info().frame_count;
  // The latency log is a ring: a long or endless run keeps the most recent million frames.
  constexpr int64_t kMaxLatencyCapacity = 1 << 20;
  const int64_t capacity = expected > 0 ? std::min(expected, kMaxLatencyCapacity) : kMaxLatencyCapacity;
  ProcessingStats stats{0, LatencyLog(static_cast<size_t>(capacity)), {}};
  Mailbox<Captured> frames;
  Mailbox<FrameResult> results;
  CaptureOutcome outcome;
  RunSummary summary;
  std::string output_error;

  sink.header(header);
  const bool source_time = host_time_is_source_time(robot_states.origin(), options.pace);
  // Sources that deliver at a rate (live or paced) drop what processing cannot take, and the
  // watchdog counts their nominal periods.
  const bool at_a_rate = source.info().live || options.pace;
  std::thread capture(
      [&] { capture_loop(source, options, clock, max_frame_age_s, source_time, at_a_rate, frames, outcome); });
  SafetyMonitor monitor(pipeline.params().safety, source.info().nominal_fps, at_a_rate);
  std::thread processing(
      [&] { processing_loop(pipeline, robot_states, options, at_a_rate, clock, monitor, frames, results, stats); });
  const FrameResult last = output_loop(sink, source, clock, monitor, results, summary, output_error);
  processing.join();
  capture.join();

  settle_run_error(output_error, stats, outcome, summary);
  summary.frames_in = outcome.frames_in;
  summary.frames_processed = stats.processed;
  summary.frames_dropped = frames.dropped() + results.dropped();
  summary.frames_dropped_camera = source.frames_dropped_camera();
  summary.timestamps = outcome.timestamps;
  summary.robot_state = robot_states.stats();
  summary.unknown_background_share = pipeline.unknown_background_share();
  summary.end_reason = outcome.end_reason;
  summary.latency_p50_us = stats.latencies.percentile(0.50);
  summary.latency_p99_us = stats.latencies.percentile(0.99);
  write_run_end(sink, last, outcome.final_reason, clock, start_ns, summary);
  return summary;
}

}  // namespace hrcsense
