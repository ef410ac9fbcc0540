// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — pause, step and seek in a recording (.bag or folder source). The viewer
// sets what it wants on a PlaybackControl; the capture thread's PlaybackSource follows it.
// While paused no frame reaches the pipeline, so its watchdog stops the cell (no_frame) and
// the view says NO DATA: a paused replay is never a `run`.
#pragma once

#include "hrcsense/source.hpp"

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

namespace hrcsense::view {

/// What the viewer asks of the replay; thread-safe.
class PlaybackControl {
 public:
  void set_paused(bool paused);
  bool paused() const;
  /// While paused: let one more frame through.
  void step();
  /// The next frame delivered is the one at `position` (0-based, in delivery order of the
  /// recording); plays on or stays paused as it was, showing that frame either way.
  void seek(int64_t position);
  /// The position of the newest frame delivered (0-based); -1 before the first.
  int64_t position() const;
  /// Frames a seek forward read and dropped so far.
  int64_t skipped() const;
  void add_skipped(int64_t frames);
  /// The recording's length in frames, -1 when unknown (set by PlaybackSource).
  int64_t frame_count() const;
  void set_frame_count(int64_t count);

  /// The capture thread's side. Waits at most `wait_s` until a frame may go; false: not yet
  /// (PlaybackSource then reports `idle`). `seek_to` gets a pending seek's position, or -1.
  bool wait_until_go(double wait_s, int64_t& seek_to);
  /// A frame at `position` went out.
  void delivered(int64_t position);
  /// Wakes a waiting capture thread (the run is ending).
  void wake();

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool paused_ = false;
  int steps_ = 0;           ///< frames allowed through while paused
  int64_t seek_to_ = -1;    ///< pending seek, -1: none
  int64_t position_ = -1;   ///< of the newest frame delivered
  int64_t frame_count_ = -1;
  int64_t skipped_ = 0;
};

/// A recording that follows a PlaybackControl. A seek forward reads and drops the frames in
/// between; a seek back opens the recording again (`open`) and reads up to the position. The
/// first source (the one robot states may have been read from) stays alive for the run.
class PlaybackSource final : public Source {
 public:
  /// `first`: the opened recording; `open`: opens it again from its start.
  PlaybackSource(std::unique_ptr<Source> first, std::function<std::unique_ptr<Source>()> open,
                 PlaybackControl& control);
  SourceInfo info() const override { return info_; }
  Status next(Frame& out) override;
  std::string error() const override { return current_->error(); }

 private:
  Status reposition(int64_t position, Frame& scratch);

  std::unique_ptr<Source> first_;
  std::unique_ptr<Source> reopened_;  ///< after a seek back; null until then
  Source* current_ = nullptr;
  std::function<std::unique_ptr<Source>()> open_;
  PlaybackControl& control_;
  SourceInfo info_;
  int64_t next_position_ = 0;  ///< of the frame current_->next() returns next
};

}  // namespace hrcsense::view
