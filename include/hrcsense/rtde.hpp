// SPDX-License-Identifier: Apache-2.0
// hrcsense — a Universal Robots RTDE client (protocol version 2, written from UR's public guide:
// ../shared/specs/ur-rtde.md) as a robot state source. RTDE is not a safety interface and
// hrcsense is not a safety-rated device: the robot's rated stop is its safety input.
#pragma once

#include "hrcsense/clock.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/robot_state_history.hpp"
#include "hrcsense/types.hpp"

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace rtde {

/// Package types (the header's third byte), as UR names them.
enum class PackageType : uint8_t {
  request_protocol_version = 'V',
  get_urcontrol_version = 'v',
  text_message = 'M',
  setup_outputs = 'O',
  setup_inputs = 'I',
  start = 'S',
  pause = 'P',
  data = 'U',
};

/// UR's name of a package type ("DATA_PACKAGE"), or "unknown package type" for others.
const char* package_type_name(uint8_t type);

constexpr size_t kHeaderSize = 3;  ///< uint16 size (whole package) + uint8 type
/// The variables hrcsense requests, in this order.
constexpr const char* kOutputVariables =
    "timestamp,actual_q,actual_qd,robot_mode,safety_mode,speed_scaling,actual_TCP_pose";

// ---- The client's packages (complete, header included).
std::vector<uint8_t> encode_request_protocol_version(uint16_t version);
std::vector<uint8_t> encode_get_urcontrol_version();
/// Protocol 2 layout: double frequency (Hz), then the comma-separated names (≤ 2048 bytes;
/// std::invalid_argument when longer).
std::vector<uint8_t> encode_setup_outputs(double frequency_hz, const std::string& names);
std::vector<uint8_t> encode_start();
std::vector<uint8_t> encode_pause();

// ---- The controller's packages.

/// One package inside a byte buffer (not owned).
struct Frame {
  uint8_t type = 0;
  const uint8_t* payload = nullptr;  ///< after the 3-byte header
  size_t payload_size = 0;
};

enum class SplitStatus {
  frame,      ///< `frame` is complete; `consumed` bytes (its size field) belong to it
  need_more,  ///< the buffer holds part of a package (or less than a header): read more
  malformed,  ///< size field < 3: the stream cannot be framed any more (`error` says so)
};

struct FrameSplit {
  SplitStatus status = SplitStatus::need_more;
  Frame frame;
  size_t consumed = 0;
  std::string error;
};

/// The first package of `data[0, size)`. Never reads past `size`.
FrameSplit split_frame(const uint8_t* data, size_t size);

/// GET_URCONTROL_VERSION's reply.
struct ControllerVersion {
  uint32_t major = 0, minor = 0, bugfix = 0, build = 0;
};

/// A TEXT_MESSAGE (protocol 2 layout). level: 0 exception, 1 error, 2 warning, 3 info.
struct TextMessage {
  std::string message;
  std::string source;
  uint8_t level = 0;
};

/// A CONTROL_PACKAGE_SETUP_OUTPUTS (or _INPUTS) reply.
struct SetupReply {
  uint8_t recipe_id = 0;
  std::vector<std::string> types;  ///< one per requested variable, e.g. "DOUBLE", "NOT_FOUND"
};

/// The variables of a data package hrcsense knows; others are skipped by their type's size.
enum class OutputField : uint8_t { other, timestamp, actual_q, actual_qd, robot_mode, safety_mode,
                                   speed_scaling, actual_tcp_pose };

/// How to decode the output recipe's data packages: each variable's field and byte size.
struct OutputRecipe {
  struct Entry {
    OutputField field = OutputField::other;
    size_t size = 0;  ///< bytes in a data package
  };
  uint8_t id = 0;
  std::vector<Entry> entries;
  size_t payload_size = 0;  ///< 1 (recipe id) + the entries' sizes
};

/// One output data package of hrcsense's recipe (fields the recipe lacks stay as here).
struct DataSample {
  uint8_t recipe_id = 0;
  double timestamp_s = 0.0;  ///< the controller's clock: seconds since it started
  JointAngles q{};           ///< actual_q, rad, base joint first
  JointAngles qd{};          ///< actual_qd, rad/s
  int32_t robot_mode = -1;   ///< -1 no controller ... 7 running
  int32_t safety_mode = 0;   ///< 1 normal, 3 protective stop, 5 safeguard stop, ...
  double speed_scaling = 0.0;
  std::array<double, 6> tcp_pose{};  ///< actual_TCP_pose: x, y, z (m), rotation vector (rad), base frame
};

// Each parser checks the type and that the payload is exactly what the type explains; false
// with `error` naming the package type and the field on anything else.
bool parse_accepted(const Frame& frame, PackageType expected, bool& accepted, std::string& error);
bool parse_controller_version(const Frame& frame, ControllerVersion& out, std::string& error);
bool parse_text_message(const Frame& frame, TextMessage& out, std::string& error);
bool parse_setup_reply(const Frame& frame, PackageType expected, SetupReply& out, std::string& error);
/// The recipe for data packages from a setup reply to the request `names` (comma-separated):
/// false when a variable is NOT_FOUND (naming it), the counts differ, a type is unknown or a
/// variable hrcsense reads has an unexpected type.
bool make_output_recipe(const SetupReply& reply, const std::string& names, OutputRecipe& out,
                        std::string& error);
/// A DATA_PACKAGE of `recipe`: false on another recipe id or a payload of the wrong size.
bool parse_data_package(const Frame& frame, const OutputRecipe& recipe, DataSample& out, std::string& error);

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
  RtdeStatus status() const;

 private:
  struct Connection;
  void run();
  bool session(Connection& connection);  // false: the connection ended (problem recorded)
  bool handshake(Connection& connection);
  void on_data(const rtde::Frame& frame, Connection& connection);
  void on_text(const rtde::Frame& frame);
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

}  // namespace hrcsense
