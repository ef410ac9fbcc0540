// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the ROS 2 joint state source (ros2_joint_state_source.hpp).
#include "dds/ros2_joint_state_source.hpp"

#include "dds/dds_entity.hpp"

#include "std_msgs.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace hrcsense::ros2 {
namespace {

int64_t wall_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string ms_text(double ms) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", ms);
  return text;
}

// Samples taken per call; a call that fills it is followed by another.
constexpr uint32_t kJointTake = 16;

// Loaned samples of one take from `reader`, returned to it when this goes out of scope.
template <typename T>
class JointLoan {
 public:
  explicit JointLoan(dds_entity_t reader) : reader_(reader) {
    count_ = dds_take(reader_, samples_.data(), infos_.data(), kJointTake, kJointTake);
    if (count_ < 0) count_ = 0;  // a failed take reads as empty; the next wake-up tries again
  }
  JointLoan(const JointLoan&) = delete;
  JointLoan& operator=(const JointLoan&) = delete;
  ~JointLoan() {
    if (count_ > 0) dds_return_loan(reader_, samples_.data(), count_);
  }
  int32_t size() const { return count_; }
  bool valid(int32_t i) const { return infos_[static_cast<size_t>(i)].valid_data; }
  const T& operator[](int32_t i) const { return *static_cast<const T*>(samples_[static_cast<size_t>(i)]); }

 private:
  dds_entity_t reader_;
  std::array<void*, kJointTake> samples_{};
  std::array<dds_sample_info_t, kJointTake> infos_{};
  int32_t count_ = 0;
};

}  // namespace

// The domain's shared participant; the topics, readers and the waitset made here go with this.
struct Ros2JointStateSource::Dds {
  std::unique_ptr<ParticipantScope> scope;
  dds_entity_t joint_reader = 0;
  dds_entity_t speed_reader = 0;  ///< 0: no speed scaling topic
  dds_entity_t waitset = 0;

  dds_entity_t reader(const dds_topic_descriptor_t& type, const std::string& ros_topic, int32_t depth) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic =
        scope->own(dds_create_topic(scope->participant(), &type, name.c_str(), nullptr, nullptr), "DDS topic " + name);
    // Best-effort volatile: matches ROS's default (reliable) writers and best-effort ones alike.
    const QosHandle qos(EndpointQos{false, false, depth});
    return scope->own(dds_create_reader(scope->participant(), topic, qos.get(), nullptr), "DDS reader on " + name);
  }

  void attach(dds_entity_t reader) {
    const dds_entity_t condition = check_dds(dds_create_readcondition(reader, DDS_ANY_STATE), "DDS read condition");
    check_dds(dds_waitset_attach(waitset, condition, condition), "DDS waitset attach");
  }
};

Ros2JointStateSource::Ros2JointStateSource(const Ros2JointStateParams& params, const RunClock& clock)
    : clock_(clock),
      params_(params),
      names_(ur_joint_names(params.tf_prefix)),
      description_(params.topic + " (domain " + std::to_string(params.domain_id) + ")"),
      dds_(std::make_unique<Dds>()) {
  history_.params = params_.history;
  dds_->scope = std::make_unique<ParticipantScope>(params_.domain_id);
  dds_->waitset = dds_->scope->own(dds_create_waitset(dds_->scope->participant()), "DDS waitset");
  dds_->joint_reader = dds_->reader(sensor_msgs_msg_dds__JointState__desc, params_.topic, int32_t{kJointTake});
  dds_->attach(dds_->joint_reader);
  if (!params_.speed_scaling_topic.empty()) {
    dds_->speed_reader = dds_->reader(std_msgs_msg_dds__Float64__desc, params_.speed_scaling_topic, 4);
    dds_->attach(dds_->speed_reader);
  }
  reader_ = std::thread([this] { read_loop(); });
}

Ros2JointStateSource::~Ros2JointStateSource() {
  stop_ = true;
  dds_waitset_set_trigger(dds_->waitset, true);  // the reader's wait returns at once
  reader_.join();
}

