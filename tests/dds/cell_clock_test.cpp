// SPDX-License-Identifier: Apache-2.0
// The cell clock (dds/ros2_cell_clock.hpp, docs/MULTICAMERA.md, "The cell clock"): the scene
// clock's epoch read from outside data is checked by hand-computed cases; published once,
// transient-local, it reaches a camera that starts later; a simulated camera of a cell without
// sim.epoch takes it (with_cell_clock) and plays the same scene frames at the same capture times
// as a camera that started before it. Loopback DDS; every wait is bounded.
#include "common/assembly.hpp"
#include "common/fuse_session.hpp"
#include "dds/ros2_cell_clock.hpp"
#include "dds/ros2_messages.hpp"
#include "dds_test_util.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

namespace hrcsense::cell_clock_test {
namespace {

constexpr int64_t kNow = 1'800'000'000'000'000'000;  // 2027-01-15, realtime ns

builtin_interfaces_msg_dds__Time_ time_of(int32_t sec, uint32_t nanosec) {
  builtin_interfaces_msg_dds__Time_ t{};
  t.sec = sec;
  t.nanosec = nanosec;
  return t;
}

TEST(CellClockParse, AnEpochNearNowIsReadToTheNanosecond) {
  const ros2::CellClockEpoch read = ros2::parse_cell_clock(time_of(1'800'000'001, 500'000'000), kNow);
  ASSERT_TRUE(read.ok) << read.error;
  EXPECT_EQ(read.epoch_ns, 1'800'000'001'500'000'000);
  // An hour ago is fine too (a cell that has run for an hour).
  EXPECT_TRUE(ros2::parse_cell_clock(time_of(1'800'000'000 - 3600, 0), kNow).ok);
}

TEST(CellClockParse, ADayAwayIsTheLimitEitherSide) {
  EXPECT_TRUE(ros2::parse_cell_clock(time_of(1'800'000'000 + 86'400, 0), kNow).ok);
  EXPECT_TRUE(ros2::parse_cell_clock(time_of(1'800'000'000 - 86'400, 0), kNow).ok);
  const ros2::CellClockEpoch ahead = ros2::parse_cell_clock(time_of(1'800'000'000 + 86'400, 1), kNow);
  EXPECT_FALSE(ahead.ok);
  EXPECT_NE(ahead.error.find("sec:"), std::string::npos) << ahead.error;
  EXPECT_FALSE(ros2::parse_cell_clock(time_of(1'800'000'000 - 86'401, 0), kNow).ok);
  EXPECT_FALSE(ros2::parse_cell_clock(time_of(0, 0), kNow).ok);          // 1970: not an epoch of today
  EXPECT_FALSE(ros2::parse_cell_clock(time_of(-2'000'000'000, 0), kNow).ok);
}

TEST(CellClockParse, ANanosecondFieldOfASecondOrMoreIsRefused) {
  const ros2::CellClockEpoch read = ros2::parse_cell_clock(time_of(1'800'000'000, 1'000'000'000), kNow);
  EXPECT_FALSE(read.ok);
  EXPECT_NE(read.error.find("nanosec"), std::string::npos) << read.error;
}

TEST(CellClockParse, AReaderClockAtTheEndOfTheRangeDoesNotOverflow) {
  EXPECT_FALSE(ros2::parse_cell_clock(time_of(1'800'000'000, 0), INT64_MIN).ok);
  EXPECT_FALSE(ros2::parse_cell_clock(time_of(-1, 0), INT64_MAX).ok);
}

std::string test_namespace(const char* what) { return std::string("/clock_") + what + "_" + std::to_string(::getpid()); }

TEST(CellClock, NothingPublishedIsAnErrorNamingTheTopicAndTheDomainWithinTheWait) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string ns = test_namespace("none");
  try {
    ros2::wait_for_cell_clock(test::test_domain(), ns, 0.3);
    FAIL() << "no publisher, yet an epoch";
  } catch (const ros2::Ros2Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(ns + "/cell_clock"), std::string::npos) << what;
    EXPECT_NE(what.find("(domain " + std::to_string(test::test_domain()) + ")"), std::string::npos) << what;
  }
}

// A simulated camera of a cell: a small wall scene at 30 frames/s, no epoch of its own.
Config camera_config(const std::string& ns) {
  Config config;
  config.camera = "front";
  config.source.type = SourceType::sim;
  config.sim.width = 424;
  config.sim.height = 240;
  config.sim.fps = 30.0;
  config.sim.frames = 1'000'000;
  config.sim.noise = false;
  config.sim.color = false;
  config.ros2.domain_id = static_cast<int>(test::test_domain());
  config.ros2.node_namespace = ns;
  return config;
}

int64_t realtime_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Frame i of the scene clock is due at epoch + i / fps (docs/SIMULATOR.md), to the nanosecond.
int64_t due_ns(int64_t epoch_ns, int64_t index) { return epoch_ns + std::llround(static_cast<double>(index) * 1e9 / 30.0); }

TEST(CellClock, ACameraStartedLaterJoinsTheSameSceneFramesWithTheEpochFromDds) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const std::string ns = test_namespace("join");
  // The fuser's epoch: 1.25 s ago, so the first camera joins near frame 37.
  const int64_t epoch_ns = realtime_now_ns() - 1'250'000'000;
  const ros2::CellClockPublisher publisher(test::test_domain(), ns, epoch_ns);

  const Config first_config = with_cell_clock(camera_config(ns), 5.0, nullptr);
  ASSERT_TRUE(first_config.sim_epoch_ns.has_value());
  EXPECT_EQ(*first_config.sim_epoch_ns, epoch_ns);
  const std::unique_ptr<Source> first = make_source(first_config);
  Frame a;
  ASSERT_EQ(first->next(a), Source::Status::frame);
  EXPECT_GE(a.index, 37);
  EXPECT_EQ(a.timestamp_ns, due_ns(epoch_ns, a.index));
  ASSERT_EQ(first->next(a), Source::Status::frame);  // a frame later

  // The second camera starts after the first has played a few frames.
  const Config second_config = with_cell_clock(camera_config(ns), 5.0, nullptr);
  ASSERT_TRUE(second_config.sim_epoch_ns.has_value());
  EXPECT_EQ(*second_config.sim_epoch_ns, epoch_ns);
  const std::unique_ptr<Source> second = make_source(second_config);
  Frame b;
  ASSERT_EQ(second->next(b), Source::Status::frame);
  EXPECT_GT(b.index, a.index) << "the later camera joins at the current scene frame, not at the start";
  EXPECT_EQ(b.timestamp_ns, due_ns(epoch_ns, b.index));
  // The first camera, played on, reaches the second's frames at the same capture times.
  Frame c;
  for (int i = 0; i < 30 && c.index < b.index; ++i) ASSERT_EQ(first->next(c), Source::Status::frame);
  EXPECT_EQ(c.timestamp_ns, due_ns(epoch_ns, c.index));
  EXPECT_EQ(c.timestamp_ns - b.timestamp_ns, due_ns(epoch_ns, c.index) - due_ns(epoch_ns, b.index));
}

TEST(CellClock, TheFuserPublishesSimEpochElseASecondAfterItsStart) {
  Config config;
  EXPECT_EQ(app::cell_clock_epoch_ns(config, 1'800'000'000'000'000'000), 1'800'000'001'000'000'000);
  config.sim_epoch_ns = 1'799'999'990'250'000'000;
  EXPECT_EQ(app::cell_clock_epoch_ns(config, 1'800'000'000'000'000'000), 1'799'999'990'250'000'000);
}

TEST(CellClock, ACameraWithItsOwnEpochOrNotACameraOfACellWaitsForNothing) {
  // No DDS is touched: nothing is published on this namespace, and the wait would fail.
  Config own = camera_config(test_namespace("own"));
  own.sim_epoch_ns = 1'700'000'000'000'000'000;
  EXPECT_EQ(*with_cell_clock(own, 0.1, nullptr).sim_epoch_ns, 1'700'000'000'000'000'000);
  Config single = camera_config(test_namespace("single"));
  single.camera.clear();
  EXPECT_FALSE(with_cell_clock(single, 0.1, nullptr).sim_epoch_ns.has_value());
}

}  // namespace
}  // namespace hrcsense::cell_clock_test
