// SPDX-License-Identifier: Apache-2.0
// hrcsense — RTDE packages: the client's, encoded, and the controller's, framed and parsed.
// Pure functions over byte buffers; everything big-endian (../shared/specs/ur-rtde.md).
#include "hrcsense/net/rtde.hpp"
#include "rtde_protocol.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace hrcsense::rtde {
namespace {

constexpr size_t kMaxNamesBytes = 2048;  // UR's limit on the variable list

void put_u16(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(static_cast<uint8_t>(v >> 8));
  out.push_back(static_cast<uint8_t>(v & 0xFF));
}

void put_f64(std::vector<uint8_t>& out, double v) {
  uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  for (int shift = 56; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(bits >> shift));
}

std::vector<uint8_t> package(PackageType type, size_t payload_size) {
  std::vector<uint8_t> out;
  out.reserve(kHeaderSize + payload_size);
  put_u16(out, static_cast<uint16_t>(kHeaderSize + payload_size));
  out.push_back(static_cast<uint8_t>(type));
  return out;
}

uint32_t get_u32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}

double get_f64(const uint8_t* p) {
  const uint64_t bits = (uint64_t{get_u32(p)} << 32) | get_u32(p + 4);
  double v = 0.0;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

std::string name_of(uint8_t type) { return package_type_name(type); }

bool expect_type(const Package& frame, PackageType expected, std::string& error) {
  if (frame.type == static_cast<uint8_t>(expected)) return true;
  error = std::string(package_type_name(static_cast<uint8_t>(expected))) + ": got a " + name_of(frame.type) +
          " (type " + std::to_string(frame.type) + ") instead";
  return false;
}

bool expect_size(const Package& frame, size_t size, const char* what, std::string& error) {
  if (frame.payload_size == size) return true;
  error = name_of(frame.type) + ": payload of " + std::to_string(frame.payload_size) + " bytes, expected " +
          std::to_string(size) + " (" + what + ")";
  return false;
}

// Byte size of an output type in a data package; 0 for a name that is not a fixed-size type.
size_t type_size(const std::string& type) {
  if (type == "BOOL" || type == "UINT8") return 1;
  if (type == "UINT32" || type == "INT32") return 4;
  if (type == "UINT64" || type == "DOUBLE") return 8;
  if (type == "VECTOR3D") return 24;
  if (type == "VECTOR6D") return 48;
  if (type == "VECTOR6INT32" || type == "VECTOR6UINT32") return 24;
  return 0;
}

struct Known {
  const char* name;
  OutputField field;
  const char* type;
};
constexpr Known kKnown[] = {
    {"timestamp", OutputField::timestamp, "DOUBLE"},       {"actual_q", OutputField::actual_q, "VECTOR6D"},
    {"actual_qd", OutputField::actual_qd, "VECTOR6D"},     {"robot_mode", OutputField::robot_mode, "INT32"},
    {"safety_mode", OutputField::safety_mode, "INT32"},    {"speed_scaling", OutputField::speed_scaling, "DOUBLE"},
    {"target_speed_fraction", OutputField::target_speed_fraction, "DOUBLE"},
    {"actual_TCP_pose", OutputField::actual_tcp_pose, "VECTOR6D"},
};

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts;
  size_t begin = 0;
  while (true) {
    const size_t comma = text.find(',', begin);
    parts.push_back(text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
    if (comma == std::string::npos) return parts;
    begin = comma + 1;
  }
}

void get_vector6(const uint8_t* p, double* out) {
  for (size_t i = 0; i < 6; ++i) out[i] = get_f64(p + 8 * i);
}

}  // namespace

const char* package_type_name(uint8_t type) {
  switch (static_cast<PackageType>(type)) {
    case PackageType::request_protocol_version: return "REQUEST_PROTOCOL_VERSION";
    case PackageType::get_urcontrol_version: return "GET_URCONTROL_VERSION";
    case PackageType::text_message: return "TEXT_MESSAGE";
    case PackageType::setup_outputs: return "CONTROL_PACKAGE_SETUP_OUTPUTS";
    case PackageType::setup_inputs: return "CONTROL_PACKAGE_SETUP_INPUTS";
    case PackageType::start: return "CONTROL_PACKAGE_START";
    case PackageType::pause: return "CONTROL_PACKAGE_PAUSE";
    case PackageType::data: return "DATA_PACKAGE";
  }
  return "unknown package type";
}

std::vector<uint8_t> encode_request_protocol_version(uint16_t version) {
  std::vector<uint8_t> out = package(PackageType::request_protocol_version, 2);
  put_u16(out, version);
  return out;
}

std::vector<uint8_t> encode_get_urcontrol_version() { return package(PackageType::get_urcontrol_version, 0); }

