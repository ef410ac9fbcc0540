// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the fuser of a cell with several cameras republishes the live robot state it
// owns as sensor_msgs/JointState on `<ros2.namespace>/joint_states`, and the state's speed
// fraction as std_msgs/Float64 on `<ros2.namespace>/robot_speed_scaling`, which the camera
// processes read with `robot.state.source: ros2` (docs/MULTICAMERA.md, "Robot state"). The
// writer is the reader's mirror (ros2_joint_state.hpp): UR's six joint names after the same
// tf_prefix, the generated message types, QoS the reader matches.
#pragma once

#include "dds/ros2_joint_state.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/types.hpp"

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::ros2 {

/// `<namespace>/joint_states`: where the fuser republishes the robot state.
std::string cell_joint_states_topic(const std::string& node_namespace);
/// `<namespace>/robot_speed_scaling`: where the fuser republishes the robot's speed fraction
/// (0..1, speed_scaling_unit fraction). Not `<namespace>/speed_scaling`: that is hrcsense's own
/// commanded speed scale (ros2_outputs.hpp).
std::string cell_robot_speed_scaling_topic(const std::string& node_namespace);

struct JointStateWriterParams {
  uint32_t domain_id = 0;                          ///< `ros2.domain_id`
  std::string topic = "/hrcsense/joint_states";    ///< ROS 2 name (cell_joint_states_topic)
  std::string tf_prefix;                           ///< before UR's six names (robot.state.ros2.tf_prefix)
  /// ROS 2 name of the std_msgs/Float64 speed fraction (cell_robot_speed_scaling_topic); empty:
  /// none is written.
  std::string speed_scaling_topic;
};

/// What became of one write.
enum class WriteOutcome {
  written,
  timed_out,  ///< a reliable reader had not acknowledged enough: DDS waited 100 ms and gave up
  refused,    ///< a non-finite or out-of-range value, or an error of DDS (last_error() names the topic)
};

/// Writes JointState samples: the six UR joints (ur_joint_names), position and velocity, no
/// effort, header.stamp the sample's time on the shared clock (ROS time), frame_id empty as
/// joint_state_broadcaster writes it; and, when speed_scaling_topic is set, Float64 speed
/// fractions. Reliable, volatile, keep-last 10 (ROS's default QoS, as the driver's own
/// joint_state_broadcaster): the cameras' best-effort readers match it, and so do `ros2 topic
/// echo` and RViz. Not thread-safe: one thread writes.
class JointStateWriter {
 public:
  explicit JointStateWriter(const JointStateWriterParams& params);  ///< throws Ros2Error naming the topic
  ~JointStateWriter();
  JointStateWriter(const JointStateWriter&) = delete;
  JointStateWriter& operator=(const JointStateWriter&) = delete;

  /// Writes one sample; refused, writing nothing, for a non-finite value (the sources reject
  /// those already: this is the last line).
  WriteOutcome write(int64_t stamp_ns, const JointAngles& q_rad, const JointAngles& qd_rad_s);
  /// Writes one speed fraction; refused, writing nothing, outside 0..1 (NaN included: no
  /// reading is not a reading) or without a speed_scaling_topic.
  WriteOutcome write_speed_fraction(double fraction);
  /// Readers matched so far (ros2 readers of the cameras, an echo) on the joint state topic...
  int32_t readers_matched() const;
  /// ...and on the speed scaling topic (0 without one). Both may be called from any thread.
  int32_t speed_readers_matched() const;
  const std::string& topic() const { return params_.topic; }
  const std::string& speed_scaling_topic() const { return params_.speed_scaling_topic; }
  const std::string& last_error() const { return last_error_; }

 private:
  struct Dds;
  WriteOutcome outcome(int32_t ret, const std::string& topic);  // of a dds_write
  JointStateWriterParams params_;
  JointNames names_;
  std::unique_ptr<Dds> dds_;
  std::string last_error_;
};

/// What a relay did with the samples its source accepted.
struct JointStateRelayCounters {
  int64_t published = 0;        ///< JointStates written
  int64_t speed_published = 0;  ///< speed fractions written (samples without one have none)
  int64_t refused = 0;          ///< writes DDS refused, or a non-finite sample
  /// Writes that waited the 100 ms DDS allows for a reliable reader's acknowledgements and were
  /// tried again (a slow or stalled reliable reader, e.g. an echo on a poor link).
  int64_t write_waits = 0;
  /// Accepted samples lost because the writer fell kQueueCapacity samples behind (the oldest
  /// queued one goes first).
  int64_t dropped = 0;
  std::string last_error;
};

/// Republishes each sample a live robot state source accepts, once and in order. The source
/// hands each one over as it accepts it (RobotStateSource::set_sample_listener): the listener
/// only copies it into a queue (short, on the source's receiving thread, under its lock), and
/// the relay's own thread writes it, its speed fraction first when it has one. So a slow DDS
/// write (a reliable reader's acknowledgements awaited) never holds up the source's reception,
/// and a sample is lost only when the writer falls kQueueCapacity samples (8 s at 500 Hz)
/// behind (counted: dropped). A write that timed out waiting for a reliable reader is tried
/// again until it goes or the relay stops. Samples the source rejects (joint limits, jumps, steps
/// back, non-finite: RobotStateHistory's rules) never reach the listener and so are never
/// published; a speed fraction of NaN (the source does not report one) is not written. A source
/// that goes silent publishes nothing more: the cameras' readers then go stale by their own rule
/// (robot_state_stale, or no_robot_state before the first sample).
/// Stamps: the sample's host time, which the live sources take from the steady clock, moved onto
/// the shared clock (realtime_minus_steady_ns).
class JointStateRelay {
 public:
  /// Samples the queue holds (8 s at 500 Hz, 33 s at 125 Hz); made once, at construction.
  static constexpr size_t kQueueCapacity = 4096;

  /// Listens to `source` (which must outlive this) and starts the writing thread. Throws
  /// Ros2Error as the writer, and std::invalid_argument for a source that offers no listener
  /// (fixed, sim, recorded: nothing to relay).
  JointStateRelay(RobotStateSource& source, const JointStateWriterParams& params);
  ~JointStateRelay();  ///< stops listening, then stops and joins the thread (what is queued is not written)
  JointStateRelay(const JointStateRelay&) = delete;
  JointStateRelay& operator=(const JointStateRelay&) = delete;

  JointStateRelayCounters counters() const;
  const std::string& topic() const { return writer_.topic(); }
  const std::string& speed_scaling_topic() const { return writer_.speed_scaling_topic(); }
  int32_t readers_matched() const { return writer_.readers_matched(); }
  int32_t speed_readers_matched() const { return writer_.speed_readers_matched(); }

 private:
  void enqueue(const RobotState& sample);  // the source's thread, its lock held
  void loop();
  void publish(const RobotState& sample);
  /// Repeats `write` while it times out and the relay runs; counts what became of it.
  template <typename Write>
  bool write_until_done(const Write& write);

  RobotStateSource& source_;
  JointStateWriter writer_;
  mutable std::mutex mutex_;  // guards everything below but thread_
  std::condition_variable wake_;
  std::vector<RobotState> queue_;  ///< a ring of kQueueCapacity
  size_t first_ = 0;               ///< the oldest queued sample
  size_t queued_ = 0;
  std::atomic<bool> stop_{false};  ///< set under mutex_ (the wait's predicate), read anywhere
  JointStateRelayCounters counters_;
  std::thread thread_;  // last: starts once everything above is made
};

}  // namespace hrcsense::ros2
