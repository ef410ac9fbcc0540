// SPDX-License-Identifier: Apache-2.0
// Tests of run_pipeline: threads, fail-safe stops, watchdog and summary, with a fake source;
// stalls, ages and pacing on a fake clock.

#include "fake_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace hrcsense {
namespace {

using test::after_learning;
using test::CollectingSink;
using test::expected_distance_m;
using test::fake_params;
using test::FakeSource;
using test::Step;

bool starts_with(const std::string& text, const char* prefix) { return text.rfind(prefix, 0) == 0; }

RunSummary run(FakeSource& source, CollectingSink& sink, const PipelineParams& params, RunOptions options = {}) {
  return test::run_fake(source, sink, params, options);
}

TEST(RunPipeline, UnpacedProcessesEveryFrameWithExpectedVerdicts) {
  FakeSource source(after_learning({{1.5F}, {0.8F}, {0.3F}, {0.0F}}));
  CollectingSink sink;
  const RunSummary summary = run(source, sink, fake_params());

  EXPECT_EQ(sink.headers, 1);
  EXPECT_EQ(sink.summaries, 1);
  EXPECT_EQ(sink.header_seen.source.type, "fake");
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 7U);
  for (size_t i = 0; i < frames.size(); ++i) EXPECT_EQ(frames[i].frame, static_cast<int64_t>(i));
  for (int i = 0; i < test::kLearnFrames; ++i) {
    EXPECT_FALSE(frames[static_cast<size_t>(i)].valid);
    EXPECT_TRUE(starts_with(frames[static_cast<size_t>(i)].verdict.reason, "learning background"));
    EXPECT_EQ(frames[static_cast<size_t>(i)].verdict.code, ReasonCode::learning_background);
  }
  EXPECT_EQ(frames[3].verdict.state, VerdictState::run);
  EXPECT_EQ(frames[4].verdict.state, VerdictState::slow);
  EXPECT_EQ(frames[5].verdict.state, VerdictState::stop);
  EXPECT_EQ(frames[6].verdict.state, VerdictState::run);
  EXPECT_NEAR(frames[3].contact.distance_m, expected_distance_m(1.5), 1e-4);
  EXPECT_NEAR(frames[4].contact.distance_m, expected_distance_m(0.8), 1e-4);
  EXPECT_NEAR(frames[5].contact.distance_m, expected_distance_m(0.3), 1e-4);
  EXPECT_FALSE(frames[6].contact.valid);

  // Fail safe: the last result written is a stop saying why the run ended.
  const FrameResult& last = sink.results.back();
  EXPECT_EQ(last.verdict.state, VerdictState::stop);
  EXPECT_EQ(last.verdict.reason, "source ended");
  EXPECT_FALSE(last.valid);
  EXPECT_FALSE(last.source_frame);  // it stands for no new source frame
  for (size_t i = 0; i + 1 < sink.results.size(); ++i) EXPECT_TRUE(sink.results[i].source_frame);

  EXPECT_EQ(summary.frames_in, 7);
  EXPECT_EQ(summary.frames_processed, 7);
  EXPECT_EQ(summary.frames_dropped, 0);
  EXPECT_EQ(summary.frames_valid, 4);
  EXPECT_EQ(summary.verdict_run, 2);
  EXPECT_EQ(summary.verdict_slow, 1);
  EXPECT_EQ(summary.verdict_stop, 4);  // 3 learning + 1 too close
  EXPECT_NEAR(summary.min_distance_m, expected_distance_m(0.3), 1e-4);
  EXPECT_EQ(summary.end_reason, "end of source");
  EXPECT_GT(summary.wall_s, 0.0);
  EXPECT_GT(summary.fps, 0.0);
  EXPECT_LE(summary.latency_p50_us, summary.latency_p99_us);
  EXPECT_EQ(sink.summary_seen.frames_processed, summary.frames_processed);
}

TEST(RunPipeline, UnpacedLongRunDropsNothing) {
  std::vector<Step> steps(200, Step{0.8F});
  FakeSource source(after_learning(steps));
  CollectingSink sink;
  const RunSummary summary = run(source, sink, fake_params());
  EXPECT_EQ(summary.frames_in, 203);
  EXPECT_EQ(summary.frames_processed, 203);
  EXPECT_EQ(summary.frames_dropped, 0);
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 203U);
  for (size_t i = 0; i < frames.size(); ++i) ASSERT_EQ(frames[i].frame, static_cast<int64_t>(i));
  EXPECT_EQ(summary.verdict_slow, 200);
}

