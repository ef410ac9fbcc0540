// SPDX-License-Identifier: Apache-2.0
// hrcsense — sources, sinks, the per-frame processing path and the threads around it.
#pragma once

#include "hrcsense/filters.hpp"
#include "hrcsense/proximity.hpp"
#include "hrcsense/safety.hpp"
#include "hrcsense/segmentation.hpp"
#include "hrcsense/sim.hpp"
#include "hrcsense/types.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

namespace hrcsense {

/// What a source says about itself before the first frame.
struct SourceInfo {
  std::string type;             ///< "sim", "folder", "bag", ...
  std::string description;      ///< e.g. the scene or file
  Intrinsics intrinsics;        ///< of the depth stream
  float stereo_baseline_mm = 0.0F;  ///< 0 when unknown
  double nominal_fps = 30.0;    ///< for pacing when frames carry no usable timestamps
  int64_t frame_count = -1;     ///< -1 when unknown
};

/// A source of depth frames. One of the two virtual interfaces of hrcsense.
class Source {
 public:
  enum class Status { frame, end, error };
  virtual ~Source() = default;
  virtual SourceInfo info() const = 0;
  /// Reads the next frame into `out`, reusing its buffers. After `error`, error() says why.
  virtual Status next(Frame& out) = 0;
  virtual std::string error() const { return {}; }
};

/// The simulator as a source, ending after params.frames frames.
class SimSource : public Source {
 public:
  explicit SimSource(Simulator simulator) : sim_(std::move(simulator)) {}
  SourceInfo info() const override;
  Status next(Frame& out) override;

 private:
  Simulator sim_;
  int64_t next_index_ = 0;
};

/// What the run is about, written once before the first frame.
struct RunHeader {
  std::string version;  ///< empty: the JSON Lines sink writes the version it was built as
  std::string commit;   ///< empty: likewise the commit
  std::string config_hash;
  SourceInfo source;
  /// The depth filters as they run: `filters.preset`, the domain of filter_domain(), a note
  /// when the domain is not the one the preset asks for, and the filtered resolution.
  struct Filters {
    std::string preset;    ///< empty: not written (no configuration, e.g. in tests)
    std::string domain;    ///< "none", "disparity" or "depth"
    std::string note;      ///< e.g. why there is no disparity domain; empty for none
    Intrinsics intrinsics; ///< of the filtered image (background, Contact::pixel)
  } filters;
};

/// Source timestamps out of order, counted over a run (each frame against the one before).
struct TimestampCounts {
  int64_t backwards = 0;       ///< a timestamp earlier than the previous frame's
  int64_t repeated = 0;        ///< the same timestamp as the previous frame's
  int64_t gaps = 0;            ///< steps of more than 1.5 nominal periods (up to max_frame_age_s)
  int64_t frames_skipped = 0;  ///< frames missing in those gaps, at the nominal rate
  int64_t jumps = 0;           ///< steps longer than safety.max_frame_age_s (paced waits are cut there)
};

/// Totals written once at the end.
struct RunSummary {
  int64_t frames_in = 0;          ///< frames read from the source
  int64_t frames_processed = 0;   ///< frames that went through processing
  int64_t frames_dropped = 0;     ///< dropped by mailboxes (paced or live runs only)
  int64_t frames_valid = 0;
  int64_t verdict_run = 0, verdict_slow = 0, verdict_stop = 0;
  double wall_s = 0.0;
  double fps = 0.0;               ///< frames_processed / wall_s
  double latency_p50_us = 0.0, latency_p99_us = 0.0;
  float min_distance_m = -1.0F;   ///< smallest distance seen; -1 if never any foreground
  /// How the run ended: source_ended, frame_limit_reached, stop_requested, source_error,
  /// processing_error or output_error; end_reason says it for people.
  ReasonCode end_code = ReasonCode::source_ended;
  std::string end_reason;         ///< "end of source", or the source's error
  /// Why the run failed (source error, processing error, output failed); empty when it ended
  /// normally (end of source, frame limit, stop requested). The app exits 1 when set.
  std::string error;
  TimestampCounts timestamps;     ///< source timestamps out of order
};

/// A consumer of results. The other virtual interface of hrcsense.
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void header(const RunHeader& header) = 0;
  virtual void frame(const FrameResult& result) = 0;
  virtual void summary(const RunSummary& summary) = 0;
  /// True once the sink can no longer deliver results (a closed pipe, a full disk); the run
  /// then ends. failure() says why.
  virtual bool failed() const { return false; }
  virtual std::string failure() const { return {}; }
};

