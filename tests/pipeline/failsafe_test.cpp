// SPDX-License-Identifier: Apache-2.0
// R1: nothing unsafe says `run`. The processing path and the run loop against hostile data: a
// pose that overflows, frames the filters empty, a damaged loaded background, timestamps that
// jump, go backwards or repeat, a sink whose reader left.

#include "../support/decide.hpp"
#include "fake_scene.hpp"

#include "hrcsense/sinks/sinks.hpp"
#include "hrcsense/robot_state.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <sstream>
#include <string>

namespace hrcsense {
namespace {

using test::after_learning;
using test::CollectingSink;
using test::fake_params;
using test::FakeSource;
using test::fill_frame;
using test::Step;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int64_t kFrameNs = 33'333'333;

// Item 1: an overflowed pose (here inf in the translation, as 1e39 cast to float gives) turns
// every foreground point into inf/NaN; the search finds no contact, and that must be a stop.
TEST(Failsafe, ForegroundWithoutContactIsStop) {
  PipelineParams params = fake_params();
  params.T_base_camera.translation() = Eigen::Vector3d(kInf, 0.0, 0.0);
  Pipeline pipeline(params);
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(test::learn_wall(pipeline, frame, result));
  fill_frame(3, 1.5F, frame);  // a 40x40 px object at 1.5 m: 1600 foreground pixels
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.foreground_points, 1600U);
  EXPECT_FALSE(result.contact.valid);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.reason, "no contact");
  EXPECT_EQ(result.verdict.code, ReasonCode::non_finite_input);
  // The empty cell with the same broken pose has no foreground: that one is still run.
  fill_frame(4, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.foreground_points, 0U);
  EXPECT_EQ(result.verdict.state, VerdictState::run);
}

// The same with a robot capsule at infinity (a robot point of 1e39).
TEST(Failsafe, RobotAtInfinityIsStop) {
  PipelineParams params = fake_params();
  params.robot.points.capsules[0].a = params.robot.points.capsules[0].b = Eigen::Vector3f(kInf, 0.0F, 0.0F);
  Pipeline pipeline(params);
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(test::learn_wall(pipeline, frame, result));
  fill_frame(3, 1.5F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_GT(result.foreground_points, 0U);
  EXPECT_NE(result.verdict.state, VerdictState::run) << result.verdict.reason;
  EXPECT_NE(result.verdict.state, VerdictState::slow) << result.verdict.reason;
}

// Item 2: the frame the filters leave must still see the cell. A threshold that cuts away the
// whole scene (the wall is at 2 m, the threshold at 1 m) leaves no valid pixel.
TEST(Failsafe, NoValidDepthAfterTheFiltersIsStop) {
  PipelineParams params = fake_params();
  params.filters.order = {FilterBlock::threshold};
  params.filters.threshold.max_m = 1.0F;
  Pipeline pipeline(params);
  Frame frame;
  FrameResult result;
  fill_frame(0, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.invalid_pixels, 0U);  // the source frame itself is complete
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.reason, "no valid depth after filters");
  EXPECT_EQ(result.verdict.code, ReasonCode::no_valid_depth);
  EXPECT_FALSE(pipeline.background_ready());  // and it is not learnt from
}

// A frame with one valid pixel of 4800 (0.02 %) is below the default 20 % share: stop, even
// after the background is ready; a frame with the object only (1600 of 4800 = 33 %) is above.
TEST(Failsafe, TooFewValidPixelsIsStop) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(test::learn_wall(pipeline, frame, result));
  fill_frame(3, 0.0F, frame);
  std::fill(frame.depth.pixels.begin(), frame.depth.pixels.end(), uint16_t{0});
  frame.depth.pixels[100] = 2000;
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_NE(result.verdict.reason.find("min_valid_share"), std::string::npos) << result.verdict.reason;
  EXPECT_FLOAT_EQ(result.valid_share, 1.0F / 4800.0F);
  EXPECT_EQ(result.verdict.code, ReasonCode::low_valid_share);
  EXPECT_FALSE(result.valid);

  fill_frame(4, 1.5F, frame);
  for (size_t i = 0; i < frame.depth.pixels.size(); ++i) {
    if (frame.depth.pixels[i] == 2000) frame.depth.pixels[i] = 0;  // the wall is gone
  }
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_TRUE(result.valid) << result.verdict.reason;
  EXPECT_FLOAT_EQ(result.valid_share, 1600.0F / 4800.0F);
  EXPECT_EQ(result.verdict.state, VerdictState::run);  // 1.5 m is beyond slow_distance_m 1.0 m
}

