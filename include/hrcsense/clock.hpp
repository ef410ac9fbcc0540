// SPDX-License-Identifier: Apache-2.0
// hrcsense — the clock run_pipeline decides by (pacing, frame ages, the watchdog, wall time):
// the steady clock, or a fake one that tests move by hand. RunClock is one of the four virtual
// interfaces (source.hpp says which).
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>

namespace hrcsense {

/// Seconds (a limit such as safety.max_frame_age_s, a nominal period) as ns. Not positive or NaN:
/// 0 (every frame that took any time is then stale). At most 10^6 s, so that sums of run-clock
/// times stay far inside int64.
inline int64_t seconds_to_ns(double s) {
  constexpr double kMaxS = 1e6;
  if (!(s > 0.0)) return 0;
  return static_cast<int64_t>(std::llround((s < kMaxS ? s : kMaxS) * 1e9));
}

/// The shared clock of a cell with several cameras (docs/MULTICAMERA.md, "Clocks"):
/// CLOCK_REALTIME, ns since the Unix epoch, kept in step across hosts by chrony or PTP.
int64_t shared_clock_ns();
/// CLOCK_REALTIME − the steady clock now, ns (the steady clock read on both sides of the realtime
/// read, the offset taken at their middle): what moves a steady-clock time onto the shared clock.
int64_t realtime_minus_steady_ns();

/// The time source of run_pipeline. Times are integer nanoseconds from an arbitrary origin and
/// never decrease. Implementations are called from several threads at once: the run's three,
/// and the threads of the link sinks and live robot state sources that are given the clock.
class RunClock {
 public:
  virtual ~RunClock() = default;
  /// The current time, ns.
  virtual int64_t now_ns() const = 0;
  /// Returns once now_ns() >= `t_ns`, or soon after `*stop_requested` becomes true (null: no
  /// stop request); at once when `t_ns` has passed.
  virtual void sleep_until(int64_t t_ns, const std::atomic<bool>* stop_requested) = 0;
};

/// std::chrono::steady_clock: what a run uses unless told otherwise (RunOptions::clock null).
class SteadyClock final : public RunClock {
 public:
  int64_t now_ns() const override;
  /// Sleeps in slices of at most 20 ms, looking at the stop request between them.
  void sleep_until(int64_t t_ns, const std::atomic<bool>* stop_requested) override;
};

/// A clock that moves only when told: by advance(), set(), or a sleep_until() that jumps to its
/// deadline. A sleep takes no real time, as if the sleeper were alone: a paced run plays at once
/// while its timestamps' time passes on this clock. Which thread sees the time move when is
/// then up to the test (it makes its source and sink wait for each other where it matters);
/// a sleep that blocked until another thread advanced the clock would need a driver thread
/// in every test and would order nothing more. Thread-safe.
class FakeClock final : public RunClock {
 public:
  explicit FakeClock(int64_t start_ns = 0) : now_ns_(start_ns) {}
  int64_t now_ns() const override { return now_ns_.load(); }
  /// Jumps to `t_ns` when that is later and returns at once; a stop request (already set)
  /// returns without moving the clock, as the steady clock's sleep would end early.
  void sleep_until(int64_t t_ns, const std::atomic<bool>* stop_requested) override;
  /// Moves the clock on by `ns` (>= 0; std::invalid_argument otherwise: it never goes back).
  void advance(int64_t ns);
  /// Sets the time to `t_ns` (not before now_ns(); std::invalid_argument otherwise).
  void set(int64_t t_ns);

 private:
  std::atomic<int64_t> now_ns_;
};

}  // namespace hrcsense