TEST(RunPipeline, SourceErrorEndsWithStopCarryingTheError) {
  FakeSource source(after_learning({{0.0F}, {1.5F}, {0.0F, 0.0, true}, {1.5F}}));
  CollectingSink sink;
  const RunSummary summary = run(source, sink, fake_params());
  EXPECT_EQ(summary.frames_in, 5);
  ASSERT_FALSE(sink.results.empty());
  EXPECT_EQ(sink.results.back().verdict.state, VerdictState::stop);
  EXPECT_EQ(sink.results.back().verdict.reason, "source error: cable unplugged");
  EXPECT_EQ(sink.results.back().verdict.code, ReasonCode::source_error);
  EXPECT_EQ(summary.end_code, ReasonCode::source_error);
  EXPECT_EQ(summary.end_reason, "source error: cable unplugged");
  // The frame before the failure still ran normally.
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 5U);
  EXPECT_EQ(frames[4].verdict.state, VerdictState::run);
}

TEST(RunPipeline, FrameWithoutValidDepthIsStop) {
  FakeSource source(after_learning({{1.5F}, {-1.0F}, {1.5F}}));
  CollectingSink sink;
  run(source, sink, fake_params());
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 6U);
  EXPECT_EQ(frames[3].verdict.state, VerdictState::run);
  EXPECT_EQ(frames[4].verdict.state, VerdictState::stop);
  EXPECT_EQ(frames[4].verdict.reason, "no valid depth");
  EXPECT_EQ(frames[4].verdict.code, ReasonCode::no_valid_depth);
  EXPECT_FALSE(frames[4].valid);
  EXPECT_EQ(frames[5].verdict.state, VerdictState::run);
}

TEST(RunPipeline, MaxFramesEndsTheRunWithStop) {
  FakeSource source(after_learning({{1.5F}, {1.5F}, {1.5F}}));
  CollectingSink sink;
  RunOptions options;
  options.max_frames = 4;
  const RunSummary summary = run(source, sink, fake_params(), options);
  EXPECT_EQ(summary.frames_in, 4);
  EXPECT_EQ(sink.results.back().verdict.state, VerdictState::stop);
  EXPECT_FALSE(sink.results.back().verdict.reason.empty());
  EXPECT_EQ(sink.results.back().verdict.code, ReasonCode::frame_limit_reached);
  EXPECT_EQ(summary.end_code, ReasonCode::frame_limit_reached);
}

// Waits (real time, bounded) until the sink has `count` results; false on timeout.
bool has_results(CollectingSink& sink, size_t count) {
  return sink.wait_until([&](const std::vector<FrameResult>& results) { return results.size() >= count; });
}

// The source's before_step for a stall before frame 4: once frame 3 is written and the output
// has looked at the clock since, the fake clock jumps by `stall_ns`; the stall ends once the
// watchdog has written its no_frame stop (false if it never does).
std::function<bool(size_t)> stall_before_frame_4(test::WatchedClock& clock, CollectingSink& sink, int64_t stall_ns) {
  return [&clock, &sink, stall_ns](size_t step) {
    if (step != 4) return true;
    if (!has_results(sink, 4) || !clock.wait_output_reads_above(clock.output_reads())) return false;
    clock.fake.advance(stall_ns);
    return sink.wait_until([](const std::vector<FrameResult>& results) {
      return !results.empty() && results.back().verdict.code == ReasonCode::no_frame;
    });
  };
}