// A point inside the robot (a capsule of 2 m radius around the camera origin swallows the
// object at 1.5 m) is a stop even when both zones are 0 m, which config refuses.
TEST(Failsafe, InsideTheRobotIsStopWhateverTheZones) {
  PipelineParams params = fake_params();
  params.robot.points.capsules[0].radius_m = 1.8F;
  params.safety.slow_distance_m = 0.0F;
  params.safety.stop_distance_m = 0.0F;
  Pipeline pipeline(params);
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(test::learn_wall(pipeline, frame, result));
  fill_frame(3, 1.5F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  ASSERT_TRUE(result.contact.valid);
  EXPECT_TRUE(result.contact.inside);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.code, ReasonCode::inside_robot);
}

// The background a file holds is checked against the first frames. The one learnt here says
// the wall is at 2 m; a "damaged" copy says 1 m: everything behind it (the real wall) would
// be hidden, so the check refuses it. The true one passes and the pipeline then measures.
TEST(Failsafe, LoadedBackgroundThatMatchesIsUsedAfterTheCheck) {
  PipelineParams params = fake_params();
  params.background.check_frames = 2;
  Pipeline pipeline(params);
  pipeline.set_background(test::learn_empty_background());
  Frame frame;
  FrameResult result;
  // A person in front of the wall only makes pixels nearer: no reason to doubt the file.
  fill_frame(0, 1.5F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.reason, "checking loaded background (1/2 frames)");
  EXPECT_EQ(result.verdict.code, ReasonCode::checking_background);
  fill_frame(1, 1.5F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.verdict.reason, "checking loaded background (2/2 frames)");
  fill_frame(2, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_TRUE(result.valid);
  EXPECT_EQ(result.verdict.state, VerdictState::slow);
}

// The learnt wall "damaged" behind a correct checksum: it says 1 m where the wall is at 2 m.
BackgroundModel nearer_than_the_wall() {
  BackgroundModel damaged = test::learn_empty_background();
  std::fill(damaged.mean_m.begin(), damaged.mean_m.end(), 1.0F);
  return damaged;
}

TEST(Failsafe, LoadedBackgroundNearerThanTheSceneIsRefused) {
  const BackgroundModel damaged = nearer_than_the_wall();
  PipelineParams params = fake_params();
  params.background.check_frames = 2;
  Pipeline pipeline(params);
  pipeline.set_background(damaged);
  Frame frame;
  FrameResult result;
  fill_frame(0, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  fill_frame(1, 0.0F, frame);
  try {
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
    FAIL() << "a background 1 m nearer than the whole scene was accepted";
  } catch (const BackgroundMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("100.0 %"), std::string::npos) << e.what();
  }
}

// By hand: 4 reliable pixels at 2 m with 1 cm spread (margin max(4 * 0.01, 0.02) = 4 cm); one
// unknown (mean 0) and one unreliable pixel are never compared.
TEST(Failsafe, BackgroundCheckCountsOnlyPixelsFartherThanTheMargin) {
  BackgroundModel model;
  model.width = 6;
  model.height = 1;
  model.mean_m = {2.0F, 2.0F, 2.0F, 2.0F, 0.0F, 2.0F};
  model.spread_m = {0.01F, 0.01F, 0.01F, 0.01F, 0.01F, 0.01F};
  model.valid_ratio = {1.0F, 1.0F, 1.0F, 1.0F, 1.0F, 0.1F};
  DepthImage depth;
  depth.resize(6, 1);
  // nearer (a person), within the margin, 5 cm farther, invalid; unknown; unreliable and far.
  depth.pixels = {1500, 2030, 2050, 0, 3000, 3000};
  BackgroundCheck check;
  check.frames = 1;
  check.max_farther_share = 0.25F;
  EXPECT_EQ(check.add(model, depth), 1);
  EXPECT_TRUE(check.done());
  EXPECT_DOUBLE_EQ(check.farther_share(), 1.0 / 3.0);  // 1 of the 3 compared pixels
  EXPECT_TRUE(check.mismatch());
  // A NaN in a damaged model is never trusted.
  model.mean_m[0] = 2.0F;
  model.spread_m[0] = std::numeric_limits<float>::quiet_NaN();
  BackgroundCheck nan_check;
  nan_check.frames = 1;
  depth.pixels = {2000, 2000, 2000, 2000, 0, 0};
  nan_check.add(model, depth);
  EXPECT_DOUBLE_EQ(nan_check.farther_share(), 1.0 / 4.0);
}

RunSummary run(FakeSource& source, Sink& sink, const PipelineParams& params, const RunOptions& options) {
  return test::run_fake(source, sink, params, options);
}

// Timestamps that go backwards, repeat, skip frames or jump are counted and marked on their
// frame. At the fake's 30 frames/s: +33 ms is in order, +100 ms is a gap of 2 skipped frames,
// +10 s a jump beyond max_frame_age_s.
TEST(Failsafe, TimestampsOutOfOrderAreCountedAndMarked) {
  std::vector<Step> steps(8, Step{});
  const int64_t stamps[] = {0, kFrameNs, 2 * kFrameNs, 2 * kFrameNs, kFrameNs, 4 * kFrameNs,
                            4 * kFrameNs + 10'000'000'000, 4 * kFrameNs + 10'033'333'333};
  for (size_t i = 0; i < steps.size(); ++i) steps[i].timestamp_ns = stamps[i];
  FakeSource source(steps);
  CollectingSink sink;
  const RunSummary summary = run(source, sink, fake_params(), RunOptions{});
  EXPECT_EQ(summary.timestamps.repeated, 1);
  EXPECT_EQ(summary.timestamps.backwards, 1);
  EXPECT_EQ(summary.timestamps.gaps, 1);
  EXPECT_EQ(summary.timestamps.frames_skipped, 2);
  EXPECT_EQ(summary.timestamps.jumps, 1);
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 8U);
  const bool marked[] = {false, false, false, true, true, true, true, false};
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].timestamp_warning != nullptr, marked[i]) << "frame " << i;
  }
}

