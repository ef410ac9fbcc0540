// SPDX-License-Identifier: Apache-2.0
// hrcsense — recording frames to RealSense .bag files on a writer thread of their own: a
// bounded queue between the caller and the file, so that a slow disk costs dropped recorded
// frames (counted), never a late frame in processing.
#pragma once

#include "hrcsense/recordings/bag_writer.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/source.hpp"
#include "hrcsense/types.hpp"

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {

struct RecorderParams {
  std::string path;               ///< FILE.bag; with split_mb > 0 the files are FILE-000.bag, FILE-001.bag, ...
  int64_t split_mb = 0;           ///< `record.split_mb`: start a new file past this many MiB; 0: one file
  RecordOnError on_error = RecordOnError::stop_run;  ///< `record.on_error`
  int queue_frames = 16;          ///< frames waiting for the writer before new ones are dropped
  BagWriterParams bag;            ///< depth_units_option_m and stereo_baseline_mm come from the first frame
};

struct RecorderStats {
  int64_t frames_recorded = 0;  ///< frames handed to the writer and written (into a chunk)
  int64_t frames_dropped = 0;   ///< frames not recorded: queue full, or after a write error
  std::vector<std::string> files;  ///< the files started, in order
  std::string error;            ///< the first write error, naming the file; empty when none
};

/// The file of split number `part` (0-based) for `path`: "rec.bag" -> "rec-000.bag".
std::string split_file_name(const std::string& path, int part);

/// Records frames on a thread of its own. push() never waits for the disk.
class Recorder {
 public:
  explicit Recorder(RecorderParams params);
  ~Recorder();  ///< close()s; errors then only stay in stats()
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Queues a copy of `frame` (and the robot's state at it, when given: joints and velocities
  /// go to /hrcsense/joint_states) for the writer; false when it was dropped (queue full, or
  /// recording ended by an error). Never blocks on the disk.
  bool push(const Frame& frame, const std::optional<RobotState>& robot_state = std::nullopt);
  /// As push(), but waits (at most `timeout_ms`) for room in the queue: for `hrcsense record`,
  /// where the recorder is the only consumer and should lose nothing to a fast source.
  bool push_wait(const Frame& frame, int timeout_ms, const std::optional<RobotState>& robot_state = std::nullopt);
  /// As push(), but the joint state written for the frame is the one processing measured it
  /// against, reported by state_used(): so that a replay of the recording decides on what the
  /// live run decided on, never on a state looked up a moment earlier. `fallback` (the capture
  /// time's lookup) is written instead when processing never takes the frame (a paced run
  /// replaced it by a newer one, the run ended) or says nothing within kStateWaitMs.
  bool push_awaiting_state(const Frame& frame, const std::optional<RobotState>& fallback);
  /// From processing: frame `frame_index` was measured against `state` (not valid: against
  /// none; the frame is then recorded without a joint state). Frames pushed before it that
  /// still await theirs were never processed.
  void state_used(int64_t frame_index, const RobotState& state);
  static constexpr int kStateWaitMs = 1000;
  /// True once a write error happened (stats().error says which file and why).
  bool failed() const;
  /// Writes what is queued, closes (and indexes) the last file, joins the thread. Idempotent.
  RecorderStats close();
  RecorderStats stats() const;

 private:
  struct Item {
    Frame frame;
    std::optional<RobotState> robot_state;
    bool awaiting_state = false;  ///< push_awaiting_state: robot_state is the fallback until state_used()
  };
  bool enqueue(const Frame& frame, const std::optional<RobotState>& robot_state, int timeout_ms, bool awaiting_state);
  /// The front item can be written: its state is known, or it never will be.
  bool front_ready() const;
  void writer_loop();
  void write_item(const Item& item);
  void open_next_file(const Frame& first);

  RecorderParams params_;
  mutable std::mutex mutex_;
  std::condition_variable wake_writer_, room_;
  std::deque<Item> queue_;
  std::vector<Item> spare_;  ///< written items whose buffers push() reuses (no allocation per frame)
  bool closing_ = false;
  bool writer_exited_ = false;  ///< the writer thread has left its loop: later items would stay queued
  int64_t processed_index_ = -1;  ///< the newest frame index state_used() reported
  RecorderStats stats_;
  std::unique_ptr<BagWriter> writer_;  ///< writer thread only
  int part_ = 0;
  std::thread thread_;
};

/// How the robot state of a frame is found for its recording: the way run_pipeline's
/// processing will look it up (docs/RECORDINGS.md, "Joint states"), so that the recording holds
/// the state the frame was measured against.
struct RecordStateLookup {
  RobotStateSource* states = nullptr;    ///< null: no joint states are recorded
  /// Processing reports each frame's state (Recorder::state_used, `hrcsense run --record`): the
  /// lookup below is then only the fallback for frames processing never takes.
  bool from_processing = false;
  /// host_time_is_source_time(origin, paced) of the run: a frame without its own host time is
  /// looked up at its timestamp (true) or at its delivery time on `clock` (false).
  bool host_time_is_source_time = true;
  int64_t lookup_offset_ns = 0;          ///< robot_state_lookup_offset_ns(origin, camera_latency_s)
  const RunClock* clock = nullptr;       ///< the run's clock; null: the steady clock
};

/// The state `lookup.states` gives for `frame` at the time processing will ask for it; nullopt
/// when it has no valid one (the frame is then recorded without joints, and replays as a stop).
std::optional<RobotState> robot_state_for_recording(const Frame& frame, const RecordStateLookup& lookup);

/// A Source that records every frame its inner source delivers (before any filter), with the
/// robot state of `lookup`, and passes it on unchanged. With record.on_error stop, a write
/// error ends the source with that error.
class RecordingSource : public Source {
 public:
  RecordingSource(Source& inner, Recorder& recorder, RecordOnError on_error, RecordStateLookup lookup = {})
      : inner_(inner), recorder_(recorder), on_error_(on_error), lookup_(lookup) {}
  SourceInfo info() const override { return inner_.info(); }
  Status next(Frame& out) override;
  std::string error() const override { return error_.empty() ? inner_.error() : error_; }
  int64_t frames_dropped_camera() const override { return inner_.frames_dropped_camera(); }
  ReasonCode silence_reason() const override { return inner_.silence_reason(); }

 private:
  Source& inner_;
  Recorder& recorder_;
  RecordOnError on_error_;
  RecordStateLookup lookup_;
  std::string error_;
};

}  // namespace hrcsense
