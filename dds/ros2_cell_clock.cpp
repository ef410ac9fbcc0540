// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the cell clock's publisher and reader (ros2_cell_clock.hpp).
#include "dds/ros2_cell_clock.hpp"

#include "dds/dds_entity.hpp"
#include "dds/ros2_messages.hpp"  // dds_topic_name, stamp_ns, stamp_from_ns, Ros2Error
#include "hrcsense/clock.hpp"

#include <array>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

namespace hrcsense::ros2 {
namespace {

// Latched: reliable, transient-local, keep-last 1 on both sides (a transient-local reader needs a
// transient-local writer, ../shared/specs/ros2-interop.md, "QoS").
constexpr EndpointQos kCellClockQos{true, true, 1};

dds_entity_t cell_clock_dds_topic(ParticipantScope& scope, const std::string& ros_topic) {
  const std::string name = dds_topic_name(ros_topic);
  return scope.own(dds_create_topic(scope.participant(), &builtin_interfaces_msg_dds__Time__desc, name.c_str(), nullptr,
                                    nullptr),
                   "DDS topic " + name);
}

std::string seconds_text(double s) {
  char text[48];
  std::snprintf(text, sizeof text, "%.3f s", s);
  return text;
}

}  // namespace

std::string cell_clock_topic(const std::string& node_namespace) { return node_namespace + "/cell_clock"; }

CellClockEpoch parse_cell_clock(const builtin_interfaces_msg_dds__Time_& msg, int64_t now_realtime_ns) {
  CellClockEpoch out;
  if (msg.nanosec >= 1'000'000'000U) {
    out.error = "nanosec: " + std::to_string(msg.nanosec) + ", not below 10^9";
    return out;
  }
  const int64_t epoch_ns = stamp_ns(msg);
  int64_t offset_ns = 0;  // an overflow (a reader's clock near the ends of int64) is far off too
  const bool overflow = __builtin_sub_overflow(epoch_ns, now_realtime_ns, &offset_ns);
  if (overflow || offset_ns > kCellClockMaxOffsetNs || offset_ns < -kCellClockMaxOffsetNs) {
    out.error = "sec: the epoch " + std::to_string(msg.sec) + " s is " + seconds_text(static_cast<double>(offset_ns) * 1e-9) +
                " from this host's clock, more than a day (clocks not in sync, or not an epoch)";
    return out;
  }
  out.ok = true;
  out.epoch_ns = epoch_ns;
  return out;
}

struct CellClockPublisher::Dds {
  ParticipantScope scope;
  explicit Dds(uint32_t domain_id) : scope(domain_id) {}
};

CellClockPublisher::CellClockPublisher(uint32_t domain_id, const std::string& node_namespace, int64_t epoch_ns)
    : topic_(cell_clock_topic(node_namespace)), dds_(std::make_unique<Dds>(domain_id)) {
  const dds_entity_t topic = cell_clock_dds_topic(dds_->scope, topic_);
  const QosHandle qos(kCellClockQos);
  const dds_entity_t writer = dds_->scope.own(dds_create_writer(dds_->scope.participant(), topic, qos.get(), nullptr),
                                              "DDS writer on " + dds_topic_name(topic_));
  const builtin_interfaces_msg_dds__Time_ msg = stamp_from_ns(epoch_ns);
  check_dds(dds_write(writer, &msg), "DDS write on " + dds_topic_name(topic_));
}

CellClockPublisher::~CellClockPublisher() = default;

int64_t wait_for_cell_clock(uint32_t domain_id, const std::string& node_namespace, double timeout_s,
                            const std::atomic<bool>* stop_requested) {
  const std::string ros_topic = cell_clock_topic(node_namespace);
  const std::string where = ros_topic + " (domain " + std::to_string(domain_id) + ")";
  ParticipantScope scope(domain_id);
  const dds_entity_t topic = cell_clock_dds_topic(scope, ros_topic);
  const QosHandle qos(kCellClockQos);
  const dds_entity_t reader =
      scope.own(dds_create_reader(scope.participant(), topic, qos.get(), nullptr), "DDS reader on " + dds_topic_name(ros_topic));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::string problem;
  for (;;) {
    std::array<void*, 4> samples{};
    std::array<dds_sample_info_t, 4> infos{};
    const int32_t count = dds_take(reader, samples.data(), infos.data(), samples.size(), samples.size());
    bool found = false;
    int64_t epoch_ns = 0;
    for (int32_t i = 0; i < count; ++i) {
      if (!infos[static_cast<size_t>(i)].valid_data) continue;
      const CellClockEpoch read =
          parse_cell_clock(*static_cast<const builtin_interfaces_msg_dds__Time_*>(samples[static_cast<size_t>(i)]),
                           shared_clock_ns());
      if (read.ok) {
        found = true;
        epoch_ns = read.epoch_ns;
      } else {
        problem = read.error;
      }
    }
    if (count > 0) dds_return_loan(reader, samples.data(), count);
    if (found) return epoch_ns;
    if (stop_requested != nullptr && stop_requested->load()) {
      throw Ros2Error(where + ": stopped while waiting for the scene clock's epoch");
    }
    if (std::chrono::steady_clock::now() >= deadline) {
      throw Ros2Error(where + ": no scene clock epoch within " + seconds_text(timeout_s) +
                      (problem.empty() ? std::string(" (is hrcsense fuse running on this domain? or set sim.epoch)")
                                       : "; the last one was refused: " + problem));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

}  // namespace hrcsense::ros2
