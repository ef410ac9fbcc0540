// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the measurement writer and reader (measurement_endpoints.hpp).
#include "dds/measurement_endpoints.hpp"

#include "dds/dds_entity.hpp"
#include "hrcsense/clock.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace hrcsense::ros2 {
namespace {

// Samples taken per call of the reader; a full take is followed by another.
constexpr uint32_t kMeasurementTake = 8;

}  // namespace

struct MeasurementSink::Dds {
  ParticipantScope scope;
  dds_entity_t writer = 0;
  explicit Dds(uint32_t domain_id) : scope(domain_id) {}
};

MeasurementSink::MeasurementSink(MeasurementWriterParams params)
    : params_(std::move(params)), topic_(measurement_topic(params_.node_namespace, params_.camera_name)) {
  dds_ = std::make_unique<Dds>(params_.domain_id);
  const std::string name = dds_topic_name(topic_);
  const dds_entity_t topic = dds_->scope.own(
      dds_create_topic(dds_->scope.participant(), &hrcsense_msgs_msg_dds__Measurement__desc, name.c_str(), nullptr, nullptr),
      "DDS topic " + name);
  EndpointQos qos{true, false, 1};
  const int64_t lease_ns = seconds_to_ns(params_.max_frame_gap_periods / params_.nominal_fps);
  qos.deadline_ns = lease_ns;
  qos.liveliness_lease_ns = lease_ns;
  const QosHandle handle(qos);
  dds_->writer = dds_->scope.own(dds_create_writer(dds_->scope.participant(), topic, handle.get(), nullptr),
                                 "DDS writer on " + name);
  out_.camera_name = params_.camera_name;
  out_.nominal_fps = params_.nominal_fps;
  out_.T_base_camera = params_.T_base_camera;
}

MeasurementSink::~MeasurementSink() = default;

void MeasurementSink::header(const RunHeader& header) {
  out_.session = header.session;
  out_.intrinsics = header.filters.intrinsics.width > 0 ? header.filters.intrinsics : header.source.intrinsics;
}

void MeasurementSink::frame(const FrameResult& result) {
  if (failed()) return;
  to_camera_measurement(result, realtime_minus_steady_ns(), out_);
  if (!result.source_frame) {
    // The run's own stop with no new frame (its watchdog, or its end): the fuser hears why at
    // once instead of waiting for the stale rule. It is stamped just after the last frame sent,
    // so that a frame captured before the watchdog fired but delivered after it still counts.
    out_.valid = false;
    out_.reason_code = result.verdict.code;
    out_.reason = result.verdict.reason;
    out_.capture_ns = last_capture_ns_ > 0 ? last_capture_ns_ + 1 : shared_clock_ns();
    out_.links.clear();
    out_.contact = Contact{};
  }
  // What the fuser's added latency is measured against: this camera's capture to its publication.
  if (result.source_frame) {
    out_.latency_us = std::max(out_.latency_us, static_cast<double>(shared_clock_ns() - out_.capture_ns) * 1e-3);
  }
  last_capture_ns_ = out_.capture_ns;
  ++out_.sequence;
  const hrcsense_msgs_msg_dds__Measurement_ msg = measurement_message(out_, params_.base_frame, buffers_);
  const dds_return_t ret = dds_write(dds_->writer, &msg);
  if (ret >= 0) {
    ++written_;
    failed_in_a_row_ = 0;
    return;
  }
  ++failed_writes_;
  if (++failed_in_a_row_ >= 10) {
    failure_ = "measurement: 10 writes in a row refused on " + topic_ + " (" + dds_strretcode(ret) + ")";
  }
}

struct MeasurementReader::Dds {
  ParticipantScope scope;
  std::vector<dds_entity_t> readers;
  dds_entity_t publications = 0;  ///< the built-in DCPSPublication reader: every writer discovered
  dds_entity_t waitset = 0;
  explicit Dds(uint32_t domain_id) : scope(domain_id) {}
};