/// Single-slot, latest-value-wins mailbox between two threads. put() never blocks: a value
/// not yet taken is replaced and counted as dropped. take() waits for a value or close().
template <typename T>
class Mailbox {
 public:
  /// Stores `value` (swapped in, so buffers circulate without allocation). Never blocks.
  /// False (value kept) once closed: the consumer is gone and the producer should end.
  bool put(T& value) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return false;
    if (full_) ++dropped_;
    std::swap(slot_, value);
    full_ = true;
    ready_.notify_one();
    return true;
  }
  /// Like put(), but first waits until the slot is empty, so nothing is dropped: for unpaced
  /// runs, where the producer must wait for the consumer. False (value kept) once closed.
  bool put_wait(T& value) {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [&] { return !full_ || closed_; });
    if (closed_) return false;
    std::swap(slot_, value);
    full_ = true;
    ready_.notify_one();
    return true;
  }
  /// Waits for a value and swaps it into `out`; false once closed and empty.
  bool take(T& out) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [&] { return full_ || closed_; });
    if (!full_) return false;
    std::swap(slot_, out);
    full_ = false;
    space_.notify_one();
    return true;
  }
  /// Like take(), but gives up after `timeout_s`; false on timeout or when closed and empty.
  bool take_for(T& out, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return full_ || closed_; });
    if (!full_) return false;
    std::swap(slot_, out);
    full_ = false;
    space_.notify_one();
    return true;
  }
  bool closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_ && !full_;
  }
  void close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    ready_.notify_all();
    space_.notify_all();
  }
  int64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::condition_variable space_;  ///< signalled when the slot empties (put_wait)
  T slot_{};
  bool full_ = false;
  bool closed_ = false;
  int64_t dropped_ = 0;
};

/// A background loaded from a file contradicts the live scene (Pipeline::set_background).
class BackgroundMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Everything the processing path needs, already parsed (see config.hpp).
struct PipelineParams {
  FilterChainParams filters;  ///< depth filters run before segmentation; empty order: none
  Pose T_base_camera = Pose::Identity();
  RobotModel robot;
  BackgroundParams background;
  ForegroundParams foreground;
  SafetyParams safety;
  /// `proximity.backend`: brute, kdtree, octree or auto (depth_space later); the pipeline throws
  /// std::invalid_argument for another name.
  std::string backend = "brute";
  ProximityParams proximity;  ///< octree height, brute threads
};

/// The per-frame processing path: depth filters → background → foreground → proximity →
/// verdict, on the caller's thread (run_pipeline gives it a thread of its own; the brute-force
/// search may use a second one, `proximity.threads`). Owns the stages' state and scratch buffers.
class Pipeline {
 public:
  explicit Pipeline(PipelineParams params);
  /// The parameters the pipeline was built with (e.g. safety.max_frame_age_s for the watchdog).
  const PipelineParams& params() const { return params_; }
  /// Uses a background learnt earlier instead of learning from the first frames. The first
  /// BackgroundCheck::frames frames are compared with it first (stops); when they contradict
  /// it, process() throws BackgroundMismatch, naming `origin` (e.g. the file it came from).
  void set_background(BackgroundModel model, std::string origin = "the loaded background");
  bool background_ready() const { return learner_.ready() || preset_background_; }
  const BackgroundModel& background() const;
  /// Processes one frame into `result`, reusing its buffers.
  void process(const Frame& frame, FrameResult& result);
  const Foreground& foreground() const { return foreground_; }
  /// Why the background learning last restarted; empty if it never did.
  const std::string& background_message() const { return learner_.message(); }

 private:
  PipelineParams params_;
  BackgroundLearner learner_;
  bool preset_background_ = false;
  BackgroundModel preset_model_;
  std::string preset_origin_;  ///< where preset_model_ came from, for the mismatch error
  ForegroundExtractor extractor_;
  Foreground foreground_;
  FilterChain filters_;  ///< params_.filters; its temporal state spans frames
  ProximitySearch proximity_;  ///< params_.backend with its reusable search buffers
  Frame filtered_;       ///< the filtered copy of the current frame (buffers reused)
  BackgroundCheck check_;  ///< of a loaded background against the first frames

  bool enough_valid_depth(const Frame& frame, FrameResult& result) const;
  bool background_checked(const Frame& frame, FrameResult& result);
};

struct RunOptions {
  bool pace = false;         ///< play at the source's timestamps; frames may then be dropped
  int64_t max_frames = -1;   ///< stop after this many source frames; -1: until the source ends
  std::atomic<bool>* stop_requested = nullptr;  ///< set from outside (SIGINT, SIGTERM, SIGHUP) to end the run
};

/// Runs capture, processing and output on three threads joined by mailboxes. Unpaced runs
/// process every frame (the source waits for processing); paced runs drop and count.
/// Writes header, every result and the summary to `sink`; returns the summary.
RunSummary run_pipeline(Source& source, Pipeline& pipeline, Sink& sink, const RunOptions& options,
                        const RunHeader& header);

}  // namespace hrcsense
