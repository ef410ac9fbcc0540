// SPDX-License-Identifier: Apache-2.0
// hrcsense — the recorded joint states of a bag, looked up by frame timestamp.
#include "recorded_robot_state.hpp"

#include <utility>

namespace hrcsense {

void RecordedRobotState::add(int64_t stamp_ns, const JointAngles& q_rad, const JointAngles& qd_rad_s) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if ((size_ > 0 && stamp_ns <= sample(size_ - 1).stamp_ns) || (delivered_any_ && stamp_ns <= delivered_ns_)) {
    // A state after its own frame in the file (or out of order) would reach the processing
    // only sometimes, depending on the threads' timing: it is never used instead.
    ++counts_.rejected_backwards;
    problem_ = path_ + ": joint state stamped " + std::to_string(stamp_ns) +
               " ns comes after its frame or an earlier state in the file: not used";
    return;
  }
  if (size_ == kCapacity) {
    first_ = (first_ + 1) % kCapacity;
    --size_;
  }
  ring_[(first_ + size_) % kCapacity] = Sample{stamp_ns, q_rad, qd_rad_s};
  ++size_;
  ++counts_.accepted;
}

void RecordedRobotState::frame_delivered(int64_t timestamp_ns) {
  const std::lock_guard<std::mutex> lock(mutex_);
  delivered_any_ = true;
  delivered_ns_ = timestamp_ns;
}

bool RecordedRobotState::state_at(int64_t time_ns, RobotState& out) {
  const std::lock_guard<std::mutex> lock(mutex_);
  out = RobotState{};
  out.origin = RobotStateOrigin::recorded;
  // Newest first: processing asks for the frame just delivered, or one or two before it.
  for (size_t i = size_; i-- > 0;) {
    const Sample& s = sample(i);
    if (s.stamp_ns < time_ns) break;
    if (s.stamp_ns != time_ns) continue;
    out.host_time_ns = out.sample_time_ns = time_ns;
    out.q_rad = s.q_rad;
    out.qd_rad_s = s.qd_rad_s;
    out.valid = true;
    return true;
  }
  problem_ = path_ + ": no joint state recorded for the frame at " + std::to_string(time_ns) +
             " ns (topic /hrcsense/joint_states)";
  return false;
}

std::string RecordedRobotState::error() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return problem_;
}

RobotStateStats RecordedRobotState::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  RobotStateStats stats;
  stats.samples = counts_;
  stats.last_problem = problem_;
  return stats;
}

namespace {

class SharedRecordedRobotState final : public RobotStateSource {
 public:
  explicit SharedRecordedRobotState(std::shared_ptr<RecordedRobotState> states) : states_(std::move(states)) {}
  RobotStateOrigin origin() const override { return RobotStateOrigin::recorded; }
  bool state_at(int64_t time_ns, RobotState& out) override { return states_->state_at(time_ns, out); }
  std::string error() const override { return states_->error(); }
  RobotStateStats stats() const override { return states_->stats(); }

 private:
  std::shared_ptr<RecordedRobotState> states_;
};

}  // namespace

std::unique_ptr<RobotStateSource> share_recorded_robot_state(std::shared_ptr<RecordedRobotState> states) {
  return std::make_unique<SharedRecordedRobotState>(std::move(states));
}

}  // namespace hrcsense