void Ros2JointStateSource::read_loop() {
  while (!stop_) {
    // The timeout only bounds a lost wake-up; the trigger ends the wait on destruction.
    dds_waitset_wait(dds_->waitset, nullptr, 0, DDS_MSECS(200));
    if (stop_) break;
    take_joint_states();
    if (dds_->speed_reader != 0) take_speed_scaling();
    dds_subscription_matched_status_t matched{};
    if (dds_get_subscription_matched_status(dds_->joint_reader, &matched) == DDS_RETCODE_OK) {
      const std::lock_guard<std::mutex> lock(mutex_);
      connections_ = matched.total_count;
      disconnects_ = static_cast<int64_t>(matched.total_count) - static_cast<int64_t>(matched.current_count);
    }
  }
}

void Ros2JointStateSource::take_joint_states() {
  for (;;) {  // until the reader is empty: a full take may have left samples behind
    const JointLoan<sensor_msgs_msg_dds__JointState_> taken(dds_->joint_reader);
    for (int32_t i = 0; i < taken.size(); ++i) {
      if (!taken.valid(i)) continue;
      // The parse runs outside the lock: state_at must not wait for it.
      const JointStateSample parsed = parse_joint_state(taken[i], names_);
      const int64_t host_time_ns = host_time_of_stamp(parsed.stamp_ns, wall_clock_ns(), clock_.now_ns());
      const std::lock_guard<std::mutex> lock(mutex_);
      ++received_;
      add_sample(parsed, host_time_ns);
    }
    if (taken.size() < static_cast<int32_t>(kJointTake) || stop_) return;
  }
}

void Ros2JointStateSource::reject(const std::string& topic, const std::string& why) {
  sample_problem_ = topic + ": " + why;
  last_problem_ = sample_problem_;
}

void Ros2JointStateSource::add_sample(const JointStateSample& parsed, int64_t host_time_ns) {
  if (!parsed.ok && !parsed.non_finite) {
    ++malformed_;
    reject(params_.topic, "JointState rejected: " + parsed.error);
    return;
  }
  RobotState sample;
  sample.host_time_ns = host_time_ns;
  sample.q_rad = parsed.q_rad;
  sample.qd_rad_s = parsed.qd_rad_s;
  sample.valid = true;
  sample.origin = RobotStateOrigin::ros2;
  // The speed reading of the sample's time, as state_at would give it: a listener (the fuser's
  // relay) passes it on with the sample.
  sample.speed_fraction = speed_fraction_at(host_time_ns);
  // Built on a rejection only: an accepted sample allocates nothing here.
  const auto stamp_text = [&parsed] {
    return "JointState stamped " + std::to_string(parsed.stamp_ns) + " ns rejected: ";
  };
  const auto max_age_ns = static_cast<int64_t>(history_.params.max_age_s * 1e9);
  if (parsed.ok && !parsed.has_velocity) {
    const int64_t host_step_ns = host_time_ns - reference_.host_time_ns;
    if (!reference_.set || host_step_ns > max_age_ns || host_step_ns < -max_age_ns) {
      // Nothing recent to difference against: this one is the reference for the next.
      reference_ = Reference{true, parsed.stamp_ns, host_time_ns, parsed.q_rad, JointAngles{}};
      return;
    }
    // The stamps' step is the publisher's sampling; the host's, when the stamps stand still.
    const int64_t stamp_step_ns = parsed.stamp_ns - reference_.stamp_ns;
    const int64_t step_ns = stamp_step_ns > 0 ? stamp_step_ns : host_step_ns;
    if (step_ns > 0) {
      const double dt_s = static_cast<double>(step_ns) * 1e-9;
      for (size_t j = 0; j < kJointCount; ++j) {
        const double moved = std::fabs(parsed.q_rad[j] - reference_.q_rad[j]);
        if (!(moved <= std::fabs(reference_.qd_rad_s[j]) * dt_s + history_.params.jump_tolerance_rad)) {
          ++fd_jumps_;
          reject(params_.topic, stamp_text() + "'" + names_[j] + "' (joint " + std::to_string(j + 1) + ") jumped " +
                                    std::to_string(moved) + " rad since the previous sample, further than qd·dt + "
                                    "tolerance");
          return;
        }
      }
      sample.qd_rad_s = finite_difference_rad_s(reference_.q_rad, parsed.q_rad, dt_s);
    }
    // step_ns ≤ 0: not later than the reference; the history rejects it as backwards.
  }
  if (!history_.add(sample)) {
    // A non-finite sample's parser names the joint; every other rejection the history names.
    reject(params_.topic, stamp_text() + (parsed.non_finite ? parsed.error : history_.last_rejection()));
    return;
  }
  reference_ = Reference{true, parsed.stamp_ns, host_time_ns, sample.q_rad, sample.qd_rad_s};
}

