// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — progress on stderr: one line per second of wall time, then the summary.
#pragma once

#include "hrcsense/sink.hpp"

#include <chrono>
#include <vector>

namespace hrcsense::app {

/// Logs (spdlog, stderr) "t=3.0s frames/s=29.8 latency p50=0.9ms closest=1.234m verdict=slow"
/// once per second of wall time, and a short summary block at the end. Each change of the
/// controller's robot_mode or safety_mode (rtde) and each start and end of a TCP pose
/// mismatch is one line of its own.
class ConsoleSink : public Sink {
 public:
  ConsoleSink();
  void header(const RunHeader& header) override;
  void frame(const FrameResult& result) override;
  void summary(const RunSummary& summary) override;

 private:
  using Clock = std::chrono::steady_clock;
  void log_robot_status(const FrameResult& result);

  Clock::time_point start_;
  Clock::time_point window_start_;
  std::vector<double> window_latency_us_;  ///< latencies since the last line; capacity reused
  int64_t window_frames_ = 0;
  int64_t timestamp_warnings_ = 0;  ///< out-of-order timestamps logged so far
  RobotStatus last_status_;         ///< the last known controller status (its changes are logged)
};

}  // namespace hrcsense::app
