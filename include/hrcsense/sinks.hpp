// SPDX-License-Identifier: Apache-2.0
// hrcsense — sinks: where results go. JSON Lines as docs/OUTPUT.md describes.
#pragma once

#include "hrcsense/pipeline.hpp"

#include <ostream>
#include <string>
#include <utility>

namespace hrcsense {

/// `safety_notice` of every output's header (JSON Lines, the console's first line).
inline constexpr const char* kSafetyNotice =
    "hrcsense is not a safety-rated device: its verdict may request a slower or stopped robot, but a "
    "safety function must come from rated equipment (docs/SAFETY.md)";

/// Writes one JSON object per line: a header, one line per frame, a summary; each line is
/// flushed as soon as it is written.
/// Field names are binding (DESIGN.md "Names other tools rely on").
class JsonLinesSink : public Sink {
 public:
  /// `out` must outlive the sink. `T_base_camera` is not needed: results carry both frames.
  /// `backend` is the proximity backend written in every frame line (proximity.backend).
  explicit JsonLinesSink(std::ostream& out, std::string backend = "brute")
      : out_(out), backend_(std::move(backend)) {}
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
  std::string line_;  ///< reused per frame
  /// The header said the frames carry robot_status: a frame without one writes null.
  bool robot_status_announced_ = false;
};

}  // namespace hrcsense
