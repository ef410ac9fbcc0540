// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — small helpers over Cyclone DDS's C API: an owning entity handle, QoS as a
// value, and return codes as exceptions naming what failed.
#pragma once

#include "dds/ros2_messages.hpp"

#include <dds/dds.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense::ros2 {

/// Throws Ros2Error "`what`: <Cyclone's text>" when `ret` is a DDS error; returns it otherwise.
inline dds_return_t check_dds(dds_return_t ret, const std::string& what) {
  if (ret < 0) throw Ros2Error(what + ": " + dds_strretcode(ret));
  return ret;
}

/// Owns one DDS entity (a participant owns its topics, readers, writers, waitsets).
class DdsEntity {
 public:
  DdsEntity() = default;
  explicit DdsEntity(dds_entity_t entity) : entity_(entity) {}
  DdsEntity(const DdsEntity&) = delete;
  DdsEntity& operator=(const DdsEntity&) = delete;
  DdsEntity(DdsEntity&& other) noexcept : entity_(std::exchange(other.entity_, 0)) {}
  DdsEntity& operator=(DdsEntity&& other) noexcept {
    std::swap(entity_, other.entity_);
    return *this;
  }
  ~DdsEntity() {
    if (entity_ > 0) dds_delete(entity_);
  }
  dds_entity_t get() const { return entity_; }

 private:
  dds_entity_t entity_ = 0;
};

/// The process's DDS participant on `domain_id`, shared: the ROS 2 camera source, the outputs
/// and the joint-state reader all join a domain through here, so a process is one participant
/// per domain (one entry in discovery, one set of sockets), deleted with its last user. Cyclone
/// reads its configuration (CYCLONEDDS_URI) when the first one is made; hrcsense never
/// overrides it. Thread-safe; throws Ros2Error naming the domain when it cannot be made.
std::shared_ptr<const DdsEntity> domain_participant(uint32_t domain_id);

/// What one user made on a shared participant (topics, readers, writers, waitsets): deleted,
/// newest first, when this goes, while the participant lives on for its other users. Holds the
/// participant, so it outlives everything made on it here.
class ParticipantScope {
 public:
  explicit ParticipantScope(uint32_t domain_id) : participant_(domain_participant(domain_id)) {}
  ParticipantScope(const ParticipantScope&) = delete;
  ParticipantScope& operator=(const ParticipantScope&) = delete;
  ~ParticipantScope() {
    for (auto it = owned_.rbegin(); it != owned_.rend(); ++it) dds_delete(*it);
  }
  dds_entity_t participant() const { return participant_->get(); }
  /// Keeps `entity` (a DDS return code < 0 throws Ros2Error with `what`) and returns it.
  dds_entity_t own(dds_return_t entity, const std::string& what) {
    owned_.push_back(check_dds(entity, what));
    return owned_.back();
  }

 private:
  std::shared_ptr<const DdsEntity> participant_;
  std::vector<dds_entity_t> owned_;
};

/// The QoS a ROS 2 endpoint is given here (../shared/specs/ros2-interop.md, "QoS").
struct EndpointQos {
  bool reliable = false;
  bool transient_local = false;
  int32_t depth = 1;  ///< keep-last depth
  /// DEADLINE: a writer offers a sample at least this often, a reader requests one (a reader
  /// requesting a shorter deadline than the writer offers does not match it), ns; 0: off
  /// (infinite, DDS's default).
  int64_t deadline_ns = 0;
  /// LIVELINESS automatic with this lease, ns: the endpoint counts as alive while its
  /// participant runs (a reader learns within a lease that a process died); 0: off (infinite).
  int64_t liveliness_lease_ns = 0;
};

/// A dds_qos_t for `qos`, deleted with the returned holder.
class QosHandle {
 public:
  explicit QosHandle(const EndpointQos& qos) : qos_(dds_create_qos()) {
    dds_qset_reliability(qos_, qos.reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_MSECS(100));
    dds_qset_durability(qos_, qos.transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos_, DDS_HISTORY_KEEP_LAST, qos.depth);
    if (qos.deadline_ns > 0) dds_qset_deadline(qos_, qos.deadline_ns);
    if (qos.liveliness_lease_ns > 0) dds_qset_liveliness(qos_, DDS_LIVELINESS_AUTOMATIC, qos.liveliness_lease_ns);
  }
  QosHandle(const QosHandle&) = delete;
  QosHandle& operator=(const QosHandle&) = delete;
  ~QosHandle() { dds_delete_qos(qos_); }
  const dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

}  // namespace hrcsense::ros2
