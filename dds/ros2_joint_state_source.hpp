// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — `robot.state.source: ros2`: a ROS 2 driver's sensor_msgs/JointState (and its
// speed scaling) read over Cyclone DDS as the robot's joint state, no ROS installation needed
// (docs/ROS2.md, "Joint states in").
#pragma once

#include "dds/ros2_joint_state.hpp"
#include "dds/ros2_messages.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/robot_state_history.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace hrcsense::ros2 {

struct Ros2JointStateParams {
  std::string topic = "/joint_states";  ///< ROS 2 name of the JointState topic (DDS: "rt" + it)
  std::string tf_prefix;                ///< before UR's six joint names (ur_joint_names)
  /// std_msgs/Float64 speed scaling of the driver; empty: not read (speed_fraction NaN).
  std::string speed_scaling_topic = "/speed_scaling_state_broadcaster/speed_scaling";
  SpeedScalingUnit speed_scaling_unit = SpeedScalingUnit::percent;
  uint32_t domain_id = 0;               ///< the DDS domain (ROS_DOMAIN_ID)
  RobotStateHistoryParams history;      ///< max_age_s, jump tolerance, the arm's limits
};

/// Reads JointState on a reader thread that takes every sample as it comes (a waitset, woken at
/// once on destruction), keeps the six UR joints (matched by name after tf_prefix) in a
/// RobotStateHistory, and answers state_at from it as the other live sources do.
///
/// - Stamps (ROS time: the publisher's wall clock) go to the host's monotonic clock, read from
///   `clock`, by host_time_of_stamp: within a second of this host's wall clock through the
///   offset of the two clocks, else (clocks not in sync, simulated time) the arrival time.
/// - Velocities: the message's, when it has them; else finite differences from the previous
///   accepted sample over the stamps' step (the host times' when the stamps do not advance).
///   A sample with nothing to difference against (the first, or the first after a gap longer
///   than max_age_s) is kept only as the reference for the next one: the state becomes valid
///   with the second sample, never with a made-up zero velocity. Such samples are tested for
///   jumps here against the previous sample's velocity (|Δq| ≤ |qd_prev|·dt + tolerance), as a
///   finite difference would pass the history's own test by construction.
/// - Speed scaling (when speed_scaling_topic is set): converted by speed_fraction_from; it has
///   no stamp, so its arrival time counts: a state's speed_fraction is the newest reading that
///   arrived by the state's time and is at most max_age_s older than it, else NaN. A value that
///   is no reading (non-finite, out of range) is rejected, counted, and ends the previous one.
/// - Counters: stats().malformed counts malformed JointStates and rejected speed readings;
///   stats().samples the history's (a finite-difference jump in rejected_jump); connections and
///   disconnects, publishers matched and gone. last_problem and error() name the topic.
/// Readers are best-effort and volatile (they match the reliable writers of ROS's default QoS and
/// best-effort ones alike), keep-last 16 for joint states so a 500 Hz stream loses nothing
/// between two takes. All members are thread-safe.
class Ros2JointStateSource final : public RobotStateSource {
 public:
  /// Joins the domain (ParticipantScope) and starts the reader; does not wait for a publisher.
  /// Throws Ros2Error naming the topic when a DDS entity cannot be made or a name is not absolute.
  /// `clock` must outlive this object.
  Ros2JointStateSource(const Ros2JointStateParams& params, const RunClock& clock);
  ~Ros2JointStateSource() override;
  Ros2JointStateSource(const Ros2JointStateSource&) = delete;
  Ros2JointStateSource& operator=(const Ros2JointStateSource&) = delete;

  RobotStateOrigin origin() const override { return RobotStateOrigin::ros2; }
  /// The history's state at `host_time_ns` (on `clock`) with the speed reading of that time;
  /// false, with out.valid false, before the first usable sample or when the newest is older
  /// than max_age_s.
  bool state_at(int64_t host_time_ns, RobotState& out) override;
  /// Why the last state_at failed, naming the topic and domain ("" after a valid one).
  std::string error() const override;
  RobotStateStats stats() const override;
  /// Each accepted JointState's state, as the reader thread accepts it, with the speed reading
  /// of its time (speed_fraction, as state_at gives it).
  bool set_sample_listener(RobotStateListener listener) override;
  /// Speed scaling messages rejected (non-finite, out of range); also in stats().malformed.
  int64_t speed_readings_rejected() const;
  /// "/joint_states (domain 0)": how messages name this source.
  const std::string& description() const { return description_; }

 private:
  struct Dds;
  struct Reference {  ///< the previous accepted sample, for finite differences
    bool set = false;
    int64_t stamp_ns = 0;
    int64_t host_time_ns = 0;
    JointAngles q_rad{};
    JointAngles qd_rad_s{};
  };
  struct SpeedReading {
    int64_t arrival_ns = 0;
    double fraction = 0.0;  ///< NaN: a rejected reading, no reading from then on
  };
  static constexpr size_t kSpeedReadings = 16;

  void read_loop();
  void take_joint_states();
  void take_speed_scaling();
  void add_sample(const JointStateSample& parsed, int64_t host_time_ns);  // mutex_ held
  void reject(const std::string& topic, const std::string& why);          // mutex_ held
  double speed_fraction_at(int64_t host_time_ns) const;                   // mutex_ held

  const RunClock& clock_;
  Ros2JointStateParams params_;
  JointNames names_;
  std::string description_;
  std::unique_ptr<Dds> dds_;
  std::atomic<bool> stop_{false};

  mutable std::mutex mutex_;  // guards everything below
  RobotStateHistory history_;
  Reference reference_;
  std::array<SpeedReading, kSpeedReadings> speed_{};
  size_t speed_count_ = 0;     ///< readings in speed_ (the newest at speed_count_ − 1, mod size)
  int64_t received_ = 0;       ///< JointStates taken, whatever became of them
  int64_t malformed_ = 0;
  int64_t speed_rejected_ = 0;
  int64_t fd_jumps_ = 0;       ///< finite-difference samples rejected as jumps
  int64_t connections_ = 0;
  int64_t disconnects_ = 0;
  std::string sample_problem_; ///< the latest rejected message
  std::string last_problem_;   ///< the latest problem: a message's or a lookup's
  std::string lookup_error_;   ///< why the last state_at failed

  std::thread reader_;  // last: started once everything above exists
};

}  // namespace hrcsense::ros2
