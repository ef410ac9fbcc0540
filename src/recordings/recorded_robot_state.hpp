// SPDX-License-Identifier: Apache-2.0
// hrcsense — `robot.state.source: recorded`: the joint states of a bag's /hrcsense/joint_states,
// handed from BagSource (the capture thread, which reads them in file order) to the pipeline's
// processing (which looks each frame's up by its timestamp).
#pragma once

#include "hrcsense/robot_state.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

namespace hrcsense {

/// The recorded joint states BagSource has read and the processing has not yet asked for: the
/// last kCapacity, in file order. Thread-safe; no allocation after construction.
class RecordedRobotState final : public RobotStateSource {
 public:
  /// Far more than the capture thread runs ahead of processing (a frame or two).
  static constexpr size_t kCapacity = 256;

  explicit RecordedRobotState(std::string path) : path_(std::move(path)) {}

  RobotStateOrigin origin() const override { return RobotStateOrigin::recorded; }
  /// The recorded state stamped exactly `time_ns` (a frame's timestamp on the playback's
  /// timeline), valid, with its recorded velocities and sample time `time_ns` (age 0). None:
  /// false and an invalid state (the frame is a stop), error() naming the file and the time.
  bool state_at(int64_t time_ns, RobotState& out) override;
  std::string error() const override;
  RobotStateStats stats() const override;

  /// BagSource: a state read from the bag, stamped on the playback's timeline (lap offset
  /// added). One not later than the previous state, or not later than the last frame already
  /// delivered (it follows its frame in the file: too late for it), is rejected and counted.
  void add(int64_t stamp_ns, const JointAngles& q_rad, const JointAngles& qd_rad_s);
  /// BagSource: the frame stamped `timestamp_ns` is being delivered.
  void frame_delivered(int64_t timestamp_ns);

 private:
  struct Sample {
    int64_t stamp_ns = 0;
    JointAngles q_rad{};
    JointAngles qd_rad_s{};
  };
  const Sample& sample(size_t i) const { return ring_[(first_ + i) % kCapacity]; }

  std::string path_;
  mutable std::mutex mutex_;
  std::array<Sample, kCapacity> ring_{};
  size_t first_ = 0;  ///< oldest sample in ring_
  size_t size_ = 0;
  bool delivered_any_ = false;
  int64_t delivered_ns_ = 0;  ///< timestamp of the last frame delivered
  RobotStateCounts counts_;
  std::string problem_;       ///< the last lookup or sample problem; empty when none
};

/// A RobotStateSource that forwards to a RecordedRobotState shared with the BagSource that fills
/// it, so either may go first.
std::unique_ptr<RobotStateSource> share_recorded_robot_state(std::shared_ptr<RecordedRobotState> states);

}  // namespace hrcsense
