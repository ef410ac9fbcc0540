// SPDX-License-Identifier: Apache-2.0
// Tests of Pipeline::process on hand-built frames, one frame at a time.

#include "../support/decide.hpp"
#include "fake_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace hrcsense {
namespace {

using test::expected_distance_m;
using test::fake_params;
using test::fill_frame;

using test::learn_empty_background;

// Each point of robot.model points is a link, measured on its own: a second point 1 m behind the
// camera (link 7) has its own closest pair, 1 m farther along z. The overall pair is link 2's.
TEST(Pipeline, MeasuresEveryLinkOnItsOwn) {
  PipelineParams params = fake_params();
  Capsule behind;
  behind.a = behind.b = {0.0F, 0.0F, -1.0F};
  behind.link = 7;
  params.robot.points.capsules.push_back(behind);
  Pipeline pipeline(params);
  Frame frame;
  FrameResult result;
  ASSERT_TRUE(test::learn_wall(pipeline, frame, result));
  fill_frame(3, 0.8F, frame);
  pipeline.process(frame, fixed_robot_state({}), result);
  ASSERT_TRUE(result.valid);
  ASSERT_EQ(result.links.size(), 2U);
  EXPECT_EQ(result.links[0].link, 2);
  EXPECT_EQ(result.links[1].link, 7);
  EXPECT_NEAR(result.links[0].contact.distance_m, expected_distance_m(0.8), 1e-4);
  // The nearest pixel centres are half a pixel off the axis: x = y = 0.5 / fx · 0.8 m.
  const double off = 0.5 / 100.0 * 0.8;
  EXPECT_NEAR(result.links[1].contact.distance_m, std::sqrt(2.0 * off * off + 1.8 * 1.8), 1e-4);
  EXPECT_EQ(result.contact.robot_link, 2);
  for (const LinkContact& link : result.links) {
    EXPECT_EQ(link.speed_towards_mps, 0.0F);  // fixed points do not move
    EXPECT_GT(link.distance_uncertainty_m, 0.0F);
  }
}

TEST(Pipeline, LearnsThenMeasuresTheObject) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  for (int i = 0; i < test::kLearnFrames; ++i) {
    fill_frame(i, 0.0F, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
    EXPECT_FALSE(result.valid);
    EXPECT_EQ(result.verdict.state, VerdictState::stop);
    EXPECT_EQ(result.verdict.reason,
              "learning background (" + std::to_string(i + 1) + "/" + std::to_string(test::kLearnFrames) + " frames)");
    ASSERT_EQ(result.timings.size(), 1U);
    EXPECT_STREQ(result.timings[0].stage, "background");
  }
  EXPECT_TRUE(pipeline.background_ready());

  fill_frame(3, 0.8F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_TRUE(result.valid);
  EXPECT_EQ(result.frame, 3);
  EXPECT_EQ(result.timestamp_ns, 3 * 33'333'333);
  ASSERT_TRUE(result.contact.valid);
  EXPECT_NEAR(result.contact.distance_m, expected_distance_m(0.8), 1e-4);
  EXPECT_NEAR(result.contact.closest_base.z(), 0.8F, 1e-4F);
  EXPECT_EQ(result.contact.closest_camera, result.contact.closest_base);  // identity pose
  EXPECT_EQ(result.contact.robot_link, 2);
  EXPECT_EQ(result.verdict.state, VerdictState::slow);
  EXPECT_EQ(result.foreground_points, 40U * 40U);
  EXPECT_EQ(result.invalid_pixels, 0U);
  ASSERT_EQ(result.timings.size(), 4U);
  EXPECT_STREQ(result.timings[0].stage, "foreground");
  EXPECT_STREQ(result.timings[1].stage, "proximity");
  EXPECT_STREQ(result.timings[2].stage, "unknown_space");
  EXPECT_STREQ(result.timings[3].stage, "safety");
  EXPECT_GE(result.latency_us, 0.0);

  // The wall alone again: nothing in the cell, run.
  fill_frame(4, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_TRUE(result.valid);
  EXPECT_FALSE(result.contact.valid);
  EXPECT_EQ(result.foreground_points, 0U);
  EXPECT_EQ(result.verdict.state, VerdictState::run);
}

TEST(Pipeline, NoValidDepthIsStop) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  fill_frame(0, -1.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_FALSE(result.valid);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.reason, "no valid depth");
  EXPECT_EQ(result.invalid_pixels, static_cast<size_t>(test::kWidth * test::kHeight));
  EXPECT_FALSE(pipeline.background_ready());  // an empty frame is not learnt from
}

TEST(Pipeline, CountsInvalidPixels) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  fill_frame(0, 0.0F, frame);
  for (int i = 0; i < 17; ++i) frame.depth.pixels[static_cast<size_t>(i * 7)] = 0;
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.invalid_pixels, 17U);
}

