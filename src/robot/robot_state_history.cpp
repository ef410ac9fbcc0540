// SPDX-License-Identifier: Apache-2.0
// hrcsense — the robot state history and the sender-to-host clock map.
#include "hrcsense/robot_state_history.hpp"

#include "hrcsense/robot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hrcsense {

bool all_finite(const JointAngles& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

namespace {

double seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// "joint 2 (shoulder_lift) 171.9 rad" and what follows; %.6g keeps 1e300 readable.
std::string joint_text(size_t j, double value_rad, const char* what) {
  char text[160];
  std::snprintf(text, sizeof text, "joint %zu (%s) %.6g rad %s", j + 1, joint_name(static_cast<int>(j)).c_str(),
                value_rad, what);
  return text;
}

}  // namespace

bool RobotStateHistory::add(const RobotState& sample) {
  if (!all_finite(sample.q_rad) || !all_finite(sample.qd_rad_s)) {
    ++counts_.rejected_non_finite;
    last_rejection_ = "a non-finite joint angle or velocity";
    return false;
  }
  for (size_t j = 0; j < kJointCount; ++j) {
    if (!(sample.q_rad[j] >= params.q_min_rad[j] && sample.q_rad[j] <= params.q_max_rad[j])) {
      ++counts_.rejected_limits;
      char limits[96];
      std::snprintf(limits, sizeof limits, "outside the arm's limits %.4g..%.4g rad", params.q_min_rad[j],
                    params.q_max_rad[j]);
      last_rejection_ = joint_text(j, sample.q_rad[j], limits);
      return false;
    }
  }
  if (size_ > 0) {
    const RobotState& previous = newest();
    if (sample.host_time_ns <= previous.host_time_ns) {
      ++counts_.rejected_backwards;
      last_rejection_ = "not later than the previous sample";
      return false;
    }
    const double dt_s = seconds(sample.host_time_ns - previous.host_time_ns);
    if (dt_s > params.max_age_s) {
      clear();  // after a gap the arm may be anywhere: no jump test against the old pose
    } else {
      for (size_t j = 0; j < kJointCount; ++j) {
        const double speed = std::max(std::fabs(previous.qd_rad_s[j]), std::fabs(sample.qd_rad_s[j]));
        // Written so that the comparison fails (rejects) for anything unexpected.
        if (!(std::fabs(sample.q_rad[j] - previous.q_rad[j]) <= speed * dt_s + params.jump_tolerance_rad)) {
          ++counts_.rejected_jump;
          char from[64];
          std::snprintf(from, sizeof from, "jumped from %.6g rad, further than qd·dt + tolerance", previous.q_rad[j]);
          last_rejection_ = joint_text(j, sample.q_rad[j], from);
          return false;
        }
      }
    }
  }
  if (size_ == kCapacity) {
    first_ = (first_ + 1) % kCapacity;
    --size_;
  }
  RobotState& slot = ring_[(first_ + size_) % kCapacity];
  slot = sample;
  slot.valid = true;
  ++size_;
  ++counts_.accepted;
  if (listener) listener(slot);
  return true;
}

RobotStateLookup RobotStateHistory::at(int64_t host_time_ns) const {
  RobotStateLookup out;
  out.state.host_time_ns = host_time_ns;
  if (size_ == 0) return out;  // no_robot_state
  const RobotState& last = newest();
  out.state.origin = last.origin;
  out.state.sample_time_ns = last.host_time_ns;
  const int64_t age_ns = std::max<int64_t>(0, host_time_ns - last.host_time_ns);
  out.age_ms = static_cast<double>(age_ns) * 1e-6;
  if (!(seconds(age_ns) <= params.max_age_s)) {
    out.code = ReasonCode::robot_state_stale;
    return out;
  }
  RobotState& state = out.state;
  if (host_time_ns >= last.host_time_ns) {
    // Past the newest sample: move on with its velocity, for at most one sample period.
    const int64_t period_ns = size_ >= 2 ? last.host_time_ns - sample(size_ - 2).host_time_ns : 0;
    const double dt_s = seconds(std::min(age_ns, period_ns));
    state.q_rad = last.q_rad;
    state.qd_rad_s = last.qd_rad_s;
    state.status = last.status;
    state.speed_fraction = last.speed_fraction;
    for (size_t j = 0; j < kJointCount; ++j) state.q_rad[j] += last.qd_rad_s[j] * dt_s;
    out.extrapolated = dt_s > 0.0;
    state.extrapolated_ns = std::min(age_ns, period_ns);
  } else if (host_time_ns <= sample(0).host_time_ns) {
    state.q_rad = sample(0).q_rad;
    state.qd_rad_s = sample(0).qd_rad_s;
    state.status = sample(0).status;
    state.speed_fraction = sample(0).speed_fraction;
  } else {
    // The first sample later than the frame; the one before it is not later.
    size_t lo = 0, hi = size_ - 1;
    while (hi - lo > 1) {
      const size_t mid = lo + (hi - lo) / 2;
      (sample(mid).host_time_ns <= host_time_ns ? lo : hi) = mid;
    }
    const RobotState& a = sample(lo);
    const RobotState& b = sample(hi);
    state.status = a.status;  // modes do not interpolate: the one in force at the frame's time
    state.speed_fraction = a.speed_fraction;  // nor does the slider: it steps
    const double w = static_cast<double>(host_time_ns - a.host_time_ns) /
                     static_cast<double>(b.host_time_ns - a.host_time_ns);
    for (size_t j = 0; j < kJointCount; ++j) {
      state.q_rad[j] = a.q_rad[j] + w * (b.q_rad[j] - a.q_rad[j]);
      state.qd_rad_s[j] = a.qd_rad_s[j] + w * (b.qd_rad_s[j] - a.qd_rad_s[j]);
    }
  }
  state.valid = true;
  out.code = ReasonCode::clear;
  return out;
}

int64_t SenderClockMap::to_host(int64_t sent_ns, int64_t arrival_ns) {
  const int64_t offset = arrival_ns - sent_ns;
  if (!started_ || sent_ns < last_sent_ns_) {  // first message, or the sender's clock restarted
    started_ = true;
    block_start_ns_ = arrival_ns;
    current_min_ = previous_min_ = offset;
  } else if (arrival_ns - block_start_ns_ >= window_ns_) {
    previous_min_ = current_min_;
    current_min_ = offset;
    block_start_ns_ = arrival_ns;
  } else {
    current_min_ = std::min(current_min_, offset);
  }
  last_sent_ns_ = sent_ns;
  return sent_ns + std::min(current_min_, previous_min_);
}

}  // namespace hrcsense
