// SPDX-License-Identifier: Apache-2.0
// Tests of run_pipeline: threads, fail-safe stops, watchdog and summary, with a fake source.

#include "fake_scene.hpp"

#include <gtest/gtest.h>

#include <string>

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

TEST(RunPipeline, WatchdogStopsWhenTheSourceStalls) {
  // The source stalls for 0.25 s before frame 4; max_frame_age_s is 0.1 s.
  FakeSource source(after_learning({{1.5F}, {1.5F, 0.25}, {1.5F}}));
  CollectingSink sink;
  run(source, sink, fake_params(0.1));
  size_t first_watchdog = sink.results.size();
  for (size_t i = 0; i < sink.results.size(); ++i) {
    if (sink.results[i].verdict.code == ReasonCode::no_frame) {
      EXPECT_TRUE(starts_with(sink.results[i].verdict.reason, "no frame for"));
      first_watchdog = std::min(first_watchdog, i);
      EXPECT_EQ(sink.results[i].verdict.state, VerdictState::stop);
      EXPECT_FALSE(sink.results[i].valid);
      EXPECT_NE(sink.results[i].verdict.reason.find("max_frame_age_s 0.100"), std::string::npos);
    }
  }
  ASSERT_LT(first_watchdog, sink.results.size()) << "no watchdog stop was written";
  EXPECT_EQ(sink.results[first_watchdog - 1].frame, 3);  // it came after frame 3, before frame 4
  // The run recovers: the frames after the stall are processed normally.
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 6U);
  EXPECT_EQ(frames[4].verdict.state, VerdictState::run);
  EXPECT_EQ(frames[5].verdict.state, VerdictState::run);
}

TEST(RunPipeline, StaleFrameIsStop) {
  // No frame can be processed within 100 ns of its capture: every one is stale.
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

TEST(RunPipeline, PacedRunCountsWhatItDrops) {
  // Paced at the fake's 30 fps timestamps; whatever is dropped is counted, so every frame read
  // is either written or counted as dropped.
  FakeSource source(after_learning({{1.5F}, {0.8F}, {1.5F}}));
  CollectingSink sink;
  RunOptions options;
  options.pace = true;
  const RunSummary summary = run(source, sink, fake_params(), options);
  EXPECT_EQ(summary.frames_in, 6);
  const auto written = static_cast<int64_t>(sink.frame_results().size());
  EXPECT_EQ(written + summary.frames_dropped, summary.frames_in);
  EXPECT_EQ(sink.results.back().verdict.reason, "source ended");
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

}  // namespace
}  // namespace hrcsense
