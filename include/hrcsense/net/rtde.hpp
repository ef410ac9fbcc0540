// SPDX-License-Identifier: Apache-2.0
// hrcsense — a Universal Robots RTDE client (protocol version 2, written from UR's public guide:
// ../shared/specs/ur-rtde.md) as a robot state source (RtdeRobotState), and the opt-in writer of
// the verdict's speed scale to the controller's inputs (RtdeLinkSink, `link.rtde.*`). RTDE is
// not a safety interface and hrcsense is not a safety-rated device: the robot's rated stop is
// its safety input.
#pragma once

#include "hrcsense/clock.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/robot_state_history.hpp"
#include "hrcsense/sink.hpp"
#include "hrcsense/types.hpp"

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace rtde {

/// GET_URCONTROL_VERSION's reply.
struct ControllerVersion {
  uint32_t major = 0, minor = 0, bugfix = 0, build = 0;
};

struct Package;  // the wire codec's view of one package (src/net/rtde_protocol.hpp)

}  // namespace rtde

/// RtdeRobotState's parameters (robot.state.* in a configuration).
struct RtdeParams {
  std::string host;               ///< the controller's address or name
  int port = 30004;               ///< RTDE's port
  double frequency_hz = 125.0;    ///< requested output rate; CB3 controllers (major < 5) get ≤ 125
  RobotStateHistoryParams history;
  /// No byte for this long (run clock) on a connection: it is dead and is closed. Also the
  /// limit for each handshake reply.
  double receive_timeout_s = 1.0;
  double connect_timeout_s = 1.0;  ///< TCP connect, real time
  double backoff_initial_s = 0.1;  ///< first wait before reconnecting (run clock), doubling...
  double backoff_max_s = 5.0;      ///< ...up to this
  /// The arm whose forward kinematics each sample's actual_TCP_pose is checked against
  /// (robot.model); none (robot.model points): no check.
  std::optional<RobotDescription> arm;
  TcpPoseCheckParams tcp_check;
};

/// What the RTDE client knows of the controller, beyond RobotStateStats.
struct RtdeStatus {
  bool streaming = false;             ///< set up and started; data packages are read
  rtde::ControllerVersion controller; ///< of the last handshake (zeros before one)
  double frequency_hz = 0.0;          ///< the rate requested on the last setup
  bool frequency_clamped = false;     ///< a CB3 controller: frequency_hz lowered to 125
  int32_t robot_mode = -1;            ///< of the newest data package (not part of the verdict)
  int32_t safety_mode = 0;            ///< of the newest data package (not part of the verdict)
  double speed_scaling = 0.0;         ///< of the newest data package
  double target_speed_fraction = std::numeric_limits<double>::quiet_NaN();  ///< the slider, of the newest data package
  int64_t data_packages = 0;          ///< DATA_PACKAGEs read, good or not
  int64_t skipped_packages = 0;       ///< unknown or unexpected package types, skipped by size
  int64_t text_messages = 0;          ///< TEXT_MESSAGEs from the controller
  int64_t tcp_pose_mismatches = 0;    ///< data packages whose actual_TCP_pose failed the check
  std::string last_text_message;      ///< "source: message"
};

/// `robot.state.source: rtde`. A reader thread connects (TCP_NODELAY), checks protocol 2,
/// reads the controller version, sets up the outputs (kOutputVariables at frequency_hz), starts
/// and drains the socket, putting each sample into a RobotStateHistory on the host clock (the
/// controller's timestamp through a SenderClockMap, arrival times from `clock`). A lost or bad
/// connection is closed, the history cleared (no valid state until new data), and the thread
/// reconnects with exponential back-off, requesting the same frequency. Bad packages are
/// counted in stats() and never crash or stop the thread. Each sample carries the controller's
/// RobotStatus; with an arm, its actual_TCP_pose is checked against the forward kinematics of
/// its actual_q (check_tcp_pose, the reference taken afresh on each connection), and the
/// start of a mismatch is stats().last_problem. Thread-safe.
class RtdeRobotState final : public RobotStateSource {
 public:
  /// Starts the reader thread; `clock` must outlive this object.
  RtdeRobotState(RtdeParams params, RunClock& clock);
  /// Stops and joins the reader thread (within a poll slice: tens of ms).
  ~RtdeRobotState() override;
  RtdeRobotState(const RtdeRobotState&) = delete;
  RtdeRobotState& operator=(const RtdeRobotState&) = delete;

  RobotStateOrigin origin() const override { return RobotStateOrigin::rtde; }
  bool state_at(int64_t host_time_ns, RobotState& out) override;
  /// Why there is no data (connection refused, protocol 1 only, NOT_FOUND...); empty while
  /// streaming.
  std::string error() const override;
  RobotStateStats stats() const override;
  /// Each accepted data package's state, as the reader thread accepts it.
  bool set_sample_listener(RobotStateListener listener) override;
  RtdeStatus status() const;

 private:
  struct Connection;
  void run();
  bool session(Connection& connection);  // false: the connection ended (problem recorded)
  bool handshake(Connection& connection);
  void on_data(const rtde::Package& frame, Connection& connection);
  void on_text(const rtde::Package& frame);
  void problem(const std::string& what, bool malformed);
  /// Keeps why the last connection ended (error() and stats().last_problem); mutex_ held.
  void record_error_locked(const std::string& error);

  const RtdeParams params_;
  RunClock& clock_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;     ///< guards everything below
  RobotStateHistory history_;
  RobotStateStats stats_;
  RtdeStatus status_;
  std::string error_;
  std::thread thread_;  // last: started once everything above exists
};

