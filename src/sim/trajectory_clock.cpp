// SPDX-License-Identifier: Apache-2.0
// hrcsense — `robot.trajectory.follow_link`: the simulated arm's own time, which runs at the
// speed scale hrcsense last sent, so that the rendered arm, the `sim` robot state and the
// truth all see a robot that obeys the link (a closed loop for tests and demos).

#include "hrcsense/sim/sim.hpp"

#include <algorithm>
#include <chrono>

namespace hrcsense {
namespace {

// Kept frames: enough for any state a history or a late label asks for, bounded for endless runs.
constexpr size_t kMaxMarks = 4096;

double seconds(int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

}  // namespace

TrajectoryClock::TrajectoryClock() { marks_.reserve(kMaxMarks); }

TrajectoryClock::Reading TrajectoryClock::read(int64_t t_ns) const {
  if (marks_.empty()) return {seconds(t_ns), 1.0};  // not started: the trajectory's own time
  // The last mark at or before t_ns; before the first, the first (read backwards at its rate).
  auto after = std::upper_bound(marks_.begin(), marks_.end(), t_ns, [](int64_t t, const Mark& m) { return t < m.t_ns; });
  const Mark& mark = after == marks_.begin() ? *after : *(after - 1);
  return {mark.trajectory_s + seconds(t_ns - mark.t_ns) * mark.rate, mark.rate};
}

TrajectoryClock::Reading TrajectoryClock::advance_to(int64_t t_ns) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!marks_.empty() && t_ns <= marks_.back().t_ns) return read(t_ns);
  // Up to t_ns at the rate in force since the last mark; from t_ns on, at the scale sent last.
  const double trajectory_s = marks_.empty() ? seconds(t_ns) : read(t_ns).trajectory_s;
  if (marks_.size() == kMaxMarks) marks_.erase(marks_.begin(), marks_.begin() + kMaxMarks / 2);
  marks_.push_back({t_ns, trajectory_s, scale_});
  return {trajectory_s, scale_};
}

TrajectoryClock::Reading TrajectoryClock::at(int64_t t_ns) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return read(t_ns);
}

void TrajectoryClock::sent(int64_t frame_timestamp_ns, float scale) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    // NaN or out of range would be no command a robot takes: it then keeps its speed.
    if (scale >= 0.0F && scale <= 1.0F) scale_ = scale;
    sent_for_ns_ = std::max(sent_for_ns_, frame_timestamp_ns);
  }
  sent_changed_.notify_all();
}

bool TrajectoryClock::wait_sent(int64_t frame_timestamp_ns, double timeout_s) const {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto timeout = std::chrono::duration<double>(std::max(0.0, timeout_s));
  return sent_changed_.wait_for(lock, timeout, [&] { return sent_for_ns_ >= frame_timestamp_ns; });
}

double TrajectoryClock::scale() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return scale_;
}

}  // namespace hrcsense