// On a fake clock the source stalls before frame 4 for 0.25 s (max_frame_age_s 0.1 s). It
// starts the stall once frame 3 is written and the output has looked at the clock since, and
// ends it once the watchdog has written its stop; the clock does not move while it waits, so
// there is exactly one, 0.25 s after frame 3.
TEST(RunPipeline, WatchdogStopsWhenTheSourceStalls) {
  test::WatchedClock clock;
  FakeSource source(after_learning({{1.5F}, {1.5F}, {1.5F}}));
  CollectingSink sink;
  source.before_step = stall_before_frame_4(clock, sink, 250'000'000);
  RunOptions options;
  options.clock = &clock;
  const RunSummary summary = run(source, sink, fake_params(0.1), options);

  ASSERT_EQ(sink.results.size(), 8U);  // 6 frames, the watchdog's stop, the final stop
  const FrameResult& watchdog = sink.results[4];
  EXPECT_EQ(watchdog.verdict.code, ReasonCode::no_frame);
  EXPECT_EQ(watchdog.verdict.state, VerdictState::stop);
  EXPECT_EQ(watchdog.verdict.reason, "no frame for 0.250 s (max_frame_age_s 0.100)");
  EXPECT_FALSE(watchdog.valid);
  EXPECT_FALSE(watchdog.source_frame);
  EXPECT_EQ(watchdog.frame, 3);  // it repeats the last frame's index
  // The run recovers: the frames after the stall are processed normally, none of them stale.
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 6U);
  for (size_t i = 3; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].frame, static_cast<int64_t>(i));
    EXPECT_EQ(frames[i].verdict.state, VerdictState::run) << "frame " << i;
  }
  EXPECT_EQ(summary.verdict_run, 3);
  EXPECT_EQ(summary.verdict_stop, 3);  // learning; the watchdog's stop is no frame's verdict
  EXPECT_DOUBLE_EQ(summary.wall_s, 0.25);
  EXPECT_EQ(sink.results.back().verdict.reason, "source ended");
}

// The watchdog's stop is held like any other (safety.min_hold_s 20 ms on the frames' own
// times, 30 frames/s): frame 4, the first after the silence, says `holding` stop, frame 5
// (33 ms later) runs again. Without the stall frame 4 runs.
TEST(RunPipeline, FramesAfterAWatchdogStopHoldIt) {
  for (const bool stall : {true, false}) {
    SCOPED_TRACE(stall ? "with the stall" : "without it");
    test::WatchedClock clock;
    FakeSource source(after_learning({{1.5F}, {1.5F}, {1.5F}}));
    CollectingSink sink;
    if (stall) source.before_step = stall_before_frame_4(clock, sink, 250'000'000);
    RunOptions options;
    options.clock = &clock;
    PipelineParams params = fake_params(0.1);
    params.safety.min_hold_s = 0.02;
    run(source, sink, params, options);

    const std::vector<FrameResult> frames = sink.frame_results();
    ASSERT_EQ(frames.size(), 6U);
    EXPECT_EQ(frames[3].verdict.state, VerdictState::run);  // before the stall
    EXPECT_EQ(frames[4].verdict.state, stall ? VerdictState::stop : VerdictState::run);
    EXPECT_EQ(frames[4].verdict.code == ReasonCode::holding, stall);
    EXPECT_EQ(frames[5].verdict.state, VerdictState::run);
  }
}

// A live source (frames at the camera's rate) at 30 frames/s: no frame for 2 periods
// (safety.max_frame_gap_periods, 66.7 ms) is a stop although max_frame_age_s is 0.5 s. The
// source stalls 70 ms of fake time before frame 4, as above: exactly one watchdog stop.
class LiveFakeSource : public FakeSource {
 public:
  using FakeSource::FakeSource;
  SourceInfo info() const override {
    SourceInfo info = FakeSource::info();
    info.live = true;
    info.nominal_fps = 30.0;
    return info;
  }
};

TEST(RunPipeline, WatchdogStopsALiveSourceAfterTwoFramePeriods) {
  test::WatchedClock clock;
  LiveFakeSource source(after_learning({{1.5F}, {1.5F}, {1.5F}}));
  CollectingSink sink;
  // A live source's frames are not waited for: each one comes once the last is written, so
  // that none is replaced before processing takes it.
  const std::function<bool(size_t)> stall = stall_before_frame_4(clock, sink, 70'000'000);
  source.before_step = [&](size_t step) {
    const bool written = sink.wait_until([&](const std::vector<FrameResult>& results) {
      return static_cast<size_t>(std::count_if(results.begin(), results.end(),
                                               [](const FrameResult& r) { return r.source_frame; })) >= step;
    });
    return written && stall(step);
  };
  RunOptions options;
  options.clock = &clock;
  run(source, sink, fake_params(0.5), options);

  ASSERT_EQ(sink.results.size(), 8U);  // 6 frames, the watchdog's stop, the final stop
  const FrameResult& watchdog = sink.results[4];
  EXPECT_EQ(watchdog.verdict.code, ReasonCode::no_frame);
  EXPECT_EQ(watchdog.verdict.reason, "no frame for 0.070 s (max_frame_gap_periods 2 at 30 frames/s)");
  EXPECT_FALSE(watchdog.source_frame);
}