// Item 8: a jump of 10^6 s in a paced recording is cut to max_frame_age_s (0.1 s here) instead
// of a sleep of eleven days. On a fake clock the waits take no real time and add up exactly:
// 3 steps of 33'333'333 ns, then the jump cut to 100'000'000 ns.
TEST(Failsafe, PacedJumpIsBoundedByMaxFrameAge) {
  std::vector<Step> steps(after_learning({{1.5F}, {1.5F}}));
  steps[4].timestamp_ns = 1'000'000 * 1'000'000'000LL;
  FakeSource source(steps);
  CollectingSink sink;
  FakeClock clock;
  RunOptions options;
  options.pace = true;
  options.clock = &clock;
  const RunSummary summary = run(source, sink, fake_params(0.1), options);
  EXPECT_EQ(summary.end_reason, "end of source");
  EXPECT_EQ(summary.frames_in, 5);
  EXPECT_EQ(summary.timestamps.jumps, 1);
  EXPECT_EQ(clock.now_ns(), 3 * 33'333'333 + 100'000'000);
  EXPECT_DOUBLE_EQ(summary.wall_s, 0.199999999);
}

// A paced wait is interruptible: with max_frame_age_s 60 s a 20 s step is waited for, and a
// stop request (SIGINT, SIGTERM) during it ends the run at once. On the steady clock: it is
// its sleep that must end.
struct StopOnFirstFrame : CollectingSink {
  std::atomic<bool>* stop = nullptr;
  void frame(const FrameResult& r) override {
    CollectingSink::frame(r);
    stop->store(true);
  }
};

