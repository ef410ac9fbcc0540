// SPDX-License-Identifier: Apache-2.0
// hrcsense — `robot.state.source: sim`: the simulator's scripted arm as a robot state source,
// exact or delivered late with a seeded jitter through a RobotStateHistory.
#include "hrcsense/sim/sim.hpp"
#include "hrcsense/clock.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <utility>

namespace hrcsense {
namespace {

int64_t to_ns(double seconds) { return std::llround(seconds * 1e9); }

/// splitmix64: a well-mixed 64-bit value from (seed, k), so jitter is the same in every run.
uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

RobotState sample_state(const RobotTrajectory& trajectory, const TrajectoryClock* clock, int64_t time_ns) {
  const TrajectoryClock::Reading time =
      clock != nullptr ? clock->at(time_ns) : TrajectoryClock::Reading{static_cast<double>(time_ns) * 1e-9, 1.0};
  const TrajectorySample sample = joints_at(trajectory, time.trajectory_s);
  RobotState state;
  state.host_time_ns = time_ns;
  state.q_rad = sample.q_rad;
  for (size_t j = 0; j < kJointCount; ++j) state.qd_rad_s[j] = sample.qd_rad_s[j] * time.rate;
  state.speed_fraction = time.rate;
  state.valid = true;
  state.origin = RobotStateOrigin::sim;
  return state;
}

}  // namespace

SimRobotState::SimRobotState(RobotTrajectory trajectory, Params params)
    : trajectory_(std::move(trajectory)), params_(params), period_ns_(std::max<int64_t>(1, to_ns(params.period_s))) {
  history_.params = params_.history;
}

int64_t SimRobotState::raw_known_ns(int64_t k) const {
  const uint64_t bits = mix(params_.seed ^ mix(static_cast<uint64_t>(k)));
  const double unit = static_cast<double>(bits >> 11) * 0x1.0p-53;  // [0, 1)
  return k * period_ns_ + to_ns(params_.latency_s + unit * params_.jitter_s);
}

bool SimRobotState::state_at(int64_t time_ns, RobotState& out) {
  if (!params_.epoch_ns) return state_on_timeline(time_ns, out);
  // A host (steady) time → the scene time it is on the shared scene clock, and the state's
  // stamps back onto the host clock, where the frame's host time is.
  const int64_t steady_to_scene_ns = realtime_minus_steady_ns() - *params_.epoch_ns;
  const bool valid = state_on_timeline(time_ns + steady_to_scene_ns, out);
  out.host_time_ns -= steady_to_scene_ns;
  if (out.sample_time_ns != 0) out.sample_time_ns -= steady_to_scene_ns;
  return valid;
}

bool SimRobotState::state_on_timeline(int64_t time_ns, RobotState& out) {
  if (params_.latency_s <= 0.0 && params_.jitter_s <= 0.0) {
    out = sample_state(trajectory_, params_.clock.get(), time_ns);
    return true;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  if (time_ns < last_time_ns_) {
    history_.clear();
    next_sample_ = 0;
    last_known_ns_ = 0;
  }
  last_time_ns_ = time_ns;
  // Far ahead of the last call: only the samples the history can hold matter.
  const int64_t latest_ns = time_ns - to_ns(params_.latency_s);
  const int64_t skip_to = latest_ns / period_ns_ - static_cast<int64_t>(RobotStateHistory::kCapacity);
  if (skip_to > next_sample_) {
    next_sample_ = skip_to;
    last_known_ns_ = 0;
  }
  for (;;) {
    const int64_t known_ns = std::max(last_known_ns_, raw_known_ns(next_sample_));
    if (known_ns > time_ns) break;
    history_.add(sample_state(trajectory_, params_.clock.get(), next_sample_ * period_ns_));
    last_known_ns_ = known_ns;
    ++next_sample_;
  }
  const RobotStateLookup lookup = history_.at(time_ns);
  out = lookup.state;
  out.origin = RobotStateOrigin::sim;
  return out.valid;
}

RobotStateStats SimRobotState::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  RobotStateStats stats;
  stats.samples = history_.counts();
  return stats;
}

}  // namespace hrcsense
