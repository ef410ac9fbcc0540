// SPDX-License-Identifier: Apache-2.0
// Tests of what changes while the cell runs: Pipeline::retune, relearn_background and
// RunOptions::before_process (hrcsense-view's panels reach the pipeline through them).

#include "../support/decide.hpp"
#include "fake_scene.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace hrcsense {
namespace {

using test::expected_distance_m;
using test::fake_params;
using test::fill_frame;

// The wall learnt, then frame 3 with the 40×40 px object at 0.8 m (0.32 m wide): slow.
bool learn_then_see_the_object(Pipeline& pipeline, Frame& frame, FrameResult& result) {
  if (!test::learn_wall(pipeline, frame, result)) return false;
  fill_frame(3, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  return result.verdict.state == VerdictState::slow;
}

TEST(Retune, ForegroundChangeTakesEffectOnTheNextFrame) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(learn_then_see_the_object(pipeline, frame, result));

  // Objects below 1 km are speckles now: the same frame has nothing in the cell.
  LiveTuning tuning = pipeline.tuning();
  tuning.foreground.min_object_mm = 1e6F;
  pipeline.retune(tuning);
  EXPECT_EQ(pipeline.params().foreground.min_object_mm, 1e6F);
  fill_frame(4, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_TRUE(result.valid);
  EXPECT_EQ(result.foreground_points, 0U);
  EXPECT_EQ(result.verdict.code, ReasonCode::no_foreground);

  tuning.foreground.min_object_mm = 40.0F;  // back: 320 mm is an object again
  pipeline.retune(tuning);
  fill_frame(5, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.foreground_points, 40U * 40U);
  EXPECT_EQ(result.verdict.state, VerdictState::slow);
}

TEST(Retune, FilterParameterChangeTakesEffect) {
  PipelineParams params = fake_params();
  params.filters.order = {FilterBlock::threshold};
  params.filters.threshold.min_m = 0.1F;
  params.filters.threshold.max_m = 4.0F;
  Pipeline pipeline(params);
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(test::learn_wall(pipeline, frame, result));
  // The threshold filter zeroes depth beyond max: with max 1.5 m the 2 m wall is gone and only
  // the object at 0.8 m (40×40 of 80×60 px) is left.
  LiveTuning tuning = pipeline.tuning();
  tuning.filters.threshold.max_m = 1.5F;
  pipeline.retune(tuning);
  fill_frame(3, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.invalid_pixels, 0U);  // counted on the source frame, before the filters
  EXPECT_NEAR(result.valid_share, 1600.0F / 4800.0F, 1e-6F);
  // With max 0.5 m nothing is left at all: a stop.
  tuning.filters.threshold.max_m = 0.5F;
  pipeline.retune(tuning);
  fill_frame(4, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_FALSE(result.valid);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.code, ReasonCode::no_valid_depth);
}

TEST(Retune, BackendChangeKeepsTheExactDistance) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(test::learn_wall(pipeline, frame, result));
  const std::pair<ProximityBackend, const char*> backends[] = {
      {ProximityBackend::kdtree, "kdtree"}, {ProximityBackend::octree, "octree"}, {ProximityBackend::brute, "brute"}};
  for (const auto& [backend, name] : backends) {
    LiveTuning tuning = pipeline.tuning();
    tuning.backend = backend;
    pipeline.retune(tuning);
    fill_frame(3, 0.8F, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
    ASSERT_TRUE(result.contact.valid) << name;
    EXPECT_NEAR(result.contact.distance_m, expected_distance_m(0.8), 1e-4) << name;
    EXPECT_STREQ(result.backend, name);
  }
}

TEST(Retune, RefusesWhatCannotChangeAndStaysAsItWas) {
  PipelineParams params = fake_params();
  params.filters.order = {FilterBlock::decimation};
  params.filters.decimation.magnitude = 2;
  Pipeline pipeline(params);

  LiveTuning order = pipeline.tuning();
  order.filters.order = {FilterBlock::decimation, FilterBlock::spatial};
  EXPECT_THROW(pipeline.retune(order), std::invalid_argument);

  LiveTuning decimation = pipeline.tuning();
  decimation.filters.decimation.magnitude = 3;
  decimation.foreground.k_sigma = 9.0F;
  EXPECT_THROW(pipeline.retune(decimation), std::invalid_argument);

  EXPECT_EQ(pipeline.params().filters.decimation.magnitude, 2);
  EXPECT_EQ(pipeline.params().foreground.k_sigma, ForegroundParams{}.k_sigma);
  EXPECT_EQ(pipeline.params().backend, ProximityBackend::brute);
}

TEST(Relearn, TheObjectPresentWhileRelearningBecomesBackground) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(learn_then_see_the_object(pipeline, frame, result));

  pipeline.relearn_background();
  EXPECT_FALSE(pipeline.background_ready());
  for (int i = 0; i < test::kLearnFrames; ++i) {
    fill_frame(4 + i, 0.8F, frame);  // the object stands still: it is part of the scene now
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
    EXPECT_FALSE(result.valid);
    EXPECT_EQ(result.verdict.code, ReasonCode::learning_background);
  }
  EXPECT_TRUE(pipeline.background_ready());
  fill_frame(7, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_TRUE(result.valid);
  EXPECT_EQ(result.verdict.code, ReasonCode::no_foreground);
  // And where the object stood, the wall behind it is farther than the background: not foreground.
  fill_frame(8, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.foreground_points, 0U);
}

TEST(Relearn, ALoadedBackgroundIsForgottenToo) {
  Pipeline pipeline(fake_params());
  pipeline.set_background(test::learn_empty_background(), "a test background");
  ASSERT_TRUE(pipeline.background_ready());
  pipeline.relearn_background();
  EXPECT_FALSE(pipeline.background_ready());
  Frame frame;
  FrameResult result;
  fill_frame(0, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.verdict.code, ReasonCode::learning_background);
}

TEST(RunPipeline, BeforeProcessSeesEveryFrameWithThePreviousResult) {
  test::FakeSource source(test::after_learning({{1.5F}, {0.8F}, {0.0F}}));
  test::CollectingSink sink;
  std::vector<int64_t> previous_frames;
  std::vector<bool> previous_valid;
  RunOptions options;
  options.before_process = [&](Pipeline& pipeline, const FrameResult& previous) {
    previous_frames.push_back(previous.frame);
    previous_valid.push_back(previous.valid);
    // A change made here holds from this frame on: no object is small enough from frame 4 on.
    if (previous.frame == 3) {
      LiveTuning tuning = pipeline.tuning();
      tuning.foreground.min_object_mm = 1e6F;
      pipeline.retune(tuning);
    }
  };
  test::run_fake(source, sink, fake_params(), options);
  const std::vector<FrameResult> frames = sink.frame_results();
  ASSERT_EQ(frames.size(), 6U);
  ASSERT_EQ(previous_frames.size(), 6U);  // once per source frame, none for the final stop
  EXPECT_FALSE(previous_valid[0]);
  for (size_t i = 1; i < previous_frames.size(); ++i) EXPECT_EQ(previous_frames[i], static_cast<int64_t>(i - 1));
  EXPECT_EQ(frames[3].verdict.state, VerdictState::run);   // 1.5 m: beyond slow
  EXPECT_EQ(frames[4].verdict.code, ReasonCode::no_foreground);  // 0.8 m would be slow
  EXPECT_EQ(frames[5].verdict.code, ReasonCode::no_foreground);
}

}  // namespace
}  // namespace hrcsense
