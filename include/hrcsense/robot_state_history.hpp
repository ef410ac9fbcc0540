// SPDX-License-Identifier: Apache-2.0
// hrcsense — the robot's recent joint states on the host clock: what a live robot state source
// keeps, and how a frame's state is read from it (interpolated, briefly extrapolated, or stale).
// Also the map from a sender's clock (RTDE's controller timestamp, udp_json's t_ns) to the host's.
#pragma once

#include "hrcsense/types.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

namespace hrcsense {

/// True when every joint value is finite (no NaN, no Inf): the one test of a joint vector
/// before it is used, by the history and the pipeline alike.
bool all_finite(const JointAngles& values);

struct RobotStateHistoryParams {
  /// `robot.state.max_age_s`: a frame whose newest sample is older than this is a stop.
  double max_age_s = 0.05;
  /// A sample may move each joint by at most |qd|·dt plus this much from the previous one
  /// (dt ≤ max_age_s); more is a jump and the sample is rejected.
  double jump_tolerance_rad = 0.05;
  /// The arm's joint limits (`robot.arm`), rad, joint 1 first, inclusive: a sample with a joint
  /// outside them is no pose of this arm (degrees sent as radians, garbage) and is rejected.
  /// Unbounded until the run sets them from its arm (assembly's robot_state_history_params).
  JointAngles q_min_rad = unbounded(-1.0);
  JointAngles q_max_rad = unbounded(1.0);

  static JointAngles unbounded(double sign) {
    JointAngles q;
    q.fill(sign * std::numeric_limits<double>::infinity());
    return q;
  }
};

/// Samples offered to a history, by what became of them.
struct RobotStateCounts {
  int64_t accepted = 0;
  int64_t rejected_non_finite = 0;  ///< a NaN or Inf angle or velocity
  int64_t rejected_backwards = 0;   ///< not later than the previous sample
  int64_t rejected_jump = 0;        ///< a joint moved further than qd·dt + tolerance
  int64_t rejected_limits = 0;      ///< a joint outside the arm's limits
  int64_t rejected() const { return rejected_non_finite + rejected_backwards + rejected_jump + rejected_limits; }
};

/// Called with a sample as a RobotStateHistory accepts it (RobotStateHistory::listener).
using RobotStateListener = std::function<void(const RobotState& accepted)>;

/// The state for one frame, with how it was found.
struct RobotStateLookup {
  RobotState state;           ///< valid false for no_robot_state / robot_state_stale; sample_time_ns the newest sample's
  ReasonCode code = ReasonCode::no_robot_state;  ///< clear when valid
  double age_ms = 0.0;        ///< frame time minus the newest sample's time, ≥ 0
  bool extrapolated = false;  ///< the frame is past the newest sample: q moved on with qd
};

/// The last kCapacity accepted samples, oldest first, on the host clock. Not thread-safe: a
/// live source guards it with its own mutex. No allocation for an accepted sample.
class RobotStateHistory {
 public:
  static constexpr size_t kCapacity = 256;  ///< 0.5 s at RTDE's 500 Hz, 2 s at 125 Hz

  RobotStateHistoryParams params;
  /// Called by add() with each sample it accepts, once the sample is in the history (valid set),
  /// in the order accepted; empty: nobody is told. It runs on the thread that calls add() and
  /// under whatever guards this history (a live source's mutex), so it must be short and must
  /// not call back into the source: handing the sample on to a queue is what it is for (the
  /// fuser's JointStateRelay). Never called for a rejected sample, nor by clear().
  RobotStateListener listener;

  /// Adds a sample (host_time_ns already on the host clock). Returns false and counts it when
  /// it is rejected: non-finite, a joint outside the limits, not later than the previous one,
  /// or a jump; last_rejection() then says why, naming the joint and value. A sample that
  /// follows a gap longer than max_age_s starts the history afresh (a reconnect may find the
  /// arm elsewhere).
  bool add(const RobotState& sample);
  /// The state at `host_time_ns`: linear interpolation of q and qd between the samples that
  /// bracket it; past the newest sample, q extrapolated with its qd for at most one sample
  /// period; before the oldest, the oldest. RobotState::status is that of the latest sample not
  /// later than `host_time_ns` (the oldest before it). No sample: no_robot_state. Newest sample
  /// older than max_age_s: robot_state_stale (status unknown).
  RobotStateLookup at(int64_t host_time_ns) const;
  void clear() { size_ = 0; }
  size_t size() const { return size_; }
  const RobotStateCounts& counts() const { return counts_; }
  /// Why the last rejected sample was rejected, for people ("joint 2 (shoulder_lift) 171.9 rad
  /// outside its limits -6.283..6.283 rad"); empty before the first rejection.
  const std::string& last_rejection() const { return last_rejection_; }
  /// The newest accepted sample; only when size() > 0.
  const RobotState& newest() const { return sample(size_ - 1); }

 private:
  std::array<RobotState, kCapacity> ring_{};
  size_t first_ = 0;  ///< index of the oldest sample in ring_
  size_t size_ = 0;
  RobotStateCounts counts_;
  std::string last_rejection_;  ///< written only on a rejection: the accepted path stays allocation-free

  const RobotState& sample(size_t i) const { return ring_[(first_ + i) % kCapacity]; }
};

/// Maps a sender's clock to the host's monotonic clock. The offset is the smallest
/// (arrival − sent) seen over the last one to two windows: the least-delayed message, so a
/// mapped time is never later than the message's arrival, and it errs (early) by the smallest
/// transport delay in the window plus the two clocks' drift over at most two windows (100 ppm
/// over 2 × 5 s: 1 ms). The window also lets a step in the sender's clock through within two
/// windows; a step backwards (a restarted controller) resets the map at once.
class SenderClockMap {
 public:
  explicit SenderClockMap(int64_t window_ns = 5'000'000'000) : window_ns_(window_ns) {}
  /// The host time of a message stamped `sent_ns` by the sender and received at `arrival_ns`.
  int64_t to_host(int64_t sent_ns, int64_t arrival_ns);
  void reset() { started_ = false; }

 private:
  int64_t window_ns_;
  bool started_ = false;
  int64_t block_start_ns_ = 0;   ///< arrival time the current block began
  int64_t current_min_ = 0;      ///< smallest offset in the current block
  int64_t previous_min_ = 0;     ///< smallest offset in the block before
  int64_t last_sent_ns_ = 0;
};

}  // namespace hrcsense