TEST(Failsafe, StopRequestInterruptsAPacedWait) {
  std::vector<Step> steps(3, Step{});
  steps[1].timestamp_ns = 20'000'000'000;
  steps[2].timestamp_ns = 40'000'000'000;
  FakeSource source(steps);
  StopOnFirstFrame sink;
  std::atomic<bool> stop{false};
  sink.stop = &stop;
  RunOptions options;
  options.pace = true;
  options.stop_requested = &stop;
  const RunSummary summary = run(source, sink, fake_params(60.0), options);
  EXPECT_EQ(summary.end_reason, "stop requested");
  EXPECT_EQ(summary.end_code, ReasonCode::stop_requested);
  EXPECT_EQ(sink.results.back().verdict.code, ReasonCode::stop_requested);
  EXPECT_LT(summary.wall_s, 10.0);  // far from the 20 s the step asks for
}

// Item 5: a sink that fails (its reader left) ends the run, and the run says so.
struct FailingSink : CollectingSink {
  size_t fail_after = 2;
  bool failed() const override { return results.size() >= fail_after; }
  std::string failure() const override { return "write failed"; }
};

TEST(Failsafe, FailedSinkEndsTheRunWithAnError) {
  std::vector<Step> steps(500, Step{1.5F});
  FakeSource source(after_learning(steps));
  FailingSink sink;
  const RunSummary summary = run(source, sink, fake_params(), RunOptions{});
  EXPECT_EQ(summary.error, "output failed: write failed");
  EXPECT_EQ(summary.end_code, ReasonCode::output_error);
  EXPECT_LT(summary.frames_in, 503);  // capture stopped early, without waiting for a reader
  EXPECT_EQ(sink.results.back().verdict.state, VerdictState::stop);
}

// Item 6: an exception while processing (std::bad_alloc, say) is the run's error, which the
// app turns into exit 1; here a background that does not match throws.
TEST(Failsafe, ProcessingErrorIsTheRunsError) {
  const BackgroundModel damaged = nearer_than_the_wall();
  PipelineParams params = fake_params();
  params.background.check_frames = 1;
  Pipeline pipeline(params);
  pipeline.set_background(damaged);
  FakeSource source({Step{}, Step{}, Step{}});
  CollectingSink sink;
  RunHeader header;
  FixedRobotState robot_states({});
  const RunSummary summary = run_pipeline(source, robot_states, pipeline, sink, RunOptions{}, header);
  EXPECT_EQ(summary.error.rfind("processing error at frame 0: the loaded background: does not match", 0), 0U)
      << summary.error;
  EXPECT_EQ(summary.end_reason, summary.error);
  EXPECT_EQ(summary.end_code, ReasonCode::processing_error);
  EXPECT_EQ(sink.results.back().verdict.state, VerdictState::stop);
  EXPECT_EQ(sink.results.back().verdict.code, ReasonCode::processing_error);
  EXPECT_EQ(sink.results.back().verdict.reason, summary.error);
}

// A run that ends normally has no error.
TEST(Failsafe, NormalEndHasNoError) {
  FakeSource source(after_learning({{1.5F}}));
  CollectingSink sink;
  const RunSummary summary = run(source, sink, fake_params(), RunOptions{});
  EXPECT_TRUE(summary.error.empty()) << summary.error;
  EXPECT_EQ(summary.end_code, ReasonCode::source_ended);
  EXPECT_EQ(sink.results.back().verdict.code, ReasonCode::source_ended);
}


}  // namespace
}  // namespace hrcsense
