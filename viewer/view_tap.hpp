// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the tap that hands the newest frame to the renderer through a latest-value
// mailbox, with the verdict the run's SafetyMonitor decided for it. Two sides: offer() on the
// processing thread copies what the frame looks like (images, foreground, capsules, contact)
// and keeps it pending; decided() on the output thread (through a ViewSink among the run's
// sinks) pairs it with its decided result and publishes it. The safety path never waits for
// the viewer, except in snapshot mode, which asks for it.
#pragma once

#include "viewer/view_model.hpp"

#include "hrcsense/mailbox.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/sink.hpp"

#include <array>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <set>

namespace hrcsense::view {

/// Fills a ViewFrame from what the processing thread has after Pipeline::process (the source
/// frame, the pipeline's foreground and capsules, the measurement), reusing `out`'s buffers.
/// Everything but the verdict, which is decided later, on the output thread (ViewTap::decided).
void fill_view_frame(const Frame& frame, const Pipeline& pipeline, const FrameResult& result, int64_t made_ns,
                     ViewFrame& out);

class ViewTap {
 public:
  /// Frames offered but not yet decided that the tap keeps: in an unpaced run processing is at
  /// most 3 frames ahead of the output (one in the results mailbox, one waiting to be put).
  static constexpr size_t kPendingFrames = 4;

  /// `snapshot_frames`: source frame indices the run must not pass before the renderer has
  /// drawn them (snapshot mode); empty: never wait.
  explicit ViewTap(std::set<int64_t> snapshot_frames = {});

  /// The processing thread's side (RunOptions::on_processed), for every processed frame: fills
  /// a ViewFrame and keeps it pending until its result is decided. Never blocks. With more
  /// than kPendingFrames pending, the oldest is forgotten.
  void offer(const Frame& frame, const Pipeline& pipeline, const FrameResult& result);

  /// The output thread's side (ViewSink), for every result the sinks write, as decided by the
  /// SafetyMonitor. A source frame's: its pending ViewFrame (same frame index and delivery
  /// time) gets the decided verdict and is published to the renderer; views offered before it
  /// are forgotten (measurements the pipeline dropped undecided, in its frames_dropped); its
  /// timeline point is added. A frame whose view is gone (forgotten) publishes nothing, so an
  /// image is never shown with another frame's verdict, and counts as a viewer drop. A result
  /// that stands for no source frame (a watchdog or end-of-run stop) takes the place of the
  /// verdict of the last frame published, while that frame is the newest (take()); its age,
  /// and so NO DATA, stays the frame's. Never blocks, except at a snapshot frame: it then waits
  /// until the renderer reports it drawn (rendered()) or the tap is closed.
  void decided(const FrameResult& result);

  /// The renderer's side: the newest frame, swapped into `out`; false when none is new within
  /// timeout_s (or closed). Either way a stop that stands for no source frame, decided after
  /// the frame in `out` with no frame published since, replaces its verdict.
  bool take(ViewFrame& out, double timeout_s);
  /// The renderer has drawn (and, for a snapshot frame, written) frame `index`.
  void rendered(int64_t index);
  /// Ends all waiting (the renderer is gone or the run ended).
  void close();
  bool closed() const { return mailbox_.closed(); }

  /// Every decided source frame of the last seconds (the timeline and the stats panel), copied
  /// into `out`.
  void timeline(std::vector<TimelinePoint>& out) const;

  /// Source frames the output never wrote, as seen from here: the gaps between the source
  /// indices of consecutive decided frames (dropped before or after processing: the summary's
  /// frames_dropped; a seek forward makes one too, the viewer subtracts
  /// PlaybackControl::skipped()).
  int64_t index_gaps() const;
  /// Decided frames the renderer never took (the mailbox replaced them, or their view was
  /// gone): `viewer_frames_dropped` in the summary.
  int64_t dropped() const;
  /// Snapshot frames still to be drawn.
  size_t snapshots_pending() const;

 private:
  /// An offered frame waiting for its decision, known by its source index and the run-clock
  /// time it was delivered (unique in a run, also after a seek back).
  struct Pending {
    ViewFrame view;
    int64_t frame = -1;
    int64_t delivered_ns = 0;
    int64_t offered = 0;  ///< offer order (1, 2, ...); 0: the slot is free
  };

  Mailbox<ViewFrame> mailbox_;
  ViewFrame offer_scratch_;    ///< processing thread: filled, then swapped into the ring
  ViewFrame publish_scratch_;  ///< output thread: swapped out of the ring, then into the mailbox
  mutable std::mutex mutex_;
  std::condition_variable drawn_;
  // Under mutex_:
  std::array<Pending, kPendingFrames> pending_;
  int64_t offered_ = 0;
  int64_t published_ = 0;           ///< frames published (ViewFrame::publication of the last)
  std::optional<Verdict> no_frame_;  ///< the last stop for no source frame, after publication no_frame_after_
  int64_t no_frame_after_ = 0;
  std::set<int64_t> snapshots_;     ///< snapshot frames not yet drawn
  Timeline timeline_;
  int64_t last_index_ = -1;         ///< the last decided source frame's index
  int64_t index_gaps_ = 0;
  int64_t views_missing_ = 0;       ///< decided source frames whose view was gone
  bool closed_ = false;
};

/// The output thread's way into a ViewTap: a Sink that hands every result the run writes, as
/// decided, to ViewTap::decided(). Put it last among the run's sinks, so that the links and
/// files are written first (app::SessionOptions::viewer_sink).
class ViewSink final : public Sink {
 public:
  explicit ViewSink(ViewTap& tap) : tap_(tap) {}
  void header(const RunHeader& /*header*/) override {}
  void frame(const FrameResult& result) override { tap_.decided(result); }
  void summary(const RunSummary& /*summary*/) override {}

 private:
  ViewTap& tap_;
};

}  // namespace hrcsense::view
