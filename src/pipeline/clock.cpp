// SPDX-License-Identifier: Apache-2.0
// hrcsense — the steady and the fake run clock.

#include "hrcsense/clock.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

namespace hrcsense {

int64_t shared_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int64_t realtime_minus_steady_ns() {
  const SteadyClock steady;
  const int64_t before = steady.now_ns();
  const int64_t realtime = shared_clock_ns();
  const int64_t after = steady.now_ns();
  return realtime - (before + (after - before) / 2);
}

int64_t SteadyClock::now_ns() const {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void SteadyClock::sleep_until(int64_t t_ns, const std::atomic<bool>* stop_requested) {
  // Short slices, so that a stop request (SIGINT, SIGTERM) ends the wait within one.
  constexpr int64_t kSliceNs = 20'000'000;
  for (int64_t now = now_ns(); now < t_ns && !(stop_requested != nullptr && stop_requested->load());
       now = now_ns()) {
    std::this_thread::sleep_for(std::chrono::nanoseconds(std::min(t_ns - now, kSliceNs)));
  }
}

void FakeClock::sleep_until(int64_t t_ns, const std::atomic<bool>* stop_requested) {
  if (stop_requested != nullptr && stop_requested->load()) return;
  // Later only: another thread may have moved the clock past t_ns meanwhile.
  int64_t now = now_ns_.load();
  while (now < t_ns && !now_ns_.compare_exchange_weak(now, t_ns)) {
    // `now` is the clock's current time again; try once more
  }
}

void FakeClock::advance(int64_t ns) {
  if (ns < 0) throw std::invalid_argument("FakeClock::advance: " + std::to_string(ns) + " ns would go back");
  now_ns_.fetch_add(ns);
}

void FakeClock::set(int64_t t_ns) {
  int64_t now = now_ns_.load();
  do {
    if (t_ns < now) {
      throw std::invalid_argument("FakeClock::set: " + std::to_string(t_ns) + " ns is before now (" +
                                  std::to_string(now) + " ns)");
    }
  } while (!now_ns_.compare_exchange_weak(now, t_ns));
}

}  // namespace hrcsense