// A live camera does not wait for processing: while processing is held at frame 3, the
// camera delivers frames 4 to 8 and each replaces the one before it. Processing then takes
// frame 8, the newest; frames 4 to 7 were never processed and are counted as dropped.
class EndingLiveSource : public LiveFakeSource {
 public:
  using LiveFakeSource::LiveFakeSource;
  Status next(Frame& out) override {
    const Status status = LiveFakeSource::next(out);
    if (status == Status::end) {
      std::lock_guard<std::mutex> lock(mutex);
      ended = true;
      changed.notify_all();
    }
    return status;
  }
  std::mutex mutex;
  std::condition_variable changed;
  bool ended = false;
};

TEST(RunPipeline, LiveSourceKeepsTheNewestFrameAndCountsTheRest) {
  EndingLiveSource source(after_learning({{1.5F}, {1.5F}, {1.5F}, {1.5F}, {1.5F}, {1.5F}}));
  CollectingSink sink;
  // Frames 0-3 come one at a time (each once the last is written or, for 3, held); frames
  // 4-8 as fast as the source can.
  bool held = false;
  source.before_step = [&](size_t step) {
    if (step != 4) return step > 4 || has_results(sink, step);
    std::unique_lock<std::mutex> lock(source.mutex);
    return source.changed.wait_for(lock, std::chrono::seconds(10), [&] { return held; });
  };
  RunOptions options;
  int calls = 0;
  bool waited = false;
  options.before_process = [&](Pipeline&, const FrameResult&) {
    if (calls++ != 3) return;
    std::unique_lock<std::mutex> lock(source.mutex);
    held = true;
    source.changed.notify_all();
    waited = source.changed.wait_for(lock, std::chrono::seconds(10), [&] { return source.ended; });
  };
  const RunSummary summary = run(source, sink, fake_params(0.5), options);

  EXPECT_TRUE(waited);
  EXPECT_EQ(summary.frames_in, 9);
  EXPECT_EQ(summary.frames_processed, 5);  // 0-3 and 8
  EXPECT_GE(summary.frames_dropped, 4);    // 4-7 in capture; the output may drop 3 as well
  const std::vector<FrameResult> frames = sink.frame_results();
  EXPECT_EQ(static_cast<int64_t>(frames.size()) + summary.frames_dropped, summary.frames_in);
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.back().frame, 8);
  for (const FrameResult& r : frames) EXPECT_TRUE(r.frame < 4 || r.frame == 8) << r.frame;
}

// The same stall of 70 ms from a source that delivers on demand (a recording, unpaced): only
// max_frame_age_s counts, so there is no watchdog stop.
TEST(RunPipeline, FrameGapDoesNotApplyToAnUnpacedRecording) {
  test::WatchedClock clock;
  FakeSource source(after_learning({{1.5F}, {1.5F}, {1.5F}}));
  CollectingSink sink;
  source.before_step = [&](size_t step) {
    if (step != 4) return true;
    if (!has_results(sink, 4) || !clock.wait_output_reads_above(clock.output_reads())) return false;
    clock.fake.advance(70'000'000);
    // The output looks at the clock after the jump at least twice (10 ms slices): time to fire.
    const int64_t reads = clock.output_reads();
    return clock.wait_output_reads_above(reads + 1);
  };
  RunOptions options;
  options.clock = &clock;
  run(source, sink, fake_params(0.5), options);
  ASSERT_EQ(sink.results.size(), 7U);  // 6 frames, the final stop
  for (const FrameResult& r : sink.results) EXPECT_NE(r.verdict.code, ReasonCode::no_frame);
}

// A live camera that is unplugged says so (Source::silence_reason): the watchdog's stop then
// carries camera_disconnected instead of no_frame, and the camera's return ends it. Same fake
// clock choreography as above: the source is "unplugged" during the stall before frame 4.
class UnpluggableSource : public FakeSource {
 public:
  using FakeSource::FakeSource;
  ReasonCode silence_reason() const override { return silence.load(); }
  std::atomic<ReasonCode> silence{ReasonCode::no_frame};
};

