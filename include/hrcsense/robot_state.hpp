// SPDX-License-Identifier: Apache-2.0
// hrcsense — a source of robot joint states: the third one-level interface beside Source and
// Sink. `fixed` (robot.joints_rad) is here; live ones (RTDE, UDP JSON) and the simulator's
// scripted arm implement the same interface.
#pragma once

#include "hrcsense/robot_state_history.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <string>

namespace hrcsense {

/// `robot.state.source` as a name: fixed, sim, rtde, udp_json, recorded.
const char* robot_state_origin_name(RobotStateOrigin origin);

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
