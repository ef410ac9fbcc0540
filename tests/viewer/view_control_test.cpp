// SPDX-License-Identifier: Apache-2.0
// The panels' requests to the running pipeline: relearning is refused while the robot moves
// or anything is near it, and nothing reaches the pipeline but between frames.

#include "../support/decide.hpp"
#include "viewer/view_control.hpp"

#include <gtest/gtest.h>

#include "hrcsense/io/io.hpp"

#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace hrcsense::view {
namespace {

// A 20×10 wall at 2 m, optionally with a 6×4 px block at `object_m`, seen by a camera at the
// robot base (identity pose); the robot a point at the origin (slow 1 m, stop 0.5 m).
void wall_frame(int64_t index, float object_m, Frame& out) {
  out.index = index;
  out.timestamp_ns = index * 33'333'333;
  out.intrinsics.width = 20;
  out.intrinsics.height = 10;
  out.intrinsics.fx = out.intrinsics.fy = 20.0F;
  out.intrinsics.ppx = 9.5F;
  out.intrinsics.ppy = 4.5F;
  out.stereo_baseline_mm = 50.0F;
  out.depth.resize(20, 10);
  for (int v = 0; v < 10; ++v) {
    for (int u = 0; u < 20; ++u) {
      const bool in_object = object_m > 0.0F && u >= 7 && u < 13 && v >= 3 && v < 7;
      out.depth.pixels[static_cast<size_t>(v) * 20 + u] =
          static_cast<uint16_t>(in_object ? object_m * 1000.0F : 2000.0F);
    }
  }
}

PipelineParams point_robot_params() {
  PipelineParams params;
  params.background.frames = 2;
  params.robot.points.capsules.push_back(Capsule{});
  params.safety.slow_distance_m = 1.0F;
  params.safety.stop_distance_m = 0.5F;
  params.foreground.min_object_mm = 0.0F;
  return params;
}

// The safety distances of point_robot_params(): slow 1 m, stop 0.5 m.
SafetyParams test_safety() { return point_robot_params().safety; }

// A measurement as the processing thread has it before each frame: not decided (the verdict
// is the default stop), still robot, nothing in the cell.
FrameResult still_and_clear() {
  FrameResult result;
  result.frame = 7;
  result.valid = true;
  result.robot_state = fixed_robot_state({});
  return result;
}

TEST(RelearnRefusal, AllowedWhenStillAndClear) { EXPECT_EQ(relearn_refusal(still_and_clear(), test_safety()), ""); }

TEST(RelearnRefusal, RefusedWhileTheRobotMoves) {
  FrameResult result = still_and_clear();
  result.robot_state.qd_rad_s[2] = 0.05F;
  const std::string why = relearn_refusal(result, test_safety());
  EXPECT_NE(why.find("moving"), std::string::npos) << why;
  EXPECT_NE(why.find("joint 3"), std::string::npos) << why;
  result.robot_state.qd_rad_s[2] = -0.05F;  // either direction
  EXPECT_NE(relearn_refusal(result, test_safety()), "");
  result.robot_state.qd_rad_s[2] = std::nanf("");  // unknown speed is no proof of standing still
  EXPECT_NE(relearn_refusal(result, test_safety()), "");
  result.robot_state.qd_rad_s[2] = 0.0005F;  // below kRobotMovingRadS: still
  EXPECT_EQ(relearn_refusal(result, test_safety()), "");
}

TEST(RelearnRefusal, RefusedWhileAnythingIsNear) {
  struct Near {
    float distance_m;
    bool inside;
    const char* code;
  };
  for (const Near& near : {Near{0.42F, false, "in_stop_zone"}, Near{0.8F, false, "in_slow_zone"},
                           Near{0.0F, true, "inside_robot"}}) {
    FrameResult result = still_and_clear();
    result.contact.valid = true;
    result.contact.distance_m = near.distance_m;
    result.contact.inside = near.inside;
    result.foreground_points = 12;
    const std::string why = relearn_refusal(result, test_safety());
    char distance[16];
    std::snprintf(distance, sizeof distance, "%.2f m", static_cast<double>(near.distance_m));
    EXPECT_NE(why.find(distance), std::string::npos) << why;
    EXPECT_NE(why.find(near.code), std::string::npos) << why;
  }
}

TEST(RelearnRefusal, JudgedOnTheMeasurementNotAnUndecidedVerdict) {
  // On the processing thread `previous` is not decided: whatever its verdict field holds (a
  // reused buffer's old verdict) must not let a relearn through while someone is near.
  FrameResult near = still_and_clear();
  near.contact.valid = true;
  near.contact.distance_m = 0.7F;
  near.foreground_points = 12;
  near.verdict.state = VerdictState::run;
  near.verdict.code = ReasonCode::clear;
  EXPECT_NE(relearn_refusal(near, test_safety()), "");
  FrameResult far = near;
  far.contact.distance_m = 1.5F;
  far.verdict.state = VerdictState::slow;
  far.verdict.code = ReasonCode::in_slow_zone;
  EXPECT_EQ(relearn_refusal(far, test_safety()), "");
}

TEST(RelearnRefusal, RefusedWithoutARobotState) {
  FrameResult result = still_and_clear();
  result.robot_state.valid = false;
  EXPECT_NE(relearn_refusal(result, test_safety()), "");
  EXPECT_NE(relearn_refusal(FrameResult{}, test_safety()), "");  // before the first frame
}

TEST(ControlInbox, NothingPostedLeavesThePipelineAlone) {
  Pipeline pipeline(point_robot_params());
  ControlInbox inbox(point_robot_params());
  inbox.apply(pipeline, still_and_clear());
  EXPECT_TRUE(inbox.take_events().empty());
  EXPECT_EQ(pipeline.params().foreground.k_sigma, ForegroundParams{}.k_sigma);
}

TEST(ControlInbox, LatestTuningWinsAndIsAppliedOnce) {
  Pipeline pipeline(point_robot_params());
  ControlInbox inbox(point_robot_params());
  LiveTuning tuning = pipeline.tuning();
  tuning.foreground.k_sigma = 2.0F;
  inbox.post_tuning(tuning);
  tuning.foreground.k_sigma = 3.0F;
  inbox.post_tuning(tuning);
  EXPECT_EQ(pipeline.params().foreground.k_sigma, ForegroundParams{}.k_sigma);  // not before apply()
  inbox.apply(pipeline, still_and_clear());
  EXPECT_EQ(pipeline.params().foreground.k_sigma, 3.0F);
  const std::vector<ControlEvent> events = inbox.take_events();
  ASSERT_EQ(events.size(), 1U);
  EXPECT_FALSE(events[0].refused);
  EXPECT_EQ(events[0].after_frame, 7);
  inbox.apply(pipeline, still_and_clear());
  EXPECT_TRUE(inbox.take_events().empty());
}

TEST(ControlInbox, RefusedTuningIsReportedAndChangesNothing) {
  Pipeline pipeline(point_robot_params());
  ControlInbox inbox(point_robot_params());
  LiveTuning tuning = pipeline.tuning();
  tuning.filters.order.push_back(FilterBlock::temporal);  // the order is fixed while the cell runs
  tuning.backend = ProximityBackend::octree;
  inbox.post_tuning(tuning);
  inbox.apply(pipeline, still_and_clear());
  const std::vector<ControlEvent> events = inbox.take_events();
  ASSERT_EQ(events.size(), 1U);
  EXPECT_TRUE(events[0].refused);
  EXPECT_EQ(pipeline.params().backend, ProximityBackend::brute);
}

// safety.mode ssm: a tuning that makes the foreground less sensitive than the configuration the
// run started with is refused with its reason, and the pipeline keeps its tuning; the bound is
// that configuration, not the last tuning applied.
TEST(ControlInbox, SsmTuningLessSensitiveThanConfiguredIsRefusedWithTheReason) {
  PipelineParams params = point_robot_params();
  params.safety.mode = SafetyParams::Mode::ssm;
  params.foreground.k_sigma = 3.0F;
  Pipeline pipeline(params);
  ControlInbox inbox(params);

  LiveTuning lower = pipeline.tuning();
  lower.foreground.k_sigma = 2.0F;  // more sensitive: taken
  inbox.post_tuning(lower);
  inbox.apply(pipeline, still_and_clear());
  std::vector<ControlEvent> events = inbox.take_events();
  ASSERT_EQ(events.size(), 1U);
  EXPECT_FALSE(events[0].refused) << events[0].text;
  ASSERT_EQ(pipeline.tuning().foreground.k_sigma, 2.0F);

  LiveTuning higher = pipeline.tuning();
  higher.foreground.k_sigma = 5.0F;
  higher.foreground.min_margin_m = 0.01F;  // allowed, but the tuning is refused as a whole
  higher.backend = ProximityBackend::octree;
  inbox.post_tuning(higher);
  inbox.apply(pipeline, still_and_clear());
  events = inbox.take_events();
  ASSERT_EQ(events.size(), 1U);
  EXPECT_TRUE(events[0].refused);
  EXPECT_EQ(events[0].after_frame, 7);
  EXPECT_NE(events[0].text.find("foreground.k_sigma 5 refused in ssm mode: above the configured 3"), std::string::npos)
      << events[0].text;
  const LiveTuning kept = pipeline.tuning();
  EXPECT_EQ(kept.foreground.k_sigma, 2.0F);
  EXPECT_EQ(kept.foreground.min_margin_m, params.foreground.min_margin_m);
  EXPECT_EQ(kept.foreground.min_object_mm, params.foreground.min_object_mm);
  EXPECT_EQ(kept.backend, ProximityBackend::brute);

  LiveTuning back = pipeline.tuning();
  back.foreground.k_sigma = 3.0F;  // back up to the configured value: taken
  inbox.post_tuning(back);
  inbox.apply(pipeline, still_and_clear());
  events = inbox.take_events();
  ASSERT_EQ(events.size(), 1U);
  EXPECT_FALSE(events[0].refused) << events[0].text;
  EXPECT_EQ(pipeline.tuning().foreground.k_sigma, 3.0F);
}

TEST(ControlInbox, RelearnRefusedNearTheRobotThenDoneWhenClear) {
  Pipeline pipeline(point_robot_params());
  Frame frame;
  FrameResult result;
  for (int i = 0; i < 2; ++i) {
    wall_frame(i, 0.0F, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  }
  ASSERT_TRUE(pipeline.background_ready());
  wall_frame(2, 0.7F, frame);  // a block 0.7 m from the robot point: slow
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  ASSERT_EQ(result.verdict.code, ReasonCode::in_slow_zone);

  ControlInbox inbox(point_robot_params());
  inbox.post_relearn();
  inbox.apply(pipeline, result);
  std::vector<ControlEvent> events = inbox.take_events();
  ASSERT_EQ(events.size(), 1U);
  EXPECT_TRUE(events[0].refused);
  EXPECT_TRUE(pipeline.background_ready());  // still the old background
  // The request is not kept for later: a refused relearn must be asked for again.
  wall_frame(3, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  ASSERT_EQ(result.verdict.state, VerdictState::run);
  inbox.apply(pipeline, result);
  EXPECT_TRUE(inbox.take_events().empty());
  EXPECT_TRUE(pipeline.background_ready());

  inbox.post_relearn();
  inbox.apply(pipeline, result);
  events = inbox.take_events();
  ASSERT_EQ(events.size(), 1U);
  EXPECT_FALSE(events[0].refused);
  EXPECT_FALSE(pipeline.background_ready());
  wall_frame(4, 0.0F, frame);
  test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  EXPECT_EQ(result.verdict.code, ReasonCode::learning_background);
}

TEST(SaveTuned, TheSavedFileRunsAsTheTunedCellWithTheRunsOverrides) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("hrcsense_view_save_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string saved = (dir / "tuned.yaml").string();
  // The run's --set stays in what is saved; the tuning comes on top of it.
  const std::vector<std::string> sets = {"safety.slow_distance_m=1.4", "filters.preset=thesis"};
  LiveTuning tuning = tuning_of(load_config("", sets).pipeline);
  tuning.foreground.k_sigma = 5.5F;
  tuning.backend = ProximityBackend::octree;
  const Config tuned = tuned_config("", sets, tuning);
  save_tuned_config(tuned, saved);
  const Config reloaded = load_config(saved, {});
  EXPECT_EQ(reloaded.pipeline.foreground.k_sigma, 5.5F);
  EXPECT_EQ(reloaded.pipeline.backend, ProximityBackend::octree);
  EXPECT_EQ(reloaded.pipeline.safety.slow_distance_m, 1.4F);
  EXPECT_EQ(reloaded.filters_preset, FilterPreset::thesis);
  EXPECT_EQ(config_hash(reloaded), config_hash(tuned));
  EXPECT_THROW(save_tuned_config(tuned, (dir / "no_such_dir" / "x.yaml").string()), IoError);
  std::filesystem::remove_all(dir);
}

TEST(SaveTuned, AValueTheParserRefusesIsAConfigErrorNamingTheKey) {
  LiveTuning tuning = tuning_of(load_config("", {}).pipeline);
  tuning.filters.order = {FilterBlock::threshold, FilterBlock::spatial};
  tuning.filters.threshold.min_m = 3.0F;  // min above max
  tuning.filters.threshold.max_m = 1.0F;
  try {
    (void)tuned_config("", {"filters.order=[threshold, spatial]"}, tuning);
    ADD_FAILURE() << "no ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("filters.threshold"), std::string::npos) << e.what();
  }
}

// --snapshot-at: indices sorted and once each; anything else is refused, naming the item.
TEST(ParseFrameList, SortedUniqueIndicesAndNamedRefusals) {
  EXPECT_EQ(parse_frame_list("198,123,,198"), (std::set<int64_t>{123, 198}));
  EXPECT_EQ(parse_frame_list("0"), (std::set<int64_t>{0}));
  EXPECT_EQ(parse_frame_list("123, 198"), (std::set<int64_t>{123, 198}));  // a space after the comma
  for (const char* bad : {"12a", "-1", "1.5", "7 "}) {
    try {
      (void)parse_frame_list(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW((void)parse_frame_list(""), ConfigError);
  EXPECT_THROW((void)parse_frame_list(",,"), ConfigError);
}

}  // namespace
}  // namespace hrcsense::view