TEST(RunPipeline, WatchdogStopNamesTheDisconnectedCamera) {
  test::WatchedClock clock;
  UnpluggableSource source(after_learning({{1.5F}, {1.5F}, {1.5F}}));
  CollectingSink sink;
  source.before_step = [&](size_t step) {
    if (step != 4) return true;
    if (!has_results(sink, 4) || !clock.wait_output_reads_above(clock.output_reads())) return false;
    source.silence = ReasonCode::camera_disconnected;  // unplugged
    clock.fake.advance(250'000'000);
    const bool stopped = sink.wait_until([](const std::vector<FrameResult>& results) {
      return !results.empty() && results.back().verdict.code == ReasonCode::camera_disconnected;
    });
    source.silence = ReasonCode::no_frame;  // the same serial is back and streams
    return stopped;
  };
  RunOptions options;
  options.clock = &clock;
  run(source, sink, fake_params(0.1), options);

  ASSERT_EQ(sink.results.size(), 8U);  // 6 frames, the watchdog's stop, the final stop
  const FrameResult& watchdog = sink.results[4];
  EXPECT_EQ(watchdog.verdict.code, ReasonCode::camera_disconnected);
  EXPECT_EQ(watchdog.verdict.state, VerdictState::stop);
  EXPECT_EQ(watchdog.verdict.reason, "camera disconnected: no frame for 0.250 s (max_frame_age_s 0.100)");
  EXPECT_FALSE(watchdog.source_frame);
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 6U);
  EXPECT_EQ(frames[4].verdict.state, VerdictState::run);  // back: frames are processed again
  EXPECT_EQ(sink.results.back().verdict.code, ReasonCode::source_ended);
}

// A live source waiting for its camera ends the wait with `end` when the run is stopped
// (SIGINT): the run ends as stopped, not as a source that ended.
class WaitEndedByStop : public FakeSource {
 public:
  WaitEndedByStop(std::vector<Step> steps, std::atomic<bool>& stop) : FakeSource(std::move(steps)), stop_(stop) {}
  Status next(Frame& out) override {
    if (delivered_ == 4) {
      stop_ = true;  // the signal arrives during the source's own wait
      return Status::end;
    }
    ++delivered_;
    return FakeSource::next(out);
  }

 private:
  std::atomic<bool>& stop_;
  int delivered_ = 0;
};

TEST(RunPipeline, SourceEndingOnAStopRequestEndsTheRunAsStopped) {
  std::atomic<bool> stop{false};
  WaitEndedByStop source(after_learning({{1.5F}, {1.5F}, {1.5F}}), stop);
  CollectingSink sink;
  RunOptions options;
  options.stop_requested = &stop;
  const RunSummary summary = run(source, sink, fake_params(), options);
  EXPECT_EQ(summary.frames_in, 4);
  EXPECT_EQ(summary.end_code, ReasonCode::stop_requested);
  EXPECT_EQ(summary.end_reason, "stop requested");
  EXPECT_EQ(sink.results.back().verdict.code, ReasonCode::stop_requested);
}

// The same on the steady clock, with a real stall of 0.4 s (max_frame_age_s 0.1 s): at least
// one watchdog stop comes after frame 3 and before frame 4. (How many, and whether a loaded
// machine adds some elsewhere, is up to the scheduler; the fake clock's test counts them.)
TEST(RunPipeline, WatchdogOnTheSteadyClockStopsWhenTheSourceStalls) {
  FakeSource source(after_learning({{1.5F}, {1.5F, 0.4}, {1.5F}}));
  CollectingSink sink;
  run(source, sink, fake_params(0.1));
  size_t after_3 = 0, before_4 = 0;
  for (size_t i = 0; i < sink.results.size(); ++i) {
    if (sink.results[i].source_frame && sink.results[i].frame == 3) after_3 = i;
    if (sink.results[i].source_frame && sink.results[i].frame == 4) before_4 = i;
  }
  ASSERT_GT(before_4, after_3 + 1) << "no watchdog stop between frames 3 and 4";
  for (size_t i = after_3 + 1; i < before_4; ++i) {
    EXPECT_EQ(sink.results[i].verdict.code, ReasonCode::no_frame);
    EXPECT_TRUE(starts_with(sink.results[i].verdict.reason, "no frame for")) << sink.results[i].verdict.reason;
    EXPECT_NE(sink.results[i].verdict.reason.find("(max_frame_age_s 0.100)"), std::string::npos);
  }
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 6U);
  EXPECT_EQ(frames[4].verdict.state, VerdictState::run) << frames[4].verdict.reason;
}