void Ros2JointStateSource::take_speed_scaling() {
  const JointLoan<std_msgs_msg_dds__Float64_> taken(dds_->speed_reader);
  if (taken.size() == 0) return;
  const int64_t arrival_ns = clock_.now_ns();
  const std::lock_guard<std::mutex> lock(mutex_);
  for (int32_t i = 0; i < taken.size(); ++i) {
    if (!taken.valid(i)) continue;
    const double value = taken[i].data;
    const double fraction = speed_fraction_from(value, params_.speed_scaling_unit);
    if (std::isnan(fraction)) {
      ++speed_rejected_;
      ++malformed_;
      char text[96];
      const bool percent = params_.speed_scaling_unit == SpeedScalingUnit::percent;
      std::snprintf(text, sizeof text, "data %.6g is no speed scaling in %s (0..%s)", value,
                    percent ? "percent" : "fraction", percent ? "100" : "1");
      reject(params_.speed_scaling_topic, text);
    }
    // A rejected reading is kept as NaN: the one before it no longer holds either.
    speed_[speed_count_ % kSpeedReadings] = SpeedReading{arrival_ns, fraction};
    ++speed_count_;
  }
}

double Ros2JointStateSource::speed_fraction_at(int64_t host_time_ns) const {
  const auto max_age_ns = static_cast<int64_t>(history_.params.max_age_s * 1e9);
  const size_t kept = std::min(speed_count_, kSpeedReadings);
  for (size_t k = 1; k <= kept; ++k) {  // newest first
    const SpeedReading& reading = speed_[(speed_count_ - k) % kSpeedReadings];
    if (reading.arrival_ns > host_time_ns) continue;  // came after the state's time
    return host_time_ns - reading.arrival_ns <= max_age_ns ? reading.fraction
                                                          : std::numeric_limits<double>::quiet_NaN();
  }
  return std::numeric_limits<double>::quiet_NaN();
}

bool Ros2JointStateSource::state_at(int64_t host_time_ns, RobotState& out) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const RobotStateLookup lookup = history_.at(host_time_ns);
  out = lookup.state;
  out.origin = RobotStateOrigin::ros2;
  if (lookup.state.valid) {
    out.speed_fraction = speed_fraction_at(host_time_ns);
    lookup_error_.clear();
    return true;
  }
  if (lookup.code == ReasonCode::robot_state_stale) {
    lookup_error_ = "ros2 " + description_ + ": newest joint state " + ms_text(lookup.age_ms) + " old (max " +
                    ms_text(history_.params.max_age_s * 1e3) + ")" +
                    (connections_ > disconnects_ ? ": the publisher is matched but silent"
                                                 : ": no publisher matched (it went away)");
  } else {
    lookup_error_ = "ros2 " + description_ + ": no joint state accepted";
  }
  // What was received instead is why; nothing at all is said as such.
  if (!sample_problem_.empty()) {
    lookup_error_ += "; last problem: " + sample_problem_;
  } else if (lookup.code == ReasonCode::no_robot_state) {
    lookup_error_ += received_ > 0 ? "; waiting for a second JointState (no velocities: finite differences)"
                                   : "; no JointState received (is the driver running, in this domain?)";
  }
  last_problem_ = lookup_error_;
  return false;
}

std::string Ros2JointStateSource::error() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return lookup_error_;
}

RobotStateStats Ros2JointStateSource::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  RobotStateStats stats;
  stats.samples = history_.counts();
  stats.samples.rejected_jump += fd_jumps_;
  stats.connections = connections_;
  stats.disconnects = disconnects_;
  stats.malformed = malformed_;
  stats.last_problem = last_problem_;
  return stats;
}

bool Ros2JointStateSource::set_sample_listener(RobotStateListener listener) {
  const std::lock_guard<std::mutex> lock(mutex_);  // add_sample runs under it: no call is under way now
  history_.listener = std::move(listener);
  return true;
}

int64_t Ros2JointStateSource::speed_readings_rejected() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return speed_rejected_;
}

}  // namespace hrcsense::ros2
