// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the tap on the processing thread that hands the newest processed frame to
// the renderer through a latest-value mailbox: the safety path never waits for the viewer
// (except in snapshot mode, which asks for it).
#pragma once

#include "viewer/view_model.hpp"

#include "hrcsense/mailbox.hpp"
#include "hrcsense/pipeline.hpp"

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <set>

namespace hrcsense::view {

/// Fills a ViewFrame from what the processing thread has after Pipeline::process (the source
/// frame, the pipeline's foreground and capsules, the result), reusing `out`'s buffers.
void fill_view_frame(const Frame& frame, const Pipeline& pipeline, const FrameResult& result, int64_t made_ns,
                     ViewFrame& out);

class ViewTap {
 public:
  /// `snapshot_frames`: source frame indices the run must not pass before the renderer has
  /// drawn them (snapshot mode); empty: never wait.
  explicit ViewTap(std::set<int64_t> snapshot_frames = {});

  /// Called on the processing thread for every processed frame (RunOptions::on_processed).
  /// Never blocks, except at a snapshot frame: it then waits until the renderer reports it
  /// drawn (rendered()) or the tap is closed.
  void offer(const Frame& frame, const Pipeline& pipeline, const FrameResult& result);

  /// The renderer's side: the newest frame, swapped into `out`; false when none is new within
  /// timeout_s (or closed).
  bool take(ViewFrame& out, double timeout_s) { return mailbox_.take_for(out, timeout_s); }
  /// The renderer has drawn (and, for a snapshot frame, written) frame `index`.
  void rendered(int64_t index);
  /// Ends all waiting (the renderer is gone or the run ended).
  void close();
  bool closed() const { return mailbox_.closed(); }

  /// Every processed frame of the last seconds (the timeline and the stats panel), copied
  /// into `out`.
  void timeline(std::vector<TimelinePoint>& out) const;

  /// Source frames that never reached processing, as seen from here: the gaps between the
  /// source indices of consecutive processed frames (a seek forward makes one too; the viewer
  /// subtracts PlaybackControl::skipped()).
  int64_t index_gaps() const;
  /// Frames the renderer never took: `viewer_frames_dropped` in the summary.
  int64_t dropped() const { return mailbox_.dropped(); }
  /// Snapshot frames still to be drawn.
  size_t snapshots_pending() const;

 private:
  Mailbox<ViewFrame> mailbox_;
  ViewFrame scratch_;  ///< filled on the processing thread, then swapped into the mailbox
  mutable std::mutex mutex_;
  std::condition_variable drawn_;
  std::set<int64_t> pending_;  ///< snapshot frames not yet drawn
  Timeline timeline_;          ///< under mutex_
  int64_t last_index_ = -1;    ///< under mutex_: the last processed frame's source index
  int64_t index_gaps_ = 0;     ///< under mutex_
  bool closed_ = false;
};

}  // namespace hrcsense::view