// Frame 4 is measured, then 0.2 s of fake time pass before the output takes it (a slow output,
// or the whole process stopped by SIGSTOP or a VM pause right after processing): it is decided
// at its age as it is then, 0.2 s > max_frame_age_s 0.1 s, and becomes a stop. (Before S1 the
// verdict was made when processing ended, and a 1 s old `run` could be written after a freeze.)
// The capture of frame 5 waits for the stall, so frame 5 is fresh again.
TEST(RunPipeline, MeasurementThatWaitsBeforeItsDecisionIsStale) {
  test::WatchedClock clock;
  std::mutex mutex;
  std::condition_variable changed;
  bool measured_4 = false, stalled = false;
  const auto wait_for = [&](const bool& flag) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, std::chrono::duration<double>(test::kTestWaitS), [&] { return flag; });
  };
  FakeSource source(after_learning({{1.5F}, {1.5F}, {1.5F}}));
  source.before_step = [&](size_t step) { return step != 5 || wait_for(stalled); };
  CollectingSink sink;
  // The output thread, writing frame 3, waits until frame 4 is measured, then 0.2 s pass: frame
  // 4 is in the mailbox (or about to be) while the clock moves, and the output's wait for it
  // starts after the move, so the watchdog has nothing to say; only frame 4's age does.
  sink.before_frame = [&](const FrameResult& r) {
    if (r.frame != 3) return;
    EXPECT_TRUE(wait_for(measured_4));
    clock.fake.advance(200'000'000);
    std::lock_guard<std::mutex> lock(mutex);
    stalled = true;
    changed.notify_all();
  };
  RunOptions options;
  options.clock = &clock;
  options.on_processed = [&](const Frame& frame, const Pipeline&, const FrameResult&) {
    if (frame.index != 4) return;
    std::lock_guard<std::mutex> lock(mutex);
    measured_4 = true;
    changed.notify_all();
  };
  const RunSummary summary = run(source, sink, fake_params(0.1), options);

  ASSERT_EQ(sink.results.size(), 7U);  // no watchdog stop
  for (size_t i = 0; i < 6; ++i) {
    const FrameResult& r = sink.results[i];
    EXPECT_EQ(r.frame, static_cast<int64_t>(i));
    EXPECT_EQ(r.verdict.code == ReasonCode::stale_frame, i == 4) << "frame " << i << ": " << r.verdict.reason;
    if (i == 3 || i == 5) {
      EXPECT_EQ(r.verdict.state, VerdictState::run) << "frame " << i;
    }
  }
  EXPECT_EQ(sink.results[4].verdict.state, VerdictState::stop);
  EXPECT_EQ(sink.results[4].verdict.reason, "stale frame");
  EXPECT_NEAR(sink.results[4].frame_age_s, 0.2, 1e-9);
  EXPECT_TRUE(sink.results[4].contact.valid);  // it was measured, but is too old to trust
  EXPECT_EQ(summary.verdict_stop, 4);  // 3 learning + the stale one
  EXPECT_EQ(summary.verdict_run, 2);
  EXPECT_DOUBLE_EQ(summary.wall_s, 0.2);
}

// On the steady clock: no frame can be processed within 100 ns of its capture, every one is
// stale.
TEST(RunPipeline, StaleFrameIsStop) {
  FakeSource source(after_learning({{1.5F}, {1.5F}}));
  CollectingSink sink;
  const RunSummary summary = run(source, sink, fake_params(1e-7));
  int stale = 0;
  for (const FrameResult& r : sink.results) {
    EXPECT_EQ(r.verdict.state, VerdictState::stop);
    stale += r.verdict.code == ReasonCode::stale_frame ? 1 : 0;
  }
  EXPECT_EQ(stale, summary.frames_processed);
  EXPECT_EQ(summary.frames_processed, 5);
  EXPECT_EQ(summary.verdict_run, 0);
}