std::vector<uint8_t> encode_setup_outputs(double frequency_hz, const std::string& names) {
  if (names.size() > kMaxNamesBytes) {
    throw std::invalid_argument("CONTROL_PACKAGE_SETUP_OUTPUTS: variable names of " + std::to_string(names.size()) +
                                " bytes (at most 2048)");
  }
  std::vector<uint8_t> out = package(PackageType::setup_outputs, 8 + names.size());
  put_f64(out, frequency_hz);
  out.insert(out.end(), names.begin(), names.end());
  return out;
}

std::vector<uint8_t> encode_start() { return package(PackageType::start, 0); }
std::vector<uint8_t> encode_pause() { return package(PackageType::pause, 0); }

PackageSplit split_package(const uint8_t* data, size_t size) {
  PackageSplit out;
  if (size < kHeaderSize) return out;  // need_more
  const size_t package_size = (size_t{data[0]} << 8) | data[1];
  if (package_size < kHeaderSize) {
    out.status = SplitStatus::malformed;
    out.error = "package size " + std::to_string(package_size) + " (type " + std::to_string(data[2]) +
                "): less than its 3-byte header";
    return out;
  }
  if (package_size > size) return out;  // truncated so far: need_more
  out.status = SplitStatus::package;
  out.package = Package{data[2], data + kHeaderSize, package_size - kHeaderSize};
  out.consumed = package_size;
  return out;
}

bool parse_accepted(const Package& frame, PackageType expected, bool& accepted, std::string& error) {
  if (!expect_type(frame, expected, error) || !expect_size(frame, 1, "uint8 accepted", error)) return false;
  accepted = frame.payload[0] != 0;
  return true;
}

bool parse_controller_version(const Package& frame, ControllerVersion& out, std::string& error) {
  if (!expect_type(frame, PackageType::get_urcontrol_version, error) ||
      !expect_size(frame, 16, "uint32 major, minor, bugfix, build", error)) {
    return false;
  }
  out = ControllerVersion{get_u32(frame.payload), get_u32(frame.payload + 4), get_u32(frame.payload + 8),
                          get_u32(frame.payload + 12)};
  return true;
}

bool parse_text_message(const Package& frame, TextMessage& out, std::string& error) {
  if (!expect_type(frame, PackageType::text_message, error)) return false;
  const uint8_t* p = frame.payload;
  const size_t n = frame.payload_size;
  size_t at = 0;
  std::string* parts[] = {&out.message, &out.source};
  const char* names[] = {"message", "source"};
  for (int i = 0; i < 2; ++i) {
    if (at >= n || p[at] > n - at - 1) {
      error = "TEXT_MESSAGE: " + std::string(names[i]) + " runs past the package's " + std::to_string(n) +
              " payload bytes";
      return false;
    }
    parts[i]->assign(reinterpret_cast<const char*>(p + at + 1), p[at]);
    at += 1 + p[at];
  }
  if (!expect_size(frame, at + 1, "message, source, uint8 level", error)) return false;
  out.level = p[at];
  return true;
}

bool parse_setup_reply(const Package& frame, PackageType expected, SetupReply& out, std::string& error) {
  if (!expect_type(frame, expected, error)) return false;
  if (frame.payload_size < 1) {
    error = name_of(frame.type) + ": empty reply (no recipe id)";
    return false;
  }
  out.recipe_id = frame.payload[0];
  out.types = split_commas(std::string(reinterpret_cast<const char*>(frame.payload + 1), frame.payload_size - 1));
  return true;
}

bool make_output_recipe(const SetupReply& reply, const std::string& names, OutputRecipe& out, std::string& error) {
  const std::vector<std::string> variables = split_commas(names);
  if (variables.size() != reply.types.size()) {
    error = "CONTROL_PACKAGE_SETUP_OUTPUTS: " + std::to_string(reply.types.size()) + " types for " +
            std::to_string(variables.size()) + " requested variables";
    return false;
  }
  out = OutputRecipe{};
  out.id = reply.recipe_id;
  out.payload_size = 1;
  for (size_t i = 0; i < variables.size(); ++i) {
    const std::string& type = reply.types[i];
    if (type == "NOT_FOUND") {
      error = "CONTROL_PACKAGE_SETUP_OUTPUTS: variable '" + variables[i] + "' NOT_FOUND on this controller";
      return false;
    }
    OutputRecipe::Entry entry;
    entry.size = type_size(type);
    if (entry.size == 0) {
      error = "CONTROL_PACKAGE_SETUP_OUTPUTS: variable '" + variables[i] + "': unsupported type '" + type + "'";
      return false;
    }
    for (const Known& known : kKnown) {
      if (variables[i] != known.name) continue;
      if (type != known.type) {
        error = "CONTROL_PACKAGE_SETUP_OUTPUTS: variable '" + variables[i] + "' is " + type + ", expected " +
                known.type;
        return false;
      }
      entry.field = known.field;
    }
    out.entries.push_back(entry);
    out.payload_size += entry.size;
  }
  return true;
}

