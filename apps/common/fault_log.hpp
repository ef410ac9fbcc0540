// SPDX-License-Identifier: Apache-2.0
// hrcsense — faults said while a run goes on: a cell that runs for days must not hide a full
// disk, a silent robot or a refusing controller until the summary. Each part of the run is
// polled for what is wrong with it now; a fault is logged when it starts, again at most once a
// second while its text changes, and when it has cleared.
#pragma once

#include "hrcsense/sink.hpp"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense::app {

/// One change of a fault, as the log says it.
struct FaultEvent {
  enum class Kind { started, changed, cleared };
  Kind kind = Kind::started;
  std::string text;       ///< started, changed: what is wrong now; cleared: what was wrong last
  double lasted_s = 0.0;  ///< cleared: from the start to the last time it was seen
};

/// The fault state of one part of a run, fed what the part says is wrong at each poll ("" for
/// nothing). A fault clears only after `quiet_ns` without it, so that one that comes and goes
/// (a lost datagram now and then) is one fault, not a line per occurrence.
class FaultTrack {
 public:
  explicit FaultTrack(int64_t quiet_ns = 1'000'000'000) : quiet_ns_(quiet_ns) {}
  /// The event this poll gives rise to, if any: started (a fault where there was none), changed
  /// (another text, at most once per quiet_ns after the last line), cleared (none for quiet_ns).
  std::optional<FaultEvent> update(const std::string& problem, int64_t now_ns);
  bool active() const { return active_; }

 private:
  int64_t quiet_ns_;
  bool active_ = false;
  std::string text_;          ///< the newest text of the fault in force
  bool text_logged_ = true;   ///< text_ has been said
  int64_t started_ns_ = 0, seen_ns_ = 0, logged_ns_ = 0;
};

/// A part of the run and how to ask it what is wrong now. `problem` gets the newest result
/// (the frame just written) and runs on the output thread; what it reads from other threads
/// must be thread-safe (the sources' stats(), the sinks' counters()).
struct FaultProbe {
  std::string name;  ///< "robot state", "recording", "link.udp", "link.rtde"
  std::function<std::string(const FrameResult& newest)> problem;
};

/// What a probe reports for a counter of bad events: the text `describe()` gives whenever the
/// counter rose since the last poll, "" otherwise. For faults that are events (a rejected
/// sample, a refused write) rather than states.
std::function<std::string(const FrameResult&)> when_rising(std::function<int64_t()> count,
                                                           std::function<std::string()> describe);

/// A Sink that passes everything to `inner` and, after each frame, polls the probes on `now_ns`
/// and logs their faults' events on stderr (spdlog: warn for started and changed, info for
/// cleared). `log` replaces spdlog for tests.
class FaultLogSink final : public Sink {
 public:
  using Log = std::function<void(const std::string& name, const FaultEvent& event)>;
  FaultLogSink(Sink& inner, std::vector<FaultProbe> probes, std::function<int64_t()> now_ns, Log log = {});
  void header(const RunHeader& header) override { inner_.header(header); }
  void frame(const FrameResult& result) override;
  void summary(const RunSummary& summary) override { inner_.summary(summary); }
  bool failed() const override { return inner_.failed(); }
  std::string failure() const override { return inner_.failure(); }

 private:
  Sink& inner_;
  std::vector<FaultProbe> probes_;
  std::vector<FaultTrack> tracks_;
  std::function<int64_t()> now_ns_;
  Log log_;
};

/// The line a FaultLogSink writes for `event` of the part `name`, without the log level.
std::string fault_line(const std::string& name, const FaultEvent& event);

}  // namespace hrcsense::app
