// SPDX-License-Identifier: Apache-2.0
// The viewer's CPU side without a display: the colour map and its equalisation against hand
// values, the robot's pixels against hand-solved ray-capsule geometry, the markers at their
// pinhole projections, the shown state (NO DATA) on injected times, the layout rule, and the
// view tap (each picture published with its own decided verdict, drops counted, snapshot
// frames waited for).
#include "../support/scenes.hpp"
#include "viewer/view_model.hpp"
#include "viewer/view_tap.hpp"

#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>

namespace hrcsense::view {
namespace {

Rgb rgb_at(const ColorImage& image, int u, int v) {
  const size_t i = 3 * (static_cast<size_t>(v) * image.width + u);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

// A 200×100 pinhole camera, focal 100 px, principal point (100, 50).
Intrinsics test_camera() {
  Intrinsics in;
  in.width = 200;
  in.height = 100;
  in.fx = 100.0F;
  in.fy = 100.0F;
  in.ppx = 100.0F;
  in.ppy = 50.0F;
  return in;
}

TEST(Jet, HandValuesAtTheStopsAndBetween) {
  EXPECT_EQ(jet(0.0F), (Rgb{0, 0, 255}));
  EXPECT_EQ(jet(0.25F), (Rgb{0, 255, 255}));
  EXPECT_EQ(jet(0.5F), (Rgb{255, 255, 0}));
  EXPECT_EQ(jet(0.75F), (Rgb{255, 0, 0}));
  EXPECT_EQ(jet(1.0F), (Rgb{50, 0, 0}));
  EXPECT_EQ(jet(0.125F), (Rgb{0, 128, 255}));  // 127.5 rounds up
  EXPECT_EQ(jet(0.375F), (Rgb{128, 255, 128}));
  EXPECT_EQ(jet(0.875F), (Rgb{153, 0, 0}));    // (255 + 50) / 2 = 152.5
  EXPECT_EQ(jet(-3.0F), jet(0.0F));
  EXPECT_EQ(jet(7.0F), jet(1.0F));
  EXPECT_EQ(jet(std::nanf("")), jet(0.0F));
}

TEST(Jet, NoMarkerColourIsAJetColour) {
  for (int i = 0; i <= 100000; ++i) {
    const Rgb c = jet(static_cast<float>(i) / 100000.0F);
    EXPECT_NE(c, kContactMarker);
    EXPECT_NE(c, kRobotMarker);
    EXPECT_NE(c, kRobotOutline);
    EXPECT_NE(c, kContactLine);
  }
}

TEST(Equalise, ShareOfValidPixelsAtOrBelow) {
  DepthImage depth;
  depth.resize(4, 1);
  depth.pixels = {0, 1000, 1000, 3000};
  std::vector<uint32_t> histogram;
  std::vector<float> t;
  equalise_depth(depth, histogram, t);
  ASSERT_EQ(t.size(), 4U);
  EXPECT_FLOAT_EQ(t[0], -1.0F);
  EXPECT_FLOAT_EQ(t[1], 2.0F / 3.0F);
  EXPECT_FLOAT_EQ(t[2], 2.0F / 3.0F);
  EXPECT_FLOAT_EQ(t[3], 1.0F);

  ColorImage rgb;
  std::vector<uint32_t> lut;
  colorize_depth(depth, histogram, lut, rgb);
  EXPECT_EQ(rgb_at(rgb, 0, 0), (Rgb{0, 0, 0}));     // invalid: black
  EXPECT_EQ(rgb_at(rgb, 3, 0), (Rgb{50, 0, 0}));    // the farthest: the map's end
  // 2/3 of the way: between (255, 255, 0) at 1/2 and (255, 0, 0) at 3/4, f = 2/3 → g = 85.
  EXPECT_EQ(rgb_at(rgb, 1, 0), (Rgb{255, 85, 0}));
}

TEST(RobotMask, HandSolvedCapsuleSilhouette) {
  // A horizontal capsule 2 m ahead: axis from x = -0.5 to 0.5, radius 0.1 m.
  ViewCamera camera{test_camera(), Extrinsics{}};
  const std::vector<Capsule> capsules{{Eigen::Vector3f(-0.5F, 0.0F, 2.0F), Eigen::Vector3f(0.5F, 0.0F, 2.0F), 0.1F, 1}};
  std::vector<uint8_t> mask;
  robot_mask(capsules, Pose::Identity(), camera, mask);
  auto at = [&](int u, int v) { return mask[static_cast<size_t>(v) * 200 + u]; };
  // Column u = 100: the ray (0, s, 1) passes 2|s| / sqrt(1 + s²) from the axis: inside for
  // |s| ≤ 0.05006, i.e. |v - 50| ≤ 5 at 100 px focal length.
  for (int v = 45; v <= 55; ++v) EXPECT_EQ(at(100, v), 1) << "v " << v;
  EXPECT_EQ(at(100, 44), 0);
  EXPECT_EQ(at(100, 56), 0);
  // Row v = 50, the end cap at x = 0.5: the ray (t, 0, 1) is inside while
  // (2t - 0.5) ≤ 0.1·sqrt(1 + t²): t = 0.30 inside (0.100 ≤ 0.1044), t = 0.31 outside.
  EXPECT_EQ(at(130, 50), 1);
  EXPECT_EQ(at(131, 50), 0);
  EXPECT_EQ(at(70, 50), 1);
  EXPECT_EQ(at(69, 50), 0);
  EXPECT_EQ(at(10, 10), 0);
}

TEST(RobotMask, FollowsTheCameraPoseAndIgnoresWhatIsBehind) {
  ViewCamera camera{test_camera(), Extrinsics{}};
  // The base frame 1 m to the camera's right (T_camera_base translates x by +1): a capsule at
  // base x = -1 lands on the optical axis.
  Pose T_camera_base = Pose::Identity();
  T_camera_base.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  const std::vector<Capsule> ahead{{Eigen::Vector3f(-1.0F, -0.2F, 2.0F), Eigen::Vector3f(-1.0F, 0.2F, 2.0F), 0.05F, 0}};
  std::vector<uint8_t> mask;
  robot_mask(ahead, T_camera_base, camera, mask);
  EXPECT_EQ(mask[50 * 200 + 100], 1);
  EXPECT_EQ(mask[50 * 200 + 110], 0);  // 10 px: 0.2 m off the axis at 2 m, the radius 0.05 m
  const std::vector<Capsule> behind{{Eigen::Vector3f(0.0F, 0.0F, -2.0F), Eigen::Vector3f(0.1F, 0.0F, -2.0F), 0.2F, 0}};
  robot_mask(behind, Pose::Identity(), camera, mask);
  for (uint8_t m : mask) ASSERT_EQ(m, 0);
}

ViewFrame depth_only_frame() {
  ViewFrame frame;
  frame.frame = 7;
  frame.depth_intrinsics = test_camera();
  frame.depth.resize(200, 100);
  std::fill(frame.depth.pixels.begin(), frame.depth.pixels.end(), uint16_t{2000});
  for (int v = 0; v < 10; ++v) {
    for (int u = 0; u < 10; ++u) frame.depth.pixels[static_cast<size_t>(v) * 200 + u] = 0;  // a hole, top left
  }
  frame.valid = true;
  return frame;
}

TEST(Compose, MarkersLandOnThePinholeProjections) {
  ViewFrame frame = depth_only_frame();
  frame.contact.valid = true;
  frame.contact.distance_m = 0.3F;
  frame.contact.closest_camera = Eigen::Vector3f(0.4F, 0.2F, 2.0F);      // u = 100 + 20, v = 50 + 10
  frame.contact.closest_robot_base = Eigen::Vector3f(-0.6F, 0.0F, 2.0F); // u = 70, v = 50 (T identity)
  ComposeScratch scratch;
  ColorImage out;
  compose_2d(frame, 0.5F, 3, scratch, out);
  ASSERT_EQ(out.width, 200);
  ASSERT_EQ(out.height, 100);
  EXPECT_EQ(rgb_at(out, 120, 60), kContactMarker);
  EXPECT_EQ(rgb_at(out, 123, 60), kContactMarker);  // the disc's radius, either side
  EXPECT_EQ(rgb_at(out, 117, 60), kContactMarker);
  EXPECT_EQ(rgb_at(out, 120, 57), kContactMarker);
  EXPECT_NE(rgb_at(out, 124, 60), kContactMarker);
  EXPECT_NE(rgb_at(out, 120, 64), kContactMarker);
  EXPECT_EQ(rgb_at(out, 70, 50), kRobotMarker);
  EXPECT_EQ(rgb_at(out, 70, 47), kRobotMarker);
  EXPECT_EQ(rgb_at(out, 95, 55), kContactLine);     // on the line between them, (95, 55) of (70, 50)-(120, 60)
  // Depth only, uniform: every valid pixel the map's end; the hole black.
  EXPECT_EQ(rgb_at(out, 5, 5), (Rgb{0, 0, 0}));
  EXPECT_EQ(rgb_at(out, 180, 90), (Rgb{50, 0, 0}));
}

TEST(Compose, DepthOverColourAndTheRobotOutline) {
  ViewFrame frame = depth_only_frame();
  frame.color.emplace();
  frame.color->width = 200;
  frame.color->height = 100;
  frame.color->rgb.assign(200 * 100 * 3, 0);
  for (size_t i = 0; i < frame.color->rgb.size(); i += 3) {
    frame.color->rgb[i] = 10;
    frame.color->rgb[i + 1] = 20;
    frame.color->rgb[i + 2] = 30;
  }
  frame.color_intrinsics = test_camera();
  frame.depth_to_color = Extrinsics{};  // the same camera: aligned depth = depth
  frame.capsules_base = {{Eigen::Vector3f(-0.5F, 0.0F, 2.0F), Eigen::Vector3f(0.5F, 0.0F, 2.0F), 0.1F, 1}};
  ComposeScratch scratch;
  ColorImage out;
  compose_2d(frame, 0.5F, 3, scratch, out);
  // Half colour (10, 20, 30), half jet(1) = (50, 0, 0): (30, 10, 15).
  EXPECT_EQ(rgb_at(out, 180, 90), (Rgb{30, 10, 15}));
  // The hole: half colour, half black.
  EXPECT_EQ(rgb_at(out, 5, 5), (Rgb{5, 10, 15}));
  // The capsule of RobotMask.HandSolvedCapsuleSilhouette: rows 45..55 at u = 100, its top and
  // bottom rows the outline, the inside brightened halfway to white.
  EXPECT_EQ(rgb_at(out, 100, 45), kRobotOutline);
  EXPECT_EQ(rgb_at(out, 100, 55), kRobotOutline);
  EXPECT_EQ(rgb_at(out, 130, 50), kRobotOutline);
  EXPECT_EQ(rgb_at(out, 100, 50), (Rgb{142, 132, 135}));  // (30 + 255) / 2 ... rounded down
  EXPECT_EQ(rgb_at(out, 100, 44), (Rgb{30, 10, 15}));
}

TEST(ShownState, NoDataWhenNothingOrTooOld) {
  ViewFrame frame;
  EXPECT_EQ(shown_state(frame, 0, 0.5), ShownState::no_data);  // nothing yet
  frame.frame = 3;
  frame.made_ns = 1'000'000'000;
  frame.verdict.state = VerdictState::run;
  EXPECT_EQ(shown_state(frame, 1'400'000'000, 0.5), ShownState::run);
  EXPECT_EQ(shown_state(frame, 1'500'000'000, 0.5), ShownState::run);      // exactly the limit
  EXPECT_EQ(shown_state(frame, 1'500'000'001, 0.5), ShownState::no_data);  // a frozen pipeline
  frame.verdict.state = VerdictState::slow;
  EXPECT_EQ(shown_state(frame, 1'100'000'000, 0.5), ShownState::slow);
  frame.verdict.state = VerdictState::stop;
  EXPECT_EQ(shown_state(frame, 1'100'000'000, 0.5), ShownState::stop);
  EXPECT_EQ(shown_state(frame, 1'100'000'000, std::nan("")), ShownState::no_data);
  EXPECT_NE(state_color(ShownState::no_data), kRunColor);
  EXPECT_STREQ(state_word(ShownState::no_data), "NO DATA");
  EXPECT_STREQ(state_word(ShownState::slow), "SLOW");
}

TEST(Layout, PaneAndFit) {
  const Rect pane = pane_area(1280, 720, 12, 150);
  EXPECT_EQ(pane.x, 12);
  EXPECT_EQ(pane.y, 12);
  EXPECT_EQ(pane.width, 1256);
  EXPECT_EQ(pane.height, 546);
  // 848×480 into 1256×546: height-bound, 546·848/480 = 964.6 → 964 wide, centred.
  const Rect fit = fit_rect(848, 480, pane);
  EXPECT_EQ(fit.width, 964);
  EXPECT_EQ(fit.height, 546);
  EXPECT_EQ(fit.x, 12 + (1256 - 964) / 2);
  EXPECT_EQ(fit.y, 12);
  // Width-bound: 400×100 into 1256×546 → 1256×314, centred vertically.
  const Rect wide = fit_rect(400, 100, pane);
  EXPECT_EQ(wide.width, 1256);
  EXPECT_EQ(wide.height, 314);
  EXPECT_EQ(wide.y, 12 + (546 - 314) / 2);
}

TimelinePoint point_at(double made_s, double source_s, double latency_us) {
  TimelinePoint p;
  p.made_ns = static_cast<int64_t>(made_s * 1e9);
  p.timestamp_ns = static_cast<int64_t>(source_s * 1e9);
  p.latency_us = latency_us;
  return p;
}

TEST(Timeline, KeepsTheLastSecondsOnly) {
  Timeline timeline(2.0, 100);
  for (int i = 0; i <= 40; ++i) timeline.add(point_at(0.1 * i, 0.1 * i, 1.0));  // 0 .. 4 s
  // Made within 2 s of the newest (4.0 s): 2.0 .. 4.0 s, 21 points (2.0 s itself is at the edge,
  // kept unless rounding of 0.1·i puts it just beyond).
  ASSERT_GE(timeline.points().size(), 20U);
  ASSERT_LE(timeline.points().size(), 21U);
  EXPECT_NEAR(static_cast<double>(timeline.points().back().made_ns) * 1e-9, 4.0, 1e-9);
  EXPECT_GE(timeline.points().front().made_ns, static_cast<int64_t>(1.999e9));
  Timeline bounded(100.0, 5);
  for (int i = 0; i < 12; ++i) bounded.add(point_at(0.01 * i, 0.01 * i, 1.0));
  EXPECT_EQ(bounded.points().size(), 5U);
}

TEST(Timeline, RatesAndLatencyPercentiles) {
  // 11 frames 1/30 s apart in source time, processed 1/60 s apart; latencies 100..1100 us.
  std::vector<TimelinePoint> points;
  for (int i = 0; i <= 10; ++i) points.push_back(point_at(i / 60.0, i / 30.0, 100.0 * (i + 1)));
  const RateStats stats = rate_stats(points);
  EXPECT_NEAR(stats.capture_fps, 30.0, 1e-6);
  EXPECT_NEAR(stats.processing_fps, 60.0, 1e-6);
  EXPECT_DOUBLE_EQ(stats.latency_p50_us, 600.0);   // nearest rank: the 6th of 11
  EXPECT_DOUBLE_EQ(stats.latency_p99_us, 1100.0);  // the 11th
  EXPECT_EQ(rate_stats({points.front()}).capture_fps, 0.0);
}

Pipeline walk_pipeline() {
  const Config config = load_config(test::scene_path("walk.yaml"), {});
  return Pipeline(config.pipeline);
}

// A source frame whose depth image is `index + 1` pixels wide, so that a published view shows
// which frame its picture came from.
Frame numbered_frame(int64_t index) {
  Frame frame;
  frame.index = index;
  frame.depth.resize(static_cast<int>(index) + 1, 1);
  return frame;
}

// The measurement of frame `index` as processing hands it over: not decided yet, its verdict
// field whatever the buffer held (here a run that the monitor will not confirm).
FrameResult measured(int64_t index, int64_t delivered_ns = 0) {
  FrameResult result;
  result.frame = index;
  result.timestamp_ns = index * 33'333'333;
  result.delivered_ns = delivered_ns;
  result.verdict.state = VerdictState::run;
  result.verdict.code = ReasonCode::clear;
  return result;
}

// The same result as the SafetyMonitor decided it on the output thread.
FrameResult decided_as(FrameResult result, VerdictState state, ReasonCode code) {
  result.verdict.state = state;
  result.verdict.code = code;
  result.verdict.reason = reason_code_name(code);
  return result;
}

// Processing and output of one frame in step, as in an unpaced run whose output keeps up.
void offer_and_decide(ViewTap& tap, const Pipeline& pipeline, int64_t index,
                      VerdictState state = VerdictState::stop, ReasonCode code = ReasonCode::in_stop_zone) {
  const FrameResult result = measured(index);
  tap.offer(numbered_frame(index), pipeline, result);
  tap.decided(decided_as(result, state, code));
}

TEST(ViewTap, NeverWaitsAndCountsWhatTheRendererMissed) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap;
  for (int64_t i = 0; i < 5; ++i) offer_and_decide(tap, pipeline, i);  // nobody takes: each replaces the last
  EXPECT_EQ(tap.dropped(), 4);
  ViewFrame newest;
  ASSERT_TRUE(tap.take(newest, 1.0));
  EXPECT_EQ(newest.frame, 4);
  EXPECT_EQ(newest.depth.width, 5);
  EXPECT_FALSE(tap.take(newest, 0.0));
}

TEST(ViewTap, ShowsTheVerdictTheMonitorDecidedNotTheMeasurementsField) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap;
  // Its verdict field says run; the monitor decides slow (neither that nor a ViewFrame's
  // default stop).
  const FrameResult result = measured(3);
  tap.offer(numbered_frame(3), pipeline, result);
  ViewFrame shown;
  EXPECT_FALSE(tap.take(shown, 0.0));  // nothing is published before its verdict is decided
  tap.decided(decided_as(result, VerdictState::slow, ReasonCode::in_slow_zone));
  ASSERT_TRUE(tap.take(shown, 1.0));
  EXPECT_EQ(shown.frame, 3);
  EXPECT_EQ(shown.depth.width, 4);
  EXPECT_EQ(shown.verdict.state, VerdictState::slow);
  EXPECT_EQ(shown.verdict.code, ReasonCode::in_slow_zone);
  EXPECT_EQ(shown.verdict.reason, "in_slow_zone");
  EXPECT_EQ(shown_state(shown, shown.made_ns, 0.5), ShownState::slow);  // the border: amber, not green
  std::vector<TimelinePoint> timeline;
  tap.timeline(timeline);
  ASSERT_EQ(timeline.size(), 1U);
  EXPECT_EQ(timeline[0].state, VerdictState::slow);
  EXPECT_EQ(timeline[0].made_ns, shown.made_ns);
}

TEST(ViewTap, ProcessingAheadOfTheOutputPairsEachPictureWithItsOwnVerdict) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap;
  // Unpaced: processing offers up to 3 frames before the output decides the first.
  const VerdictState states[] = {VerdictState::run, VerdictState::slow, VerdictState::stop};
  for (int64_t i = 0; i < 3; ++i) tap.offer(numbered_frame(i), pipeline, measured(i));
  for (int64_t i = 0; i < 3; ++i) {
    tap.decided(decided_as(measured(i), states[i], ReasonCode::holding));
    ViewFrame shown;
    ASSERT_TRUE(tap.take(shown, 1.0));
    EXPECT_EQ(shown.frame, i);
    EXPECT_EQ(shown.depth.width, i + 1);
    EXPECT_EQ(shown.verdict.state, states[i]);
  }
  EXPECT_EQ(tap.dropped(), 0);
}

TEST(ViewTap, ADecidedFrameWhoseViewWasReplacedPublishesNothing) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap;
  // Processing runs 6 frames ahead (a paced run with a slow output): frames 0 and 1's views
  // are forgotten, the ring keeping the newest ViewTap::kPendingFrames.
  static_assert(ViewTap::kPendingFrames == 4);
  for (int64_t i = 0; i < 6; ++i) tap.offer(numbered_frame(i), pipeline, measured(i));
  tap.decided(decided_as(measured(1), VerdictState::stop, ReasonCode::in_stop_zone));
  ViewFrame shown;
  EXPECT_FALSE(tap.take(shown, 0.0));  // no picture rather than frame 2's with frame 1's stop
  EXPECT_EQ(shown.frame, -1);
  EXPECT_EQ(tap.dropped(), 1);  // decided, never drawn
  // Frame 3 (2 was dropped by the pipeline undecided) still finds its own picture.
  tap.decided(decided_as(measured(3), VerdictState::slow, ReasonCode::in_slow_zone));
  ASSERT_TRUE(tap.take(shown, 1.0));
  EXPECT_EQ(shown.frame, 3);
  EXPECT_EQ(shown.depth.width, 4);
  EXPECT_EQ(shown.verdict.state, VerdictState::slow);
  EXPECT_EQ(tap.index_gaps(), 1);  // frame 2 never written
  // Frame 2's view, offered before 3's, was forgotten with the decision of 3: a late result of
  // frame 2 cannot pair with anything.
  tap.decided(decided_as(measured(2), VerdictState::run, ReasonCode::clear));
  EXPECT_FALSE(tap.take(shown, 0.0));
  EXPECT_EQ(shown.frame, 3);
  EXPECT_EQ(shown.verdict.state, VerdictState::slow);
}

TEST(ViewTap, AFrameIndexSeenAgainAfterASeekBackPairsByItsDelivery) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap;
  Frame first = numbered_frame(5);
  Frame again = numbered_frame(5);
  again.depth.resize(9, 1);  // another picture of the same index
  tap.offer(first, pipeline, measured(5, 1'000));
  tap.offer(again, pipeline, measured(5, 2'000));
  tap.decided(decided_as(measured(5, 2'000), VerdictState::slow, ReasonCode::in_slow_zone));
  ViewFrame shown;
  ASSERT_TRUE(tap.take(shown, 1.0));
  EXPECT_EQ(shown.depth.width, 9);
  EXPECT_EQ(shown.verdict.state, VerdictState::slow);
}

TEST(ViewTap, AStopForNoSourceFrameTakesThePlaceOfTheShownVerdict) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap;
  offer_and_decide(tap, pipeline, 7, VerdictState::run, ReasonCode::clear);
  ViewFrame shown;
  ASSERT_TRUE(tap.take(shown, 1.0));
  ASSERT_EQ(shown.verdict.state, VerdictState::run);
  const int64_t made_ns = shown.made_ns;
  // The watchdog's stop repeats frame 7's index and stands for no source frame.
  FrameResult watchdog = decided_as(measured(7), VerdictState::stop, ReasonCode::no_frame);
  watchdog.source_frame = false;
  tap.decided(watchdog);
  EXPECT_FALSE(tap.take(shown, 0.0));  // no new picture...
  EXPECT_EQ(shown.frame, 7);
  EXPECT_EQ(shown.verdict.state, VerdictState::stop);  // ...but the stop is shown
  EXPECT_EQ(shown.verdict.code, ReasonCode::no_frame);
  EXPECT_EQ(shown.made_ns, made_ns);  // the data's age, so NO DATA once it is old
  EXPECT_EQ(shown_state(shown, made_ns + 100'000'000, 0.5), ShownState::stop);
  EXPECT_EQ(shown_state(shown, made_ns + 600'000'000, 0.5), ShownState::no_data);
  std::vector<TimelinePoint> timeline;
  tap.timeline(timeline);
  EXPECT_EQ(timeline.size(), 1U);  // no point for a result without a frame
  // The next frame's own verdict replaces it.
  offer_and_decide(tap, pipeline, 8, VerdictState::run, ReasonCode::clear);
  ASSERT_TRUE(tap.take(shown, 1.0));
  EXPECT_EQ(shown.verdict.state, VerdictState::run);
  EXPECT_FALSE(tap.take(shown, 0.0));
  EXPECT_EQ(shown.verdict.state, VerdictState::run);
}

TEST(ViewTap, CountsTheSourceFramesTheOutputNeverWrote) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap;
  // Written: 0, 1, 4, 5, 9 (2, 3, 6, 7, 8 dropped), then 2 after a seek back: no gap.
  for (const int64_t i : {0, 1, 4, 5, 9, 2, 3}) offer_and_decide(tap, pipeline, i);
  EXPECT_EQ(tap.index_gaps(), 5);
}

TEST(ViewTap, WaitsAtASnapshotFrameUntilDrawn) {
  const Pipeline pipeline = walk_pipeline();
  ViewTap tap({3});
  std::atomic<bool> passed{false};
  std::thread run([&] {
    for (int64_t i = 0; i < 5; ++i) {
      offer_and_decide(tap, pipeline, i);  // the output thread waits in decided()
      if (i == 3) passed.store(true);
    }
  });
  // Frame 3 reaches the mailbox, decided, and the output waits there.
  ViewFrame taken;
  for (int i = 0; i < 500 && !(tap.take(taken, 0.01) && taken.frame == 3); ++i) {
  }
  ASSERT_EQ(taken.frame, 3);
  EXPECT_EQ(taken.verdict.state, VerdictState::stop);
  EXPECT_FALSE(passed.load());
  EXPECT_EQ(tap.snapshots_pending(), 1U);
  tap.rendered(3);
  run.join();
  EXPECT_TRUE(passed.load());
  EXPECT_EQ(tap.snapshots_pending(), 0U);
}

}  // namespace
}  // namespace hrcsense::view

namespace hrcsense::view {
namespace {

TEST(PaneRects, OnePaneTakesAllAndSplitHalvesWithAGap) {
  const Rect pane{12, 12, 1256, 546};
  const PaneRects only_2d = pane_rects(PaneMode::view_2d, pane, 8);
  EXPECT_EQ(only_2d.image_2d.width, 1256);
  EXPECT_EQ(only_2d.cloud_3d.width, 0);
  const PaneRects only_3d = pane_rects(PaneMode::view_3d, pane, 8);
  EXPECT_EQ(only_3d.image_2d.width, 0);
  EXPECT_EQ(only_3d.cloud_3d.x, 12);
  EXPECT_EQ(only_3d.cloud_3d.width, 1256);
  // 1256 − 8 = 1248: 624 each, the 3D pane starting at 12 + 624 + 8.
  const PaneRects split = pane_rects(PaneMode::split, pane, 8);
  EXPECT_EQ(split.image_2d.x, 12);
  EXPECT_EQ(split.image_2d.width, 624);
  EXPECT_EQ(split.cloud_3d.x, 644);
  EXPECT_EQ(split.cloud_3d.width, 624);
  EXPECT_EQ(split.cloud_3d.height, 546);
  // An odd width: the left pane gets the odd pixel; nothing overlaps.
  const PaneRects odd = pane_rects(PaneMode::split, Rect{0, 0, 109, 10}, 8);
  EXPECT_EQ(odd.image_2d.width, 51);
  EXPECT_EQ(odd.cloud_3d.x, 59);
  EXPECT_EQ(odd.cloud_3d.width, 50);
}

TEST(PaneRects, ModeNamesReadBack) {
  for (const PaneMode mode : {PaneMode::view_2d, PaneMode::view_3d, PaneMode::split}) {
    EXPECT_EQ(parse_pane_mode(pane_mode_name(mode)), mode);
  }
  EXPECT_FALSE(parse_pane_mode("4d"));
}

}  // namespace
}  // namespace hrcsense::view
