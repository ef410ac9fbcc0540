// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the fuser's JointState writer and relay (ros2_joint_state_writer.hpp).
#include "dds/ros2_joint_state_writer.hpp"

#include "dds/dds_entity.hpp"
#include "dds/ros2_messages.hpp"  // dds_topic_name, stamp_from_ns
#include "hrcsense/robot_state_history.hpp"

#include <algorithm>
#include <array>
#include <chrono>

namespace hrcsense::ros2 {

std::string cell_joint_states_topic(const std::string& node_namespace) { return node_namespace + "/joint_states"; }

struct JointStateWriter::Dds {
  ParticipantScope scope;
  dds_entity_t writer = 0;
  explicit Dds(uint32_t domain_id) : scope(domain_id) {}
};

JointStateWriter::JointStateWriter(const JointStateWriterParams& params)
    : params_(params), names_(ur_joint_names(params.tf_prefix)), dds_(std::make_unique<Dds>(params.domain_id)) {
  const std::string name = dds_topic_name(params_.topic);
  const dds_entity_t topic = dds_->scope.own(
      dds_create_topic(dds_->scope.participant(), &sensor_msgs_msg_dds__JointState__desc, name.c_str(), nullptr, nullptr),
      "DDS topic " + name);
  const QosHandle qos(EndpointQos{true, false, 10});  // ROS's default: reliable, volatile, keep-last 10
  dds_->writer = dds_->scope.own(dds_create_writer(dds_->scope.participant(), topic, qos.get(), nullptr),
                                 "DDS writer on " + name);
}

JointStateWriter::~JointStateWriter() = default;

bool JointStateWriter::write(int64_t stamp_ns, const JointAngles& q_rad, const JointAngles& qd_rad_s) {
  if (!all_finite(q_rad) || !all_finite(qd_rad_s)) {
    last_error_ = params_.topic + ": a non-finite joint value was not written";
    return false;
  }
  // The message points at these: nothing is allocated with DDS's allocator, nothing to free.
  std::array<char*, kJointCount> name_pointers{};
  for (size_t j = 0; j < kJointCount; ++j) name_pointers[j] = names_[j].data();
  std::array<double, kJointCount> position{}, velocity{};
  for (size_t j = 0; j < kJointCount; ++j) {
    position[j] = q_rad[j];
    velocity[j] = qd_rad_s[j];
  }
  char empty[] = "";
  sensor_msgs_msg_dds__JointState_ msg{};
  msg.header.stamp = stamp_from_ns(stamp_ns);
  msg.header.frame_id = empty;
  msg.name._buffer = name_pointers.data();
  msg.name._length = msg.name._maximum = static_cast<uint32_t>(kJointCount);
  msg.position._buffer = position.data();
  msg.position._length = msg.position._maximum = static_cast<uint32_t>(kJointCount);
  msg.velocity._buffer = velocity.data();
  msg.velocity._length = msg.velocity._maximum = static_cast<uint32_t>(kJointCount);
  const dds_return_t ret = dds_write(dds_->writer, &msg);
  if (ret < 0) {
    last_error_ = params_.topic + ": write refused: " + dds_strretcode(ret);
    return false;
  }
  return true;
}

int32_t JointStateWriter::readers_matched() const {
  dds_publication_matched_status_t status{};
  if (dds_get_publication_matched_status(dds_->writer, &status) != DDS_RETCODE_OK) return 0;
  return static_cast<int32_t>(status.current_count);
}

JointStateRelay::JointStateRelay(RobotStateSource& source, const RunClock& clock, const JointStateWriterParams& params,
                                 double poll_s)
    : source_(source), clock_(clock), writer_(params), poll_ns_(std::max<int64_t>(100'000, seconds_to_ns(poll_s))) {
  thread_ = std::thread([this] { loop(); });
}

JointStateRelay::~JointStateRelay() {
  stop_ = true;
  thread_.join();
}

JointStateRelayCounters JointStateRelay::counters() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

void JointStateRelay::loop() {
  while (!stop_) {
    relay_newest();
    std::this_thread::sleep_for(std::chrono::nanoseconds(poll_ns_));
  }
}

void JointStateRelay::relay_newest() {
  RobotState now_state;
  source_.state_at(clock_.now_ns(), now_state);
  // sample_time_ns is the newest accepted sample's host time, also when the state is stale: a
  // silent source leaves it where it was, and nothing new is published.
  const int64_t sample_ns = now_state.sample_time_ns;
  if (sample_ns <= last_sample_ns_) return;
  last_sample_ns_ = sample_ns;
  // At its own time the history answers with the sample itself (no interpolation, no
  // extrapolation), or nothing when it is already older than robot.state.max_age_s.
  RobotState sample;
  if (!source_.state_at(sample_ns, sample) || !sample.valid) return;
  const bool written = writer_.write(sample_ns + realtime_minus_steady_ns(), sample.q_rad, sample.qd_rad_s);
  const std::lock_guard<std::mutex> lock(mutex_);
  if (written) {
    ++counters_.published;
  } else {
    ++counters_.refused;
    counters_.last_error = writer_.last_error();
  }
}

}  // namespace hrcsense::ros2
