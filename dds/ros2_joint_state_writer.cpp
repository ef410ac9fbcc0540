// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the fuser's JointState writer and relay (ros2_joint_state_writer.hpp).
#include "dds/ros2_joint_state_writer.hpp"

#include "dds/dds_entity.hpp"
#include "dds/ros2_messages.hpp"  // dds_topic_name, stamp_from_ns
#include "hrcsense/clock.hpp"
#include "hrcsense/robot_state_history.hpp"

#include "std_msgs.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace hrcsense::ros2 {

std::string cell_joint_states_topic(const std::string& node_namespace) { return node_namespace + "/joint_states"; }

std::string cell_robot_speed_scaling_topic(const std::string& node_namespace) {
  return node_namespace + "/robot_speed_scaling";
}

struct JointStateWriter::Dds {
  ParticipantScope scope;
  dds_entity_t writer = 0;
  dds_entity_t speed_writer = 0;  ///< 0: no speed scaling topic
  explicit Dds(uint32_t domain_id) : scope(domain_id) {}

  dds_entity_t make_writer(const dds_topic_descriptor_t& type, const std::string& ros_topic) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic =
        scope.own(dds_create_topic(scope.participant(), &type, name.c_str(), nullptr, nullptr), "DDS topic " + name);
    const QosHandle qos(EndpointQos{true, false, 10});  // ROS's default: reliable, volatile, keep-last 10
    return scope.own(dds_create_writer(scope.participant(), topic, qos.get(), nullptr), "DDS writer on " + name);
  }
};

JointStateWriter::JointStateWriter(const JointStateWriterParams& params)
    : params_(params), names_(ur_joint_names(params.tf_prefix)), dds_(std::make_unique<Dds>(params.domain_id)) {
  dds_->writer = dds_->make_writer(sensor_msgs_msg_dds__JointState__desc, params_.topic);
  if (!params_.speed_scaling_topic.empty()) {
    dds_->speed_writer = dds_->make_writer(std_msgs_msg_dds__Float64__desc, params_.speed_scaling_topic);
  }
}

JointStateWriter::~JointStateWriter() = default;

WriteOutcome JointStateWriter::outcome(int32_t ret, const std::string& topic) {
  if (ret == DDS_RETCODE_TIMEOUT) return WriteOutcome::timed_out;
  if (ret < 0) {
    last_error_ = topic + ": write refused: " + dds_strretcode(ret);
    return WriteOutcome::refused;
  }
  return WriteOutcome::written;
}

WriteOutcome JointStateWriter::write(int64_t stamp_ns, const JointAngles& q_rad, const JointAngles& qd_rad_s) {
  if (!all_finite(q_rad) || !all_finite(qd_rad_s)) {
    last_error_ = params_.topic + ": a non-finite joint value was not written";
    return WriteOutcome::refused;
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
  return outcome(dds_write(dds_->writer, &msg), params_.topic);
}

WriteOutcome JointStateWriter::write_speed_fraction(double fraction) {
  if (dds_->speed_writer == 0) {
    last_error_ = "no speed scaling topic to write a speed fraction on";
    return WriteOutcome::refused;
  }
  if (!(fraction >= 0.0 && fraction <= 1.0)) {  // NaN fails too
    last_error_ = params_.speed_scaling_topic + ": a speed fraction outside 0..1 was not written";
    return WriteOutcome::refused;
  }
  const std_msgs_msg_dds__Float64_ msg{fraction};
  return outcome(dds_write(dds_->speed_writer, &msg), params_.speed_scaling_topic);
}

namespace {

int32_t matched_readers(dds_entity_t writer) {
  dds_publication_matched_status_t status{};
  if (writer == 0 || dds_get_publication_matched_status(writer, &status) != DDS_RETCODE_OK) return 0;
  return static_cast<int32_t>(status.current_count);
}

}  // namespace

int32_t JointStateWriter::readers_matched() const { return matched_readers(dds_->writer); }

int32_t JointStateWriter::speed_readers_matched() const { return matched_readers(dds_->speed_writer); }

JointStateRelay::JointStateRelay(RobotStateSource& source, const JointStateWriterParams& params)
    : source_(source), writer_(params), queue_(kQueueCapacity) {
  if (!source_.set_sample_listener([this](const RobotState& sample) { enqueue(sample); })) {
    throw std::invalid_argument(std::string("robot.state.source ") + robot_state_origin_name(source_.origin()) +
                                " hands over no samples: nothing to republish on " + params.topic);
  }
  try {
    thread_ = std::thread([this] { loop(); });
  } catch (...) {
    source_.set_sample_listener({});  // no call may reach this half-made relay
    throw;
  }
}

JointStateRelay::~JointStateRelay() {
  source_.set_sample_listener({});  // once it returns, enqueue is not under way and never runs again
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

JointStateRelayCounters JointStateRelay::counters() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

void JointStateRelay::enqueue(const RobotState& sample) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (queued_ == queue_.size()) {  // the writer is far behind: the oldest goes, the newest matter
      first_ = (first_ + 1) % queue_.size();
      --queued_;
      ++counters_.dropped;
    }
    queue_[(first_ + queued_) % queue_.size()] = sample;
    ++queued_;
  }
  wake_.notify_one();
}

void JointStateRelay::loop() {
  for (;;) {
    RobotState sample;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || queued_ > 0; });
      if (stop_) return;
      sample = queue_[first_];
      first_ = (first_ + 1) % queue_.size();
      --queued_;
    }
    publish(sample);
  }
}

template <typename Write>
bool JointStateRelay::write_until_done(const Write& write) {
  for (;;) {
    const WriteOutcome outcome = write();
    const std::lock_guard<std::mutex> lock(mutex_);
    if (outcome == WriteOutcome::written) return true;
    if (outcome == WriteOutcome::refused) {
      ++counters_.refused;
      counters_.last_error = writer_.last_error();
      return false;
    }
    ++counters_.write_waits;
    if (stop_) return false;
  }
}

void JointStateRelay::publish(const RobotState& sample) {
  // The speed fraction first: a camera that takes both in one wake-up has the reading with the state.
  if (!writer_.speed_scaling_topic().empty() && !std::isnan(sample.speed_fraction) &&
      write_until_done([&] { return writer_.write_speed_fraction(sample.speed_fraction); })) {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.speed_published;
  }
  const int64_t stamp_ns = sample.host_time_ns + realtime_minus_steady_ns();
  if (write_until_done([&] { return writer_.write(stamp_ns, sample.q_rad, sample.qd_rad_s); })) {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.published;
  }
}

}  // namespace hrcsense::ros2
