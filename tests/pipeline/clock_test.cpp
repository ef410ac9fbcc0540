// SPDX-License-Identifier: Apache-2.0
// Tests of the run clocks: the fake one moves only when told, the steady one sleeps until its
// deadline unless a stop request ends the sleep.

#include "hrcsense/clock.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace hrcsense {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(FakeClock, MovesOnlyWhenTold) {
  FakeClock clock(5);
  EXPECT_EQ(clock.now_ns(), 5);
  EXPECT_EQ(clock.now_ns(), 5);
  clock.advance(10);
  EXPECT_EQ(clock.now_ns(), 15);
  clock.advance(0);
  EXPECT_EQ(clock.now_ns(), 15);
  clock.set(100);
  EXPECT_EQ(clock.now_ns(), 100);
  clock.set(100);  // the same time is not going back
  EXPECT_EQ(clock.now_ns(), 100);
  // It never goes back: the run's times are differences of its readings.
  EXPECT_THROW(clock.advance(-1), std::invalid_argument);
  EXPECT_THROW(clock.set(99), std::invalid_argument);
  EXPECT_EQ(clock.now_ns(), 100);
}

TEST(FakeClock, SleepJumpsToTheDeadline) {
  FakeClock clock;
  const auto real_start = std::chrono::steady_clock::now();
  clock.sleep_until(3'600'000'000'000, nullptr);  // an hour
  EXPECT_EQ(clock.now_ns(), 3'600'000'000'000);
  EXPECT_LT(seconds_since(real_start), 60.0);  // and takes no real time to speak of
  clock.sleep_until(1'000, nullptr);  // a deadline that has passed: no change
  EXPECT_EQ(clock.now_ns(), 3'600'000'000'000);
  // A stop request ends the sleep where it is, as it would end a real one early.
  std::atomic<bool> stop{true};
  clock.sleep_until(7'200'000'000'000, &stop);
  EXPECT_EQ(clock.now_ns(), 3'600'000'000'000);
  stop = false;
  clock.sleep_until(7'200'000'000'000, &stop);
  EXPECT_EQ(clock.now_ns(), 7'200'000'000'000);
}

// Two threads advance it 10000 times by 1 ns each while a third reads: every step counts,
// and no reading is earlier than the one before it.
TEST(FakeClock, IsThreadSafe) {
  FakeClock clock;
  constexpr int kSteps = 10'000;
  auto advance = [&] {
    for (int i = 0; i < kSteps; ++i) clock.advance(1);
  };
  bool monotonic = true;
  std::thread reader([&] {
    int64_t previous = 0;
    for (int i = 0; i < kSteps; ++i) {
      const int64_t now = clock.now_ns();
      monotonic = monotonic && now >= previous;
      previous = now;
    }
  });
  std::thread a(advance), b(advance);
  a.join();
  b.join();
  reader.join();
  EXPECT_EQ(clock.now_ns(), 2 * kSteps);
  EXPECT_TRUE(monotonic);
}

TEST(SteadyClock, ReadsTheSteadyClock) {
  SteadyClock clock;
  const auto ns = [](std::chrono::steady_clock::time_point t) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  };
  const int64_t before = ns(std::chrono::steady_clock::now());
  const int64_t now = clock.now_ns();
  const int64_t after = ns(std::chrono::steady_clock::now());
  EXPECT_LE(before, now);
  EXPECT_LE(now, after);
}

TEST(SteadyClock, SleepsUntilTheDeadline) {
  SteadyClock clock;
  const int64_t deadline = clock.now_ns() + 30'000'000;  // 30 ms: two slices of 20 ms
  clock.sleep_until(deadline, nullptr);
  EXPECT_GE(clock.now_ns(), deadline);
  // A deadline that has passed returns at once (here: well within a minute).
  const auto real_start = std::chrono::steady_clock::now();
  clock.sleep_until(clock.now_ns() - 1'000'000'000, nullptr);
  EXPECT_LT(seconds_since(real_start), 60.0);
}

// A stop request ends a minute's sleep: one already set at once, one set from another thread
// 50 ms into the sleep within a slice of it. Were it not looked at, the test would take the
// minute and fail.
TEST(SteadyClock, StopRequestEndsTheSleep) {
  SteadyClock clock;
  std::atomic<bool> stop{true};
  auto real_start = std::chrono::steady_clock::now();
  clock.sleep_until(clock.now_ns() + 60'000'000'000, &stop);
  EXPECT_LT(seconds_since(real_start), 30.0);

  stop = false;
  real_start = std::chrono::steady_clock::now();
  std::thread requester([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stop = true;
  });
  clock.sleep_until(clock.now_ns() + 60'000'000'000, &stop);
  requester.join();
  EXPECT_GE(seconds_since(real_start), 0.05);
  EXPECT_LT(seconds_since(real_start), 30.0);
}

}  // namespace
}  // namespace hrcsense
