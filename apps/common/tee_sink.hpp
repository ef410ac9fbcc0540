// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — a sink that forwards every call to several sinks, in order.
#pragma once

#include "hrcsense/sink.hpp"

#include <string>
#include <vector>

namespace hrcsense::app {

/// Forwards header, frames and summary to each sink in the order given; null entries (a sink
/// the configuration leaves off) are skipped. The sinks must outlive the tee.
class TeeSink : public Sink {
 public:
  explicit TeeSink(const std::vector<Sink*>& sinks) {
    for (Sink* sink : sinks) {
      if (sink != nullptr) sinks_.push_back(sink);
    }
  }
  void header(const RunHeader& header) override {
    for (Sink* sink : sinks_) sink->header(header);
  }
  void frame(const FrameResult& result) override {
    for (Sink* sink : sinks_) sink->frame(result);
  }
  void summary(const RunSummary& summary) override {
    for (Sink* sink : sinks_) sink->summary(summary);
  }
  /// Failed as soon as any sink failed: a result that cannot reach every consumer ends the run.
  bool failed() const override {
    for (Sink* sink : sinks_) {
      if (sink->failed()) return true;
    }
    return false;
  }
  std::string failure() const override {
    for (Sink* sink : sinks_) {
      if (sink->failed()) return sink->failure();
    }
    return {};
  }

 private:
  std::vector<Sink*> sinks_;
};

}  // namespace hrcsense::app
