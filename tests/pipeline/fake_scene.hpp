// SPDX-License-Identifier: Apache-2.0
// Hand-built frames for the pipeline tests: a flat wall, optionally a square object in front
// of it, seen by an undistorted 80x60 camera whose frame is the robot base frame; a source and
// a sink that tests can hold back, and a fake clock that tells the run's threads apart.
#pragma once

#include "../support/decide.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/robot_state.hpp"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::test {

inline constexpr int kWidth = 80;
inline constexpr int kHeight = 60;
inline constexpr float kWallM = 2.0F;
inline constexpr int kLearnFrames = 3;
/// How long (real time) a test waits for a run's threads to get somewhere: a wait that times
/// out fails the test instead of hanging it.
inline constexpr double kTestWaitS = 10.0;

inline Intrinsics fake_intrinsics() {
  Intrinsics intr;
  intr.width = kWidth;
  intr.height = kHeight;
  intr.fx = intr.fy = 100.0F;
  intr.ppx = 39.5F;  // the optical axis passes between pixels 39 and 40
  intr.ppy = 29.5F;
  return intr;
}

/// Object depth 0: wall only; < 0: no valid depth at all; else a 40x40 px square at that depth.
inline void fill_frame(int64_t index, float object_m, Frame& out) {
  out.index = index;
  out.timestamp_ns = index * 33'333'333;
  out.intrinsics = fake_intrinsics();
  out.stereo_baseline_mm = 50.0F;
  out.depth.resize(kWidth, kHeight);
  const auto wall = static_cast<uint16_t>(std::lround(kWallM * 1000.0F));
  const auto object = static_cast<uint16_t>(std::lround(object_m * 1000.0F));
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const bool in_object = object_m > 0.0F && u >= 20 && u < 60 && v >= 10 && v < 50;
      uint16_t raw = in_object ? object : wall;
      if (object_m < 0.0F) raw = 0;
      out.depth.pixels[static_cast<size_t>(v) * kWidth + u] = raw;
    }
  }
}

/// Distance from the robot point at the camera origin to the object at depth z: the nearest
/// pixel centres are half a pixel off the axis in u and v, so x = y = 0.5 / fx · z.
inline double expected_distance_m(double z_m) {
  const double off = 0.5 / 100.0 * z_m;
  return std::sqrt(2.0 * off * off + z_m * z_m);
}

/// Robot: one point at the camera origin; thresholds 1.0 m (slow) and 0.5 m (stop).
inline PipelineParams fake_params(double max_frame_age_s = 0.5) {
  PipelineParams params;
  params.background.frames = kLearnFrames;
  Capsule point;
  point.link = 2;
  params.robot.points.capsules.push_back(point);
  params.safety.slow_distance_m = 1.0F;
  params.safety.stop_distance_m = 0.5F;
  params.safety.max_frame_age_s = max_frame_age_s;
  return params;
}

/// What the fake source does at one step.
struct Step {
  float object_m = 0.0F;   ///< see fill_frame
  double sleep_s = 0.0;    ///< before delivering (real time)
  bool fail = false;       ///< report an error instead of a frame
  int64_t timestamp_ns = -1;  ///< >= 0: this timestamp instead of the index's 30 frames/s one
};

class FakeSource : public Source {
 public:
  explicit FakeSource(std::vector<Step> steps) : steps_(std::move(steps)) {}
  SourceInfo info() const override {
    SourceInfo info;
    info.type = "fake";
    info.intrinsics = fake_intrinsics();
    info.frame_count = static_cast<int64_t>(steps_.size());
    return info;
  }
  Status next(Frame& out) override {
    if (next_ >= steps_.size()) return Status::end;
    const Step& step = steps_[next_];
    if (before_step && !before_step(next_)) {
      error_ = "a test wait before step " + std::to_string(next_) + " timed out";
      return Status::error;
    }
    if (step.sleep_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(step.sleep_s));
    if (step.fail) return Status::error;
    fill_frame(static_cast<int64_t>(next_), step.object_m, out);
    if (step.timestamp_ns >= 0) out.timestamp_ns = step.timestamp_ns;
    ++next_;
    return Status::frame;
  }
  std::string error() const override { return error_; }

  /// Called on the capture thread before step `step` is delivered: where a test waits for the
  /// run to get somewhere or moves its clock. False (a wait timed out): next() fails.
  std::function<bool(size_t step)> before_step;