/// RtdeLinkSink's parameters (`link.rtde.*`, robot.state.host/port; docs/SAFETY.md).
struct RtdeLinkParams {
  std::string host;  ///< `robot.state.host`
  int port = 30004;  ///< `robot.state.port`
  /// `link.rtde.write`: speed_slider (speed_slider_mask and speed_slider_fraction) or
  /// input_register (input_double_register_N, for a URScript to read).
  enum class Mode { speed_slider, input_register } mode = Mode::input_register;
  int register_index = 24;        ///< `link.rtde.register`: N, 24..47 (0..23 belong to fieldbus adapters)
  double min_speed_slider = 0.01; ///< `link.rtde.min_speed_slider`: the slider never goes below this (0, 1]
  /// `link.heartbeat_hz`: while no frame comes for one period, the stop value is written at
  /// this rate (a URScript watchdog sees writes, but only stops); no frame's value is written
  /// once it is older than one period, on a new connection neither.
  double heartbeat_hz = 20.0;
  double connect_timeout_s = 1.0;   ///< TCP connect, real time
  double receive_timeout_s = 1.0;   ///< each handshake reply, real time
  double backoff_initial_s = 0.1;   ///< first wait before reconnecting, doubling...
  double backoff_max_s = 2.0;       ///< ...up to this
  /// How long, in real time, the writer waits at most before it looks at the clock and the
  /// socket again, ns (bounds a heartbeat's lateness on a fake clock).
  int64_t max_wait_ns = 2'000'000;
};

/// What RtdeLinkSink has done, for the log and the tests.
struct RtdeLinkCounters {
  int64_t connections = 0;    ///< TCP connections made
  int64_t streaming = 0;      ///< of those, set up and started (inputs accepted)
  int64_t disconnects = 0;    ///< connections lost or closed after a problem
  int64_t refusals = 0;       ///< setups refused: IN_USE, NOT_FOUND, wrong type, start refused
  int64_t malformed = 0;      ///< controller packages that could not be framed or parsed
  int64_t writes = 0;         ///< input DATA_PACKAGEs sent
  int64_t stop_writes = 0;    ///< of those, the stop value (stop verdicts, heartbeats, the final stop)
  bool connected = false;     ///< streaming now
  double last_value = -1.0;   ///< the last value written (fraction or register); -1: none
  std::string last_problem;   ///< names link.rtde.write and the controller; empty when none
};

/// `link.rtde.write`: the verdict's speed scale written to the controller over its own RTDE
/// connection (robot.state.host:port), one input DATA_PACKAGE per frame. speed_slider writes
/// speed_slider_mask 1 and speed_slider_fraction = speed_scale clamped to
/// [min_speed_slider, 1] (never 0: a slider set to 0 and then to another value has caused
/// protective stops; a stop is min_speed_slider, so the slider alone never stops the robot);
/// input_register writes input_double_register_N = speed_scale, 0 for stop.
/// frame() only hands the value to a writer thread and returns (it never waits for the
/// network); the writer connects, sets up the inputs (an IN_USE reply is a refusal naming the
/// input and link.rtde.write), starts, writes the newest value, drains what the controller
/// sends (text messages; anything unparseable is counted and ends the connection), and after a
/// lost connection reconnects with back-off. No value other than the stop value is ever written
/// once its frame is more than one heartbeat period old (on `clock`): a new connection starts
/// with the newest value only when its frame came at most one period ago, else with the stop
/// value (the next frame's value follows as usual); while no frame comes for one period it
/// writes the stop value at the heartbeat rate. summary() and the destructor write a final
/// stop (the destructor waits for a connection attempt under way, at most the connect and
/// receive timeouts, not for a writer that is backing off).
class RtdeLinkSink final : public Sink {
 public:
  /// Starts the writer thread; `clock` must outlive the sink. std::invalid_argument naming the
  /// key for a register outside 24..47, a slider minimum outside (0, 1] or a non-positive rate.
  RtdeLinkSink(RtdeLinkParams params, const RunClock& clock);
  ~RtdeLinkSink() override;
  RtdeLinkSink(const RtdeLinkSink&) = delete;
  RtdeLinkSink& operator=(const RtdeLinkSink&) = delete;

  void header(const RunHeader&) override {}
  void frame(const FrameResult& result) override;
  void summary(const RunSummary& summary) override;

  RtdeLinkCounters counters() const;
  /// The value a verdict is written as: the slider fraction or the register value.
  double value_for(VerdictState state, float speed_scale) const;
  /// The input names set up, comma-separated (e.g. "input_double_register_24").
  const std::string& input_names() const { return names_; }

 private:
  struct Connection;
  void run();
  bool connect_and_stream();            // false: no connection, or it was never set up
  bool setup(Connection& connection);   // false: refused or failed (counted, problem kept)
  void stream(Connection& connection);  // until the connection ends or the final stop is written
  bool write(Connection& connection, double value, bool stop_value);
  bool drain(Connection& connection);   // reads what the controller sent; false: the connection ended
  void problem_locked(const std::string& what);

  const RtdeLinkParams params_;
  const RunClock& clock_;
  std::string names_;
  std::vector<std::string> types_;
  int64_t period_ns_ = 0;
  std::atomic<bool> stop_{false};

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  bool pending_ = false;        ///< a frame's value not yet written
  double pending_value_ = 0.0;
  bool pending_stop_ = true;
  bool have_value_ = false;     ///< a frame came (its value starts a new connection while at most one period old)
  int64_t last_frame_ns_ = 0;   ///< clock time of the last frame() (or of construction)
  bool final_requested_ = false;
  bool final_written_ = false;
  bool attempting_ = false;     ///< connecting, setting up or streaming (the destructor waits for it)
  RtdeLinkCounters counters_;

  std::thread writer_;  // last: started once everything above exists
};

}  // namespace hrcsense
