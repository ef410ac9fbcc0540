// SPDX-License-Identifier: Apache-2.0
// hrcsense — sinks: where results go. JSON Lines as docs/OUTPUT.md describes.
#pragma once

#include "hrcsense/sink.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense {

/// `safety_notice` of every output's header (JSON Lines, the console's first line).
inline constexpr const char* kSafetyNotice =
    "hrcsense is not a safety-rated device: its verdict may request a slower or stopped robot, but a "
    "safety function must come from rated equipment (docs/SAFETY.md)";

/// The recorder's counters over a run (`hrcsense run --record`), apart from the pipeline's own
/// frames_dropped.
struct RecordCounters {
  int64_t frames_recorded = 0;     ///< source frames written to the recording
  int64_t frames_dropped = 0;      ///< source frames not recorded: the writer's queue was full, or after a write error
  std::vector<std::string> files;  ///< the files written, in order (several with record.split_mb)
  std::string error;               ///< the write error, naming the file; empty when none
};

/// What the applications add to the summary, beside the pipeline's RunSummary.
struct AppCounters {
  std::optional<RecordCounters> record;  ///< the recording's counters; none when the run records nothing
  /// Frames the viewer (hrcsense-view) never drew, apart from frames_dropped: its mailbox kept
  /// only the newest; none when no viewer watched the run.
  std::optional<int64_t> viewer_frames_dropped;
};

/// What the JSON Lines carry that the pipeline does not know; both optional.
struct JsonLinesExtras {
  /// `truth.contact_label` of a frame with a truth: "static", "robot" or the object's name (a
  /// simulated run's labeller); null: none. The text must live until the next call.
  std::function<const char*(const FrameResult&)> contact_label;
  /// The summary's `record` and `viewer_frames_dropped`, asked once, just before it is written.
  std::function<AppCounters()> app_counters;
};

/// Writes one JSON object per line: a header, one line per frame, a summary; each line is
/// flushed as soon as it is written.
/// Field names are binding (DESIGN.md "Names other tools rely on").
class JsonLinesSink : public Sink {
 public:
  /// `out` must outlive the sink. `T_base_camera` is not needed: results carry both frames.
  /// `backend` is the proximity backend written in every frame line (proximity.backend).
  explicit JsonLinesSink(std::ostream& out, std::string backend = "brute", JsonLinesExtras extras = {})
      : out_(out), backend_(std::move(backend)), extras_(std::move(extras)) {}
  void header(const RunHeader& header) override;
  void frame(const FrameResult& result) override;
  void summary(const RunSummary& summary) override;
  /// The stream failed (e.g. EPIPE with SIGPIPE ignored, a full disk): the run should end.
  bool failed() const override { return !out_; }
  std::string failure() const override { return "write failed"; }

 private:
  void write_line();  ///< writes line_ and flushes it

  std::ostream& out_;
  std::string backend_;
  JsonLinesExtras extras_;
  std::string line_;  ///< reused per frame
  /// The header said the frames carry robot_status: a frame without one writes null.
  bool robot_status_announced_ = false;
};

}  // namespace hrcsense
