// SPDX-License-Identifier: Apache-2.0
// hrcsense — a source of robot joint states: one of the four one-level virtual interfaces
// (source.hpp says which). `fixed` (robot.joints_rad) is here; the live ones (RTDE, UDP JSON, ROS 2),
// the simulator's scripted arm and the states recorded in a bag implement the same interface.
#pragma once

#include "hrcsense/robot_state_history.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <string>

namespace hrcsense {

/// `robot.state.source` as a name: fixed, sim, rtde, udp_json, recorded, ros2.
const char* robot_state_origin_name(RobotStateOrigin origin);

/// UR's robot_mode as a snake_case name: no_controller (-1), disconnected, confirm_safety,
/// booting, power_off, power_on, idle, backdrive, running (7), updating_firmware (8);
/// "unknown" for other values.
const char* robot_mode_name(int32_t robot_mode);
/// UR's safety_mode as a snake_case name: normal (1), reduced, protective_stop (3), recovery,
/// safeguard_stop (5), system_emergency_stop, robot_emergency_stop, violation, fault (9);
/// "unknown" for other values (newer software has more).
const char* safety_mode_name(int32_t safety_mode);
/// The controller reports its arm running (robot_mode 7).
bool robot_running(const RobotStatus& status);
/// The controller reports a protective stop (safety_mode 3) or a safeguard stop (5).
bool in_protective_stop(const RobotStatus& status);
/// Both statuses are known and their robot_mode or safety_mode differ.
bool robot_mode_changed(const RobotStatus& before, const RobotStatus& after);

/// The controller's status over the frames of a run (FrameResult::robot_state.status), for the
/// summary. Frames without a known status (other sources, no valid state) count in none.
struct RobotStatusCounts {
  int64_t frames_reported = 0;         ///< frames with a known status
  int64_t frames_not_running = 0;      ///< robot_mode other than running
  int64_t frames_protective_stop = 0;  ///< safety_mode protective stop or safeguard stop
  int64_t mode_changes = 0;            ///< robot_mode or safety_mode differs from the last frame that had a status
  int64_t frames_tcp_pose_mismatch = 0;  ///< RobotStatus::tcp_pose_mismatch
  RobotStatus last;                    ///< the last known status (for mode_changes)

  /// Counts one frame's status.
  void add(const RobotStatus& status);
};

/// What a robot state source says about itself over a run (the summary's counters).
struct RobotStateStats {
  RobotStateCounts samples;   ///< samples accepted and rejected (RobotStateHistory)
  int64_t connections = 0;    ///< connections made, reconnections included (live sources)
  int64_t disconnects = 0;    ///< connections lost or closed by the peer
  int64_t malformed = 0;      ///< packets or datagrams rejected as malformed
  std::string last_problem;   ///< the last problem, for people; empty when none
};

/// Delivers the robot's joint state for the frames of a run.
class RobotStateSource {
 public:
  virtual ~RobotStateSource() = default;
  virtual RobotStateOrigin origin() const = 0;
  /// The state at `host_time_ns` (the frame's time on the host's monotonic clock) into `out`.
  /// Returns false, with out.valid false, when there is none; error() may say why.
  virtual bool state_at(int64_t host_time_ns, RobotState& out) = 0;
  virtual std::string error() const { return {}; }
  /// Counters so far; thread-safe (the summary reads them while the source may still run).
  virtual RobotStateStats stats() const { return {}; }
  /// From now on `listener` is called with each sample the source accepts, as it accepts it:
  /// on the source's receiving thread, in order, under its lock (RobotStateHistory::listener
  /// says what the listener may do). An empty listener ends the calls: once this returns, no
  /// call is under way and none follows. Thread-safe. False, and never called, for a source
  /// that receives no samples (fixed, sim, recorded): the default.
  virtual bool set_sample_listener(RobotStateListener /*listener*/) { return false; }
};

/// A valid state with the joint angles `q_rad`, zero velocity, origin `fixed`, at any time.
RobotState fixed_robot_state(const JointAngles& q_rad);

/// `robot.state.source: fixed`: the arm never moves; every frame gets the same joints
/// (robot.joints_rad), stamped with the frame's own host time.
class FixedRobotState final : public RobotStateSource {
 public:
  explicit FixedRobotState(const JointAngles& q_rad) : state_(fixed_robot_state(q_rad)) {}
  RobotStateOrigin origin() const override { return RobotStateOrigin::fixed; }
  bool state_at(int64_t host_time_ns, RobotState& out) override {
    out = state_;
    out.host_time_ns = host_time_ns;
    return true;
  }

 private:
  RobotState state_;
};

}  // namespace hrcsense