bool parse_data_package(const Package& frame, const OutputRecipe& recipe, DataSample& out, std::string& error) {
  if (!expect_type(frame, PackageType::data, error)) return false;
  if (frame.payload_size < 1) {
    error = "DATA_PACKAGE: empty (no recipe id)";
    return false;
  }
  if (frame.payload[0] != recipe.id) {
    error = "DATA_PACKAGE: recipe id " + std::to_string(frame.payload[0]) + ", expected " + std::to_string(recipe.id);
    return false;
  }
  if (!expect_size(frame, recipe.payload_size, "recipe id and the recipe's variables", error)) return false;
  out.recipe_id = frame.payload[0];
  const uint8_t* p = frame.payload + 1;
  for (const OutputRecipe::Entry& entry : recipe.entries) {
    switch (entry.field) {
      case OutputField::timestamp: out.timestamp_s = get_f64(p); break;
      case OutputField::actual_q: get_vector6(p, out.q.data()); break;
      case OutputField::actual_qd: get_vector6(p, out.qd.data()); break;
      case OutputField::robot_mode: out.robot_mode = static_cast<int32_t>(get_u32(p)); break;
      case OutputField::safety_mode: out.safety_mode = static_cast<int32_t>(get_u32(p)); break;
      case OutputField::speed_scaling: out.speed_scaling = get_f64(p); break;
      case OutputField::target_speed_fraction: out.target_speed_fraction = get_f64(p); break;
      case OutputField::actual_tcp_pose: get_vector6(p, out.tcp_pose.data()); break;
      case OutputField::other: break;
    }
    p += entry.size;
  }
  return true;
}

std::vector<uint8_t> encode_setup_inputs(const std::string& names) {
  if (names.size() > kMaxNamesBytes) {
    throw std::invalid_argument("CONTROL_PACKAGE_SETUP_INPUTS: variable names of " + std::to_string(names.size()) +
                                " bytes (at most 2048)");
  }
  // Sized once and written by index (GCC 12 misreads package()'s push_backs inlined here).
  std::vector<uint8_t> out(kHeaderSize + names.size());
  const size_t size = out.size();
  out[0] = static_cast<uint8_t>(size >> 8);
  out[1] = static_cast<uint8_t>(size & 0xFF);
  out[2] = static_cast<uint8_t>(PackageType::setup_inputs);
  if (!names.empty()) std::memcpy(out.data() + kHeaderSize, names.data(), names.size());
  return out;
}

std::vector<uint8_t> encode_input_data(uint8_t recipe_id, const std::vector<InputValue>& values) {
  size_t size = kHeaderSize + 1;
  for (const InputValue& v : values) size += v.type == InputValue::Type::uint32 ? 4 : 8;
  std::vector<uint8_t> out(size);
  out[0] = static_cast<uint8_t>(size >> 8);
  out[1] = static_cast<uint8_t>(size & 0xFF);
  out[2] = static_cast<uint8_t>(PackageType::data);
  out[3] = recipe_id;
  size_t at = 4;
  for (const InputValue& v : values) {
    uint64_t bits = v.u32;
    int bytes = 4;
    if (v.type == InputValue::Type::double_value) {
      std::memcpy(&bits, &v.f64, sizeof bits);
      bytes = 8;
    }
    for (int shift = 8 * (bytes - 1); shift >= 0; shift -= 8) out[at++] = static_cast<uint8_t>(bits >> shift);
  }
  return out;
}

bool check_input_setup(const SetupReply& reply, const std::string& names,
                       const std::vector<std::string>& expected_types, std::string& error) {
  const std::vector<std::string> variables = split_commas(names);
  if (variables.size() != reply.types.size() || variables.size() != expected_types.size()) {
    error = "CONTROL_PACKAGE_SETUP_INPUTS: " + std::to_string(reply.types.size()) + " types for " +
            std::to_string(variables.size()) + " requested inputs";
    return false;
  }
  for (size_t i = 0; i < variables.size(); ++i) {
    const std::string& type = reply.types[i];
    if (type == "IN_USE") {
      error = "CONTROL_PACKAGE_SETUP_INPUTS: input '" + variables[i] +
              "' is IN_USE: another RTDE client (UR's ROS driver, a fieldbus adapter) already writes it";
      return false;
    }
    if (type == "NOT_FOUND") {
      error = "CONTROL_PACKAGE_SETUP_INPUTS: input '" + variables[i] + "' NOT_FOUND on this controller";
      return false;
    }
    if (type != expected_types[i]) {
      const bool printable = type.size() <= 32 && std::all_of(type.begin(), type.end(), [](char c) {
                               return c >= 0x20 && c < 0x7F;
                             });
      error = "CONTROL_PACKAGE_SETUP_INPUTS: input '" + variables[i] + "' is " +
              (printable ? "'" + type + "'" : std::string("an unreadable type")) + ", expected " + expected_types[i];
      return false;
    }
  }
  return true;
}

}  // namespace hrcsense::rtde