// Paced at the fake's 30 fps timestamps on a fake clock, whose sleeps take no real time: the
// source delivers as fast as it can, faster than processing, so frames may be dropped;
// whatever is dropped is counted, so every frame read is either written or counted as
// dropped. The clock ends at the last frame's due time: 5 steps of 33'333'333 ns.
TEST(RunPipeline, PacedRunCountsWhatItDrops) {
  FakeSource source(after_learning({{1.5F}, {0.8F}, {1.5F}}));
  CollectingSink sink;
  FakeClock clock;
  RunOptions options;
  options.pace = true;
  options.clock = &clock;
  const RunSummary summary = run(source, sink, fake_params(), options);
  EXPECT_EQ(summary.frames_in, 6);
  const auto written = static_cast<int64_t>(sink.frame_results().size());
  EXPECT_EQ(written + summary.frames_dropped, summary.frames_in);
  EXPECT_EQ(sink.results.back().verdict.reason, "source ended");
  EXPECT_EQ(clock.now_ns(), 5 * 33'333'333);
  EXPECT_DOUBLE_EQ(summary.wall_s, 0.166666665);
}

// A paced run of 31 frames at 30 frames/s on a fake clock takes 30 periods of fake time. The
// source reads frame k only once frame k-1 is written, so nothing is dropped, nothing is
// stale (each frame is processed before the clock moves on) and the watchdog (0.5 s) is
// quiet: the output is exactly the 31 frames and the final stop.
TEST(RunPipeline, PacedRunTakesItsTimestampsTimeOnAFakeClock) {
  FakeSource source(std::vector<Step>(31, Step{}));
  CollectingSink sink;
  source.before_step = [&](size_t step) { return has_results(sink, step); };
  FakeClock clock(1'000'000'000);  // any origin
  RunOptions options;
  options.pace = true;
  options.clock = &clock;
  const RunSummary summary = run(source, sink, fake_params(), options);
  EXPECT_EQ(summary.frames_in, 31);
  EXPECT_EQ(summary.frames_processed, 31);
  EXPECT_EQ(summary.frames_dropped, 0);
  ASSERT_EQ(sink.results.size(), 32U);
  for (size_t i = 0; i < 31; ++i) {
    EXPECT_EQ(sink.results[i].frame, static_cast<int64_t>(i));
    EXPECT_EQ(sink.results[i].verdict.code, i < 3 ? ReasonCode::learning_background : ReasonCode::no_foreground) << i;
  }
  EXPECT_EQ(clock.now_ns(), 1'000'000'000 + 30 * 33'333'333);
  EXPECT_DOUBLE_EQ(summary.wall_s, 0.99999999);
  EXPECT_DOUBLE_EQ(summary.fps, 31 / 0.99999999);
}

// Paced waits on a fake clock take no real time: 3 steps of 20 s (max_frame_age_s 60 s) are
// a minute of fake time, and the run is over in far less real time than that.
TEST(RunPipeline, PacedWaitsOnAFakeClockTakeNoRealTime) {
  std::vector<Step> steps(4, Step{});
  for (size_t i = 0; i < steps.size(); ++i) steps[i].timestamp_ns = static_cast<int64_t>(i) * 20'000'000'000;
  FakeSource source(steps);
  CollectingSink sink;
  source.before_step = [&](size_t step) { return has_results(sink, step); };
  FakeClock clock;
  RunOptions options;
  options.pace = true;
  options.clock = &clock;
  const auto real_start = std::chrono::steady_clock::now();
  const RunSummary summary = run(source, sink, fake_params(60.0), options);
  const double real_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - real_start).count();
  EXPECT_EQ(summary.frames_in, 4);
  EXPECT_EQ(summary.frames_dropped, 0);
  EXPECT_EQ(clock.now_ns(), 60'000'000'000);
  EXPECT_DOUBLE_EQ(summary.wall_s, 60.0);
  EXPECT_LT(real_s, 30.0);
}

TEST(RunPipeline, StopRequestEndsTheRun) {
  std::vector<Step> steps(50, Step{1.5F});
  FakeSource source(after_learning(steps));
  CollectingSink sink;
  std::atomic<bool> stop{true};
  RunOptions options;
  options.stop_requested = &stop;
  const RunSummary summary = run(source, sink, fake_params(), options);
  EXPECT_EQ(summary.frames_in, 0);
  ASSERT_EQ(sink.results.size(), 1U);
  EXPECT_EQ(sink.results.back().verdict.state, VerdictState::stop);
}

// A live source that has nothing yet says `idle`: the run asks again, counts only frames, and
// still ends on a stop request while the camera is silent.
class IdleBetweenFrames : public Source {
 public:
  IdleBetweenFrames(FakeSource& frames, int idles_per_frame) : frames_(frames), idles_per_frame_(idles_per_frame) {}
  SourceInfo info() const override { return frames_.info(); }
  Status next(Frame& out) override {
    ++calls;
    if (idles_++ < idles_per_frame_) return Status::idle;
    idles_ = 0;
    return frames_.next(out);
  }
  int calls = 0;

 private:
  FakeSource& frames_;
  int idles_per_frame_;
  int idles_ = 0;
};

TEST(RunPipeline, IdleSourceIsAskedAgainAndIdleCallsAreNoFrames) {
  FakeSource frames(after_learning({{1.5F}, {1.5F}, {1.5F}}));
  IdleBetweenFrames source(frames, 2);
  CollectingSink sink;
  RunOptions options;
  options.max_frames = 5;
  const RunSummary summary = test::run_fake(source, sink, fake_params(), options);
  EXPECT_EQ(summary.frames_in, 5);  // the limit counts frames, not calls
  EXPECT_EQ(source.calls, 15);      // 2 idle calls before each of the 5 frames
  EXPECT_EQ(summary.end_code, ReasonCode::frame_limit_reached);
  EXPECT_EQ(sink.frame_results().size(), 5U);
}

class AlwaysIdle : public Source {
 public:
  explicit AlwaysIdle(std::atomic<bool>& stop) : stop_(stop) {}
  SourceInfo info() const override {
    SourceInfo info;
    info.intrinsics = test::fake_intrinsics();
    return info;
  }
  Status next(Frame&) override {
    if (++calls == 3) stop_.store(true);  // as SIGINT would, while the camera is silent
    return Status::idle;
  }
  int calls = 0;

 private:
  std::atomic<bool>& stop_;
};

TEST(RunPipeline, StopRequestEndsARunWhoseSourceIsSilent) {
  std::atomic<bool> stop{false};
  AlwaysIdle source(stop);
  CollectingSink sink;
  RunOptions options;
  options.stop_requested = &stop;
  const RunSummary summary = test::run_fake(source, sink, fake_params(), options);
  EXPECT_EQ(source.calls, 3);
  EXPECT_EQ(summary.frames_in, 0);
  EXPECT_EQ(summary.end_code, ReasonCode::stop_requested);
  ASSERT_FALSE(sink.results.empty());
  EXPECT_EQ(sink.results.back().verdict.state, VerdictState::stop);
}

// A replay paused for 2 s (the source says idle meanwhile, as hrcsense-view's PlaybackSource
// does) goes on at its own pace afterwards: frame 5 when the pause ends, each later one a
// frame period after it. Were the frames after the pause due at their old times, they would
// all be due at once and the fake clock would not move after the pause.
class PausesOnce : public Source {
 public:
  PausesOnce(FakeSource& frames, FakeClock& clock, CollectingSink& sink) : frames_(frames), clock_(clock), sink_(sink) {}
  SourceInfo info() const override { return frames_.info(); }
  Status next(Frame& out) override {
    if (delivered_ == 5 && !paused_) {
      paused_ = true;
      if (!has_results(sink_, 5)) return Status::error;
      clock_.advance(2'000'000'000);
      return Status::idle;
    }
    const Status status = frames_.next(out);
    if (status == Status::frame) ++delivered_;
    return status;
  }

 private:
  FakeSource& frames_;
  FakeClock& clock_;
  CollectingSink& sink_;
  int delivered_ = 0;
  bool paused_ = false;
};

TEST(RunPipeline, PacingStartsAgainAfterASilence) {
  FakeSource frames(std::vector<Step>(10, Step{}));
  CollectingSink sink;
  frames.before_step = [&](size_t step) { return has_results(sink, step); };
  FakeClock clock(1'000'000'000);
  PausesOnce source(frames, clock, sink);
  RunOptions options;
  options.pace = true;
  options.clock = &clock;
  const RunSummary summary = test::run_fake(source, sink, fake_params(5.0), options);
  EXPECT_EQ(summary.frames_in, 10);
  EXPECT_EQ(summary.frames_dropped, 0);
  // Frames 0-4 at 0, 1, ... 4 periods; the pause; frames 5-9 at 0 ... 4 periods after it.
  EXPECT_EQ(clock.now_ns(), int64_t{1'000'000'000} + 4 * 33'333'333 + 2'000'000'000 + 4 * 33'333'333);
}

}  // namespace
}  // namespace hrcsense
