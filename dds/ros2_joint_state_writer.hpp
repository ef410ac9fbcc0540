// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the fuser of a cell with several cameras republishes the live robot state it
// owns as sensor_msgs/JointState on `<ros2.namespace>/joint_states`, which the camera processes
// read with `robot.state.source: ros2` (docs/MULTICAMERA.md, "Robot state"). The writer is the
// reader's mirror (ros2_joint_state.hpp): UR's six joint names after the same tf_prefix, the
// generated sensor_msgs type, QoS the reader matches.
#pragma once

#include "dds/ros2_joint_state.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/types.hpp"

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace hrcsense::ros2 {

/// `<namespace>/joint_states`: where the fuser republishes the robot state.
std::string cell_joint_states_topic(const std::string& node_namespace);

struct JointStateWriterParams {
  uint32_t domain_id = 0;                          ///< `ros2.domain_id`
  std::string topic = "/hrcsense/joint_states";    ///< ROS 2 name (cell_joint_states_topic)
  std::string tf_prefix;                           ///< before UR's six names (robot.state.ros2.tf_prefix)
};

/// Writes JointState samples: the six UR joints (ur_joint_names), position and velocity, no
/// effort, header.stamp the sample's time on the shared clock (ROS time), frame_id empty as
/// joint_state_broadcaster writes it. Reliable, volatile, keep-last 10 (ROS's default QoS, as
/// the driver's own joint_state_broadcaster): the cameras' best-effort readers match it, and so
/// do `ros2 topic echo` and RViz. Not thread-safe: one thread writes.
class JointStateWriter {
 public:
  explicit JointStateWriter(const JointStateWriterParams& params);  ///< throws Ros2Error naming the topic
  ~JointStateWriter();
  JointStateWriter(const JointStateWriter&) = delete;
  JointStateWriter& operator=(const JointStateWriter&) = delete;

  /// Writes one sample; false, writing nothing, for a non-finite value (the sources reject those
  /// already: this is the last line) or a write DDS refuses (last_error() names the topic).
  bool write(int64_t stamp_ns, const JointAngles& q_rad, const JointAngles& qd_rad_s);
  /// Readers matched so far (ros2 readers of the cameras, an echo).
  int32_t readers_matched() const;
  const std::string& topic() const { return params_.topic; }
  const std::string& last_error() const { return last_error_; }

 private:
  struct Dds;
  JointStateWriterParams params_;
  JointNames names_;
  std::unique_ptr<Dds> dds_;
  std::string last_error_;
};

/// What a relay did: samples republished, and those it did not write.
struct JointStateRelayCounters {
  int64_t published = 0;
  int64_t refused = 0;    ///< writes DDS refused, or a non-finite sample
  std::string last_error;
};

/// Republishes each sample a live robot state source accepted: a thread looks at the source
/// every `poll_s` (1 ms: every sample of a 500 Hz e-Series arrives in its own look; one that a
/// newer sample replaced within a look is skipped, never the newest) and writes its newest
/// accepted sample, read back at that sample's own time, so that what goes out is the sample
/// (never an interpolation or an extrapolation). Samples the source rejected (joint limits,
/// jumps, steps back, non-finite: RobotStateHistory's rules) never reach its history and so are
/// never published. A source that goes silent publishes nothing more: the cameras' readers then
/// go stale by their own rule (robot_state_stale, or no_robot_state before the first sample).
/// Stamps: the source's host time (`clock`, the steady clock the source stamps with) moved onto
/// the shared clock (realtime_minus_steady_ns).
class JointStateRelay {
 public:
  /// Starts the thread; `source` and `clock` must outlive this. Throws Ros2Error as the writer.
  JointStateRelay(RobotStateSource& source, const RunClock& clock, const JointStateWriterParams& params,
                  double poll_s = 0.001);
  ~JointStateRelay();  ///< stops and joins the thread
  JointStateRelay(const JointStateRelay&) = delete;
  JointStateRelay& operator=(const JointStateRelay&) = delete;

  JointStateRelayCounters counters() const;
  const std::string& topic() const { return writer_.topic(); }

 private:
  void loop();
  void relay_newest();

  RobotStateSource& source_;
  const RunClock& clock_;
  JointStateWriter writer_;
  int64_t poll_ns_;
  int64_t last_sample_ns_ = 0;  ///< the newest sample's host time already published (relay thread only)
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;    // guards counters_
  JointStateRelayCounters counters_;
  std::thread thread_;          // last: starts once everything above is made
};

}  // namespace hrcsense::ros2
