// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — faults logged when they start and when they clear (fault_log.hpp).
#include "common/fault_log.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <utility>

namespace hrcsense::app {

std::optional<FaultEvent> FaultTrack::update(const std::string& problem, int64_t now_ns) {
  if (problem.empty()) {
    if (!active_ || now_ns - seen_ns_ < quiet_ns_) return std::nullopt;
    active_ = false;
    FaultEvent event{FaultEvent::Kind::cleared, text_, static_cast<double>(seen_ns_ - started_ns_) * 1e-9};
    return event;
  }
  seen_ns_ = now_ns;
  if (!active_) {
    active_ = true;
    started_ns_ = logged_ns_ = now_ns;
    text_ = problem;
    text_logged_ = true;
    return FaultEvent{FaultEvent::Kind::started, problem, 0.0};
  }
  if (problem != text_) {
    text_ = problem;
    text_logged_ = false;
  }
  // A text that changes every frame (an age, a count) is said once a second, the newest then.
  if (text_logged_ || now_ns - logged_ns_ < quiet_ns_) return std::nullopt;
  text_logged_ = true;
  logged_ns_ = now_ns;
  return FaultEvent{FaultEvent::Kind::changed, text_, 0.0};
}

std::function<std::string(const FrameResult&)> when_rising(std::function<int64_t()> count,
                                                           std::function<std::string()> describe) {
  return [count = std::move(count), describe = std::move(describe), last = int64_t{0}](const FrameResult&) mutable {
    const int64_t now = count();
    const bool rose = now > last;
    last = now;
    return rose ? describe() : std::string();
  };
}

FaultLogSink::FaultLogSink(Sink& inner, std::vector<FaultProbe> probes, std::function<int64_t()> now_ns, Log log)
    : inner_(inner), probes_(std::move(probes)), tracks_(probes_.size()), now_ns_(std::move(now_ns)), log_(std::move(log)) {
  if (!log_) {
    log_ = [](const std::string& name, const FaultEvent& event) {
      if (event.kind == FaultEvent::Kind::cleared) {
        spdlog::info("{}", fault_line(name, event));
      } else {
        spdlog::warn("{}", fault_line(name, event));
      }
    };
  }
}

void FaultLogSink::frame(const FrameResult& result) {
  inner_.frame(result);  // the frame first: logging never delays a verdict
  const int64_t now = now_ns_();
  for (size_t i = 0; i < probes_.size(); ++i) {
    if (const std::optional<FaultEvent> event = tracks_[i].update(probes_[i].problem(result), now)) {
      log_(probes_[i].name, *event);
    }
  }
}

std::string fault_line(const std::string& name, const FaultEvent& event) {
  switch (event.kind) {
    case FaultEvent::Kind::started: return "fault: " + name + ": " + event.text;
    case FaultEvent::Kind::changed: return "fault goes on: " + name + ": " + event.text;
    case FaultEvent::Kind::cleared: {
      char lasted[32];
      std::snprintf(lasted, sizeof lasted, "%.1f", event.lasted_s);
      return "fault cleared: " + name + " (lasted " + lasted + " s): " + event.text;
    }
  }
  return {};
}

}  // namespace hrcsense::app
