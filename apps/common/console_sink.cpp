// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — progress on stderr: one line per second of wall time, then the summary.
#include "common/console_sink.hpp"

#include "hrcsense/robot_state.hpp"
#include "hrcsense/safety.hpp"
#include "hrcsense/sinks/sinks.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace hrcsense::app {
namespace {

// Enough for one second at several thousand frames/s; beyond it the window's median is
// taken over the first samples rather than growing the buffer on the frame path.
constexpr size_t kWindowCapacity = 8192;
// Timestamp warnings logged one by one; the rest only in the summary's counts, so that a
// recording whose every stamp repeats cannot flood the log.
constexpr int64_t kMaxTimestampWarnings = 10;

}  // namespace

void ConsoleSink::log_robot_status(const FrameResult& result) {
  const RobotStatus& now = result.robot_state.status;
  if (!now.known) return;  // no report (another source, or no valid state): nothing changed that we know of
  const RobotStatus& before = last_status_;
  if (!before.known) {
    spdlog::info("frame {}: robot controller reports robot_mode {} ({}), safety_mode {} ({}), speed_scaling {:.2f}",
                 result.frame, now.robot_mode, robot_mode_name(now.robot_mode), now.safety_mode,
                 safety_mode_name(now.safety_mode), now.speed_scaling);
  } else if (robot_mode_changed(before, now)) {
    spdlog::warn("frame {}: robot controller: robot_mode {} -> {}, safety_mode {} -> {} (reported only; the "
                 "verdict does not use it)", result.frame, robot_mode_name(before.robot_mode),
                 robot_mode_name(now.robot_mode), safety_mode_name(before.safety_mode), safety_mode_name(now.safety_mode));
  }
  if (now.tcp_pose_mismatch && !before.tcp_pose_mismatch) {
    spdlog::warn("frame {}: the controller's actual_TCP_pose disagrees with the forward kinematics of its joints: "
                 "wrong robot.model or base frame? (details: the summary's robot_state.last_problem)", result.frame);
  } else if (!now.tcp_pose_mismatch && before.tcp_pose_mismatch) {
    spdlog::info("frame {}: the controller's actual_TCP_pose agrees with the forward kinematics again", result.frame);
  }
  last_status_ = now;
}

ConsoleSink::ConsoleSink() : start_(Clock::now()), window_start_(start_) {
  window_latency_us_.reserve(kWindowCapacity);
}

void ConsoleSink::header(const RunHeader& header) {
  start_ = Clock::now();
  window_start_ = start_;
  const Intrinsics& in = header.source.intrinsics;
  spdlog::info("source {} ({}), {}x{}, {} frames, config {}", header.source.type, header.source.description,
               in.width, in.height, header.source.frame_count, header.config_hash);
  spdlog::warn("{}", kSafetyNotice);
}

void ConsoleSink::frame(const FrameResult& result) {
  if (result.timestamp_warning != nullptr && timestamp_warnings_++ < kMaxTimestampWarnings) {
    spdlog::warn("frame {}: {} (timestamp_ns {}){}", result.frame, result.timestamp_warning, result.timestamp_ns,
                 timestamp_warnings_ == kMaxTimestampWarnings ? "; further ones are counted in the summary only" : "");
  }
  log_robot_status(result);
  ++window_frames_;
  if (window_latency_us_.size() < kWindowCapacity) window_latency_us_.push_back(result.latency_us);
  const Clock::time_point now = Clock::now();
  const double window_s = std::chrono::duration<double>(now - window_start_).count();
  if (window_s < 1.0) return;

  double p50_ms = 0.0;
  if (!window_latency_us_.empty()) {
    auto middle = window_latency_us_.begin() + static_cast<std::ptrdiff_t>(window_latency_us_.size() / 2);
    std::nth_element(window_latency_us_.begin(), middle, window_latency_us_.end());
    p50_ms = *middle / 1000.0;
  }
  const double t_s = std::chrono::duration<double>(now - start_).count();
  const double fps = static_cast<double>(window_frames_) / window_s;
  if (result.contact.valid) {
    spdlog::info("t={:.1f}s frames/s={:.1f} latency p50={:.1f}ms closest={:.3f}m verdict={}", t_s, fps, p50_ms,
                 result.contact.distance_m, verdict_name(result.verdict.state));
  } else {
    spdlog::info("t={:.1f}s frames/s={:.1f} latency p50={:.1f}ms closest=none verdict={}", t_s, fps, p50_ms,
                 verdict_name(result.verdict.state));
  }
  window_start_ = now;
  window_frames_ = 0;
  window_latency_us_.clear();
}

void ConsoleSink::summary(const RunSummary& s) {
  spdlog::info("summary: {} frames in, {} processed, {} dropped, {} valid in {:.2f}s ({:.1f} frames/s)",
               s.frames_in, s.frames_processed, s.frames_dropped, s.frames_valid, s.wall_s, s.fps);
  spdlog::info("summary: verdicts run={} slow={} stop={}; latency p50={:.2f}ms p99={:.2f}ms", s.verdict_run,
               s.verdict_slow, s.verdict_stop, s.latency_p50_us / 1000.0, s.latency_p99_us / 1000.0);
  if (s.min_distance_m >= 0.0F) {
    spdlog::info("summary: min distance {:.3f}m; end: {}", s.min_distance_m, s.end_reason);
  } else {
    spdlog::info("summary: no foreground seen; end: {}", s.end_reason);
  }
  const TimestampCounts& t = s.timestamps;
  if (t.backwards + t.repeated + t.gaps + t.jumps > 0) {
    spdlog::warn("summary: source timestamps out of order: {} backwards, {} repeated, {} gaps ({} frames skipped), "
                 "{} jumps beyond max_frame_age_s", t.backwards, t.repeated, t.gaps, t.frames_skipped, t.jumps);
  }
  const RobotStatusCounts& r = s.robot_status;
  if (r.frames_reported > 0) {
    spdlog::info("summary: robot controller: {} of {} frames not running, {} in a protective or safeguard stop, "
                 "{} mode changes, {} with a TCP pose mismatch", r.frames_not_running, r.frames_reported,
                 r.frames_protective_stop, r.mode_changes, r.frames_tcp_pose_mismatch);
  }
  if (!s.robot_state.last_problem.empty()) spdlog::info("summary: robot state: {}", s.robot_state.last_problem);
}

}  // namespace hrcsense::app