TEST(Pipeline, CopiesTruthAndClearsItAgain) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  fill_frame(0, 0.0F, frame);
  frame.truth.emplace();
  frame.truth->contact.valid = true;
  frame.truth->contact.distance_m = 1.25F;
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  ASSERT_TRUE(result.truth.has_value());
  EXPECT_EQ(result.truth->distance_m, 1.25F);
  frame.truth.reset();
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_FALSE(result.truth.has_value());
}

TEST(Pipeline, PresetBackgroundSkipsLearning) {
  // Learn in one pipeline, hand the model to another: its first frame is already valid.
  const BackgroundModel background = learn_empty_background();
  Frame frame;
  FrameResult result;
  PipelineParams params = fake_params();
  params.background.check_frames = 0;  // trusted at once (the check has tests of its own)
  Pipeline pipeline(params);
  EXPECT_FALSE(pipeline.background_ready());
  pipeline.set_background(background);
  EXPECT_TRUE(pipeline.background_ready());
  fill_frame(0, 0.3F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_TRUE(result.valid);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_NEAR(result.contact.distance_m, expected_distance_m(0.3), 1e-4);
}

// No robot to measure against must not read as "nothing near the robot".
TEST(Pipeline, EmptyRobotModelIsStop) {
  const BackgroundModel background = learn_empty_background();
  Frame frame;
  FrameResult result;
  PipelineParams params = fake_params();
  params.robot.points.capsules.clear();
  params.background.check_frames = 0;
  Pipeline pipeline(params);
  pipeline.set_background(background);
  fill_frame(0, 0.0F, frame);  // an empty cell: without the rule this would be run
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_FALSE(result.valid);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.reason, "no robot model");
}

TEST(Pipeline, BackgroundOfAnotherSizeIsStop) {
  Pipeline pipeline(fake_params());
  BackgroundModel model;
  model.width = 8;
  model.height = 6;
  model.mean_m.assign(48, 2.0F);
  model.spread_m.assign(48, 0.0F);
  model.valid_ratio.assign(48, 1.0F);
  pipeline.set_background(model);
  Frame frame;
  FrameResult result;
  fill_frame(0, 0.5F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_FALSE(result.valid);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_FALSE(result.verdict.reason.empty());
}

TEST(Pipeline, MovingSceneRestartsLearningWithTheLearnersMessage) {
  Pipeline pipeline(fake_params());
  Frame frame;
  FrameResult result;
  // The object appears during the first batch: the learner must refuse it.
  const float batch[] = {0.0F, 1.0F, 0.0F};
  for (int i = 0; i < 3; ++i) {
    fill_frame(i, batch[i], frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  }
  EXPECT_FALSE(pipeline.background_ready());
  ASSERT_FALSE(pipeline.background_message().empty());
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_NE(result.verdict.reason.find(pipeline.background_message()), std::string::npos);
  EXPECT_EQ(result.verdict.reason.rfind("learning background", 0), 0U);
}

}  // namespace
}  // namespace hrcsense
