// SPDX-License-Identifier: Apache-2.0
// hrcsense — robot.trajectory.follow_link: tells the simulated arm's clock the speed scale each
// written result carries, which is what the controller link sends (a test and demo feature).
#pragma once

#include "hrcsense/sim/sim.hpp"
#include "hrcsense/sink.hpp"

#include <memory>
#include <utility>

namespace hrcsense {

/// Passes every result's speed scale (run 1, slow its scale, stop 0) to a TrajectoryClock, as
/// a robot whose speed slider the link sets would take it. Put after the link sinks.
class FollowLinkSink final : public Sink {
 public:
  explicit FollowLinkSink(std::shared_ptr<TrajectoryClock> clock) : clock_(std::move(clock)) {}
  void header(const RunHeader&) override {}
  void frame(const FrameResult& result) override { clock_->sent(result.timestamp_ns, result.verdict.speed_scale); }
  void summary(const RunSummary&) override {}

 private:
  std::shared_ptr<TrajectoryClock> clock_;
};

}  // namespace hrcsense