MeasurementReader::MeasurementReader(uint32_t domain_id, const std::string& node_namespace,
                                     const std::vector<std::string>& camera_names) {
  for (const std::string& name : camera_names) topics_.push_back(measurement_topic(node_namespace, name));
  const std::string probe = measurement_topic(node_namespace, "x");
  measurement_prefix_ = dds_topic_name(probe.substr(0, probe.size() - 1));
  dds_ = std::make_unique<Dds>(domain_id);
  // Not attached to the waitset: discovery is counted when measurements are taken, and a
  // stream of foreign writers must not wake the fuser.
  dds_->publications = dds_->scope.own(
      dds_create_reader(dds_->scope.participant(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr),
      "DDS reader of the built-in DCPSPublication topic");
  dds_->waitset = dds_->scope.own(dds_create_waitset(dds_->scope.participant()), "DDS waitset");
  // Reliable keep-last 8. Reliable, because a camera's last word (the end of its run, its own
  // stop) is sent once: read best-effort, a lost fragment of it left the fuser seeing a stale
  // camera instead of an ended one. Keep-last: the cameras' keep-last 1 writers never wait for
  // the fuser, and a fuser that falls behind reads the newest eight of each camera, never an
  // unbounded backlog. (A reliable reader matches reliable writers only, as hrcsense's are.)
  const QosHandle qos(EndpointQos{true, false, int32_t{kMeasurementTake}});
  for (const std::string& ros_topic : topics_) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic = dds_->scope.own(
        dds_create_topic(dds_->scope.participant(), &hrcsense_msgs_msg_dds__Measurement__desc, name.c_str(), nullptr, nullptr),
        "DDS topic " + name);
    const dds_entity_t reader =
        dds_->scope.own(dds_create_reader(dds_->scope.participant(), topic, qos.get(), nullptr), "DDS reader on " + name);
    dds_->readers.push_back(reader);
    const dds_entity_t condition = check_dds(dds_create_readcondition(reader, DDS_ANY_STATE), "DDS read condition");
    check_dds(dds_waitset_attach(dds_->waitset, condition, condition), "DDS waitset attach");
  }
}

MeasurementReader::~MeasurementReader() = default;

void MeasurementReader::wait(int64_t timeout_ns) {
  dds_waitset_wait(dds_->waitset, nullptr, 0, timeout_ns > 0 ? timeout_ns : 0);
  dds_waitset_set_trigger(dds_->waitset, false);
}

void MeasurementReader::wake() { dds_waitset_set_trigger(dds_->waitset, true); }

int32_t MeasurementReader::writers(size_t i) const {
  dds_subscription_matched_status_t matched{};
  if (dds_get_subscription_matched_status(dds_->readers[i], &matched) != DDS_RETCODE_OK) return 0;
  return static_cast<int32_t>(matched.current_count);
}

void MeasurementReader::take_publications() {
  // Bounded: at most 64 batches a call; what is left waits for the next take().
  for (int batch = 0; batch < 64; ++batch) {
    std::array<void*, kMeasurementTake> samples{};
    std::array<dds_sample_info_t, kMeasurementTake> infos{};
    const dds_return_t n = dds_take(dds_->publications, samples.data(), infos.data(), kMeasurementTake, kMeasurementTake);
    if (n <= 0) break;
    for (size_t i = 0; i < static_cast<size_t>(n); ++i) {
      // A writer is an instance of DCPSPublication: counted once, when first seen (NEW), not
      // again when its QoS changes or it goes.
      if (!infos[i].valid_data || infos[i].view_state != DDS_NEW_VIEW_STATE) continue;
      bool again = false;
      for (size_t j = 0; j < i; ++j) again = again || infos[j].instance_handle == infos[i].instance_handle;
      const auto* writer = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      if (again || writer->topic_name == nullptr) continue;
      const std::string name(writer->topic_name);
      if (name.size() <= measurement_prefix_.size() || name.compare(0, measurement_prefix_.size(), measurement_prefix_) != 0) {
        continue;
      }
      const std::string ros_topic = name.substr(2);  // without "rt"
      if (std::find(topics_.begin(), topics_.end(), ros_topic) != topics_.end()) continue;
      ++unconfigured_publishers_;
      last_unconfigured_topic_ = ros_topic;
    }
    dds_return_loan(dds_->publications, samples.data(), n);
    if (n < static_cast<dds_return_t>(kMeasurementTake)) break;
  }
}

size_t MeasurementReader::take(
    const std::function<void(size_t topic, const CameraMeasurement& m, const std::string& problem)>& received) {
  take_publications();
  size_t count = 0;
  for (size_t t = 0; t < dds_->readers.size(); ++t) {
    for (;;) {
      std::array<void*, kMeasurementTake> samples{};
      std::array<dds_sample_info_t, kMeasurementTake> infos{};
      const dds_return_t n = dds_take(dds_->readers[t], samples.data(), infos.data(), kMeasurementTake, kMeasurementTake);
      if (n <= 0) break;
      for (int32_t i = 0; i < n; ++i) {
        if (!infos[static_cast<size_t>(i)].valid_data) continue;
        const auto& msg = *static_cast<const hrcsense_msgs_msg_dds__Measurement_*>(samples[static_cast<size_t>(i)]);
        const std::string problem = camera_measurement_from(msg, scratch_);
        received(t, scratch_, problem);
        ++count;
      }
      dds_return_loan(dds_->readers[t], samples.data(), n);
      if (n < static_cast<int32_t>(kMeasurementTake)) break;
    }
  }
  return count;
}

}  // namespace hrcsense::ros2