 private:
  std::vector<Step> steps_;
  size_t next_ = 0;
  std::string error_ = "cable unplugged";
};

/// Keeps everything it is given. Other threads may wait for results (wait_until); `results`
/// itself is for the output thread and for after the run.
struct CollectingSink : Sink {
  RunHeader header_seen;
  std::vector<FrameResult> results;
  RunSummary summary_seen;
  int headers = 0, summaries = 0;
  /// Called on the output thread before a result is kept: where a test holds the output back.
  std::function<void(const FrameResult&)> before_frame;

  void header(const RunHeader& h) override {
    header_seen = h;
    ++headers;
  }
  void frame(const FrameResult& r) override {
    if (before_frame) before_frame(r);
    std::lock_guard<std::mutex> lock(mutex_);
    results.push_back(r);
    kept_.notify_all();
  }
  /// Waits (real time, at most `timeout_s`) until `done(results)`; false on timeout.
  bool wait_until(const std::function<bool(const std::vector<FrameResult>&)>& done, double timeout_s = kTestWaitS) {
    std::unique_lock<std::mutex> lock(mutex_);
    return kept_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return done(results); });
  }
  void summary(const RunSummary& s) override {
    summary_seen = s;
    ++summaries;
  }
  /// Results that stand for a source frame: not the watchdog's, not the final stop.
  std::vector<FrameResult> frame_results() const {
    std::vector<FrameResult> out;
    for (size_t i = 0; i + 1 < results.size(); ++i) {
      if (results[i].source_frame) out.push_back(results[i]);
    }
    return out;
  }

 private:
  std::mutex mutex_;
  std::condition_variable kept_;
};

/// A FakeClock that counts the output thread's reads: run_pipeline writes the output (and
/// decides each frame there) on the caller's thread, the one that built this clock.
class WatchedClock : public RunClock {
 public:
  mutable FakeClock fake;  ///< the time; the test moves it

  int64_t now_ns() const override {
    const std::thread::id reader = std::this_thread::get_id();
    std::lock_guard<std::mutex> lock(mutex_);
    if (reader == output_thread_) ++output_reads_;
    read_.notify_all();
    return fake.now_ns();
  }
  void sleep_until(int64_t t_ns, const std::atomic<bool>* stop_requested) override {
    fake.sleep_until(t_ns, stop_requested);
  }
  /// How often the output thread has read the clock.
  int64_t output_reads() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return output_reads_;
  }
  /// Waits (real time, at most `timeout_s`) until the output thread has read the clock more
  /// than `count` times.
  bool wait_output_reads_above(int64_t count, double timeout_s = kTestWaitS) const {
    std::unique_lock<std::mutex> lock(mutex_);
    return read_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return output_reads_ > count; });
  }

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable read_;
  std::thread::id output_thread_ = std::this_thread::get_id();
  mutable int64_t output_reads_ = 0;
};

/// The background a pipeline learns from the empty fake scene (the wall at 2 m).
/// Learns the wall in `pipeline` (kLearnFrames frames), leaving `result` at the last one;
/// true when the background is then ready.
inline bool learn_wall(Pipeline& pipeline, Frame& frame, FrameResult& result) {
  for (int i = 0; i < kLearnFrames; ++i) {
    fill_frame(i, 0.0F, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  }
  return pipeline.background_ready();
}

inline BackgroundModel learn_empty_background() {
  Pipeline learner(fake_params());
  Frame frame;
  FrameResult result;
  for (int i = 0; i < kLearnFrames; ++i) {
    fill_frame(i, 0.0F, frame);
    test::process_and_decide(learner, frame, fixed_robot_state({}), result);
  }
  return learner.background();
}

/// run_pipeline over `source` into `sink` with a pipeline built from `params`.
inline RunSummary run_fake(Source& source, Sink& sink, const PipelineParams& params, const RunOptions& options = {}) {
  Pipeline pipeline(params);
  RunHeader header;
  header.version = "test";
  header.source = source.info();
  FixedRobotState robot_states({});  // fake_params' robot is a point: no joints
  return run_pipeline(source, robot_states, pipeline, sink, options, header);
}

/// `learn` wall frames, then the given steps.
inline std::vector<Step> after_learning(std::vector<Step> steps) {
  std::vector<Step> all(kLearnFrames, Step{});
  all.insert(all.end(), steps.begin(), steps.end());
  return all;
}

}  // namespace hrcsense::test
