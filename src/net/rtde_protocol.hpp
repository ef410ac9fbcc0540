// SPDX-License-Identifier: Apache-2.0
// hrcsense — the RTDE wire codec (protocol version 2, written from UR's public guide:
// ../shared/specs/ur-rtde.md), private to src/net: the packages the client sends, the framing
// of what the controller sends, and the parsers of each package type. The client and the link
// (include/hrcsense/net/rtde.hpp) use it; tests, benchmarks and the fuzz target reach it by
// its path from the source root.
#pragma once

#include "hrcsense/net/rtde.hpp"
#include "rtde_protocol.hpp"
#include "hrcsense/types.hpp"

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
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
    "timestamp,actual_q,actual_qd,robot_mode,safety_mode,speed_scaling,target_speed_fraction,actual_TCP_pose";

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
struct Package {
  uint8_t type = 0;
  const uint8_t* payload = nullptr;  ///< after the 3-byte header
  size_t payload_size = 0;
};

enum class SplitStatus {
  package,    ///< `package` is complete; `consumed` bytes (its size field) belong to it
  need_more,  ///< the buffer holds part of a package (or less than a header): read more
  malformed,  ///< size field < 3: the stream cannot be framed any more (`error` says so)
};

struct PackageSplit {
  SplitStatus status = SplitStatus::need_more;
  Package package;
  size_t consumed = 0;
  std::string error;
};

/// The first package of `data[0, size)`. Never reads past `size`.
PackageSplit split_package(const uint8_t* data, size_t size);

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
                                   speed_scaling, target_speed_fraction, actual_tcp_pose };

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
  double target_speed_fraction = std::numeric_limits<double>::quiet_NaN();  ///< the speed slider; NaN: not in the recipe
  std::array<double, 6> tcp_pose{};  ///< actual_TCP_pose: x, y, z (m), rotation vector (rad), base frame
};

// Each parser checks the type and that the payload is exactly what the type explains; false
// with `error` naming the package type and the field on anything else.
bool parse_accepted(const Package& frame, PackageType expected, bool& accepted, std::string& error);
bool parse_controller_version(const Package& frame, ControllerVersion& out, std::string& error);
bool parse_text_message(const Package& frame, TextMessage& out, std::string& error);
bool parse_setup_reply(const Package& frame, PackageType expected, SetupReply& out, std::string& error);
/// The recipe for data packages from a setup reply to the request `names` (comma-separated):
/// false when a variable is NOT_FOUND (naming it), the counts differ, a type is unknown or a
/// variable hrcsense reads has an unexpected type.
bool make_output_recipe(const SetupReply& reply, const std::string& names, OutputRecipe& out,
                        std::string& error);
/// A DATA_PACKAGE of `recipe`: false on another recipe id or a payload of the wrong size.
bool parse_data_package(const Package& frame, const OutputRecipe& recipe, DataSample& out, std::string& error);

// ---- Writing inputs (link.rtde.write).

/// CONTROL_PACKAGE_SETUP_INPUTS: the comma-separated input names (≤ 2048 bytes;
/// std::invalid_argument when longer).
std::vector<uint8_t> encode_setup_inputs(const std::string& names);

/// One value of an input DATA_PACKAGE: UINT32 or DOUBLE, the types hrcsense writes.
struct InputValue {
  enum class Type : uint8_t { uint32, double_value } type = Type::double_value;
  uint32_t u32 = 0;
  double f64 = 0.0;
};

/// A DATA_PACKAGE the client sends: the input recipe id, then the values in the recipe's order.
std::vector<uint8_t> encode_input_data(uint8_t recipe_id, const std::vector<InputValue>& values);

/// Checks an input setup reply to the request `names` (comma-separated) against the types
/// hrcsense will write (`expected_types`, e.g. {"UINT32", "DOUBLE"}): false naming the variable
/// when another client owns it (IN_USE), the controller does not know it (NOT_FOUND), its
/// type differs, or the counts differ.
bool check_input_setup(const SetupReply& reply, const std::string& names,
                       const std::vector<std::string>& expected_types, std::string& error);

/// A TCP connection to `host`:`port` (name or numeric; TCP_NODELAY, non-blocking), waiting at
/// most `timeout_s` in slices of 20 ms that look at `stop`; -1 with `error` ("RTDE host:port: ...").
int connect_tcp(const std::string& host, int port, double timeout_s, const std::atomic<bool>& stop,
                std::string& error);

}  // namespace rtde

}  // namespace hrcsense
