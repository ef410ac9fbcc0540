// SPDX-License-Identifier: Apache-2.0
// The shared scene clock (docs/SIMULATOR.md, "The shared scene clock"): with an epoch the
// simulated source plays the scene in real time — frame i due at epoch + i / fps on
// CLOCK_REALTIME, joining at the current frame, skipping frames it is late for — and the `sim`
// robot state answers in scene time; without one, nothing changes.
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <thread>

namespace hrcsense {
namespace {

int64_t realtime_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Frame k at 30 frames/s is k · 100/3 ms after the epoch: k · 10^8 / 3 ns, rounded to the
// nearest nanosecond (thirds: .333 rounds down, .667 up).
int64_t thirty_fps_offset_ns(int64_t k) { return (k * 100'000'000 + 1) / 3; }

// A small, noise-free scene: a wall 2 m in front of a 424x240 camera, 30 frames/s.
Simulator wall_scene(int64_t frames) {
  Simulator sim;
  sim.params.width = 424;
  sim.params.height = 240;
  sim.params.fps = 30.0;
  sim.params.frames = frames;
  sim.params.noise = false;
  sim.params.color = false;
  SceneObject wall;
  wall.shapes.push_back(Shape::plane(Eigen::Vector3f(0.0F, 0.0F, 2.0F), Eigen::Vector3f(0.0F, 0.0F, -1.0F)));
  sim.scene.objects.push_back(wall);
  return sim;
}

SimSource scene_source(int64_t epoch_ns, int64_t frames = 100000) {
  Simulator sim = wall_scene(frames);
  sim.params.epoch_ns = epoch_ns;
  return SimSource(std::move(sim));
}

TEST(SimSceneClock, WithoutAnEpochNothingChanges) {
  SimSource source(wall_scene(3));
  EXPECT_FALSE(source.info().live);
  Frame frame;
  const auto start = std::chrono::steady_clock::now();
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.index, 0);
  EXPECT_EQ(frame.timestamp_ns, 0);
  EXPECT_EQ(frame.host_time_ns, 0);  // left to the run
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.index, 1);
  EXPECT_EQ(frame.timestamp_ns, 33'333'333);
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.timestamp_ns, 66'666'667);
  EXPECT_EQ(source.next(frame), Source::Status::end);
  // Unpaced: three frames take far less than their 100 ms of scene time.
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(90));
}

TEST(SimSceneClock, AStartTwoSecondsAfterTheEpochJoinsAtFrameSixty) {
  const int64_t epoch_ns = realtime_ns() - 2'000'000'000;
  SimSource source = scene_source(epoch_ns);
  EXPECT_TRUE(source.info().live);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  const int64_t delivered_ns = realtime_ns();
  const int64_t delivered_steady_ns = steady_ns();
  EXPECT_GE(frame.index, 60);
  EXPECT_LE(frame.index, 61);
  EXPECT_EQ(frame.timestamp_ns, epoch_ns + thirty_fps_offset_ns(frame.index));
  // Delivered once due, and within a period and a render of it.
  EXPECT_GE(delivered_ns, frame.timestamp_ns);
  EXPECT_LT(delivered_ns - frame.timestamp_ns, 80'000'000);
  // The host time is the same instant on the steady clock.
  const int64_t expected_host_ns = delivered_steady_ns - (delivered_ns - frame.timestamp_ns);
  EXPECT_NEAR(static_cast<double>(frame.host_time_ns), static_cast<double>(expected_host_ns), 2e6);
}

TEST(SimSceneClock, FramesFollowEachOtherAtTheScenesRate) {
  const int64_t epoch_ns = realtime_ns() - 500'000'000;
  SimSource source = scene_source(epoch_ns);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  const int64_t first = frame.index;
  const auto start = std::chrono::steady_clock::now();
  for (int64_t k = 1; k <= 3; ++k) {
    ASSERT_EQ(source.next(frame), Source::Status::frame);
    EXPECT_EQ(frame.index, first + k);
    EXPECT_EQ(frame.timestamp_ns, epoch_ns + thirty_fps_offset_ns(first + k));
  }
  // Paced: three more frames take three periods (100 ms), less what the first was late.
  const auto elapsed = std::chrono::steady_clock::now() - start;
  EXPECT_GT(elapsed, std::chrono::milliseconds(60));
  EXPECT_LT(elapsed, std::chrono::milliseconds(250));
  EXPECT_EQ(source.frames_dropped_camera(), 0);
}

TEST(SimSceneClock, ALateReaderSkipsToTheCurrentFrame) {
  const int64_t epoch_ns = realtime_ns() - 1'000'000'000;
  SimSource source = scene_source(epoch_ns);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  const int64_t first = frame.index;
  // 300 ms away: nine periods pass, and the source does not play them back.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  const int64_t after_pause = frame.index;
  EXPECT_GE(after_pause, first + 8);
  EXPECT_LE(after_pause, first + 11);
  EXPECT_EQ(frame.timestamp_ns, epoch_ns + thirty_fps_offset_ns(after_pause));
  EXPECT_LT(realtime_ns() - frame.timestamp_ns, 80'000'000);  // not an old frame
  EXPECT_EQ(source.frames_dropped_camera(), after_pause - first - 1);
  // And on from there one by one.
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.index, after_pause + 1);
}

TEST(SimSceneClock, AnEpochAheadWaitsForFrameZero) {
  const int64_t epoch_ns = realtime_ns() + 100'000'000;
  SimSource source = scene_source(epoch_ns);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.index, 0);
  EXPECT_EQ(frame.timestamp_ns, epoch_ns);
  EXPECT_GE(realtime_ns(), epoch_ns);
  // A scene minutes ahead: the source says idle after a bounded wait, so a stop can end it.
  SimSource later = scene_source(realtime_ns() + 60'000'000'000);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(later.next(frame), Source::Status::idle);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(500));
}

TEST(SimSceneClock, TheSceneEndsAfterItsFrames) {
  // 100 frames at 30 frames/s end 3.3 s after the epoch; 10 s later there is nothing to join.
  SimSource source = scene_source(realtime_ns() - 10'000'000'000, 100);
  Frame frame;
  EXPECT_EQ(source.next(frame), Source::Status::end);
}

TEST(SimSceneClock, TheSimRobotStateAnswersInSceneTime) {
  // Joint 1 goes from 0 to 1 rad in 100 s: at scene time t it is t / 100 rad.
  RobotTrajectory ramp;
  ramp.waypoints.push_back({0.0, {0.0, 0.3, 0.3, 0.3, 0.3, 0.3}});
  ramp.waypoints.push_back({100.0, {1.0, 0.3, 0.3, 0.3, 0.3, 0.3}});
  const int64_t epoch_ns = realtime_ns() - 3'000'000'000;
  SimSource source = scene_source(epoch_ns);
  SimRobotState::Params params;
  params.epoch_ns = epoch_ns;
  SimRobotState states(ramp, params);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  RobotState state;
  ASSERT_TRUE(states.state_at(frame.host_time_ns, state));
  // Frame k is at scene time k / 30 s, so joint 1 is at k / 3000 rad (the clocks' offset, read
  // twice, may move it by a few microseconds: 1e-8 rad).
  EXPECT_NEAR(state.q_rad[0], static_cast<double>(frame.index) / 3000.0, 1e-6);
  EXPECT_NEAR(state.qd_rad_s[0], 0.01, 1e-12);
  // Stamped on the host clock, at the time asked for.
  EXPECT_EQ(state.host_time_ns, frame.host_time_ns);
}

}  // namespace
}  // namespace hrcsense
