// SPDX-License-Identifier: Apache-2.0
// hrcsense sinks — JSON text composed by hand into a reused line (jsonl.cpp): strings, exact numbers, members.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

namespace hrcsense::jsonl_detail {

inline void put_string(std::string& line, std::string_view text) {
  line += '"';
  for (char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      line += '\\';
      line += ch;
    } else if (byte < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", byte);
      line += escaped;
    } else {
      line += ch;
    }
  }
  line += '"';
}

inline void put_key(std::string& line, const char* key) {
  if (line.back() != '{') line += ',';
  put_string(line, key);
  line += ':';
}

// Shortest text that reads back as the same float: 9 significant digits at most, which
// keeps metres far below 0.1 mm. JSON has no NaN or infinity: those become null.
inline void put_float(std::string& line, float value) {
  if (!std::isfinite(value)) {
    line += "null";
    return;
  }
  char buffer[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, static_cast<double>(value));
    if (std::strtof(buffer, nullptr) == value) break;
  }
  line += buffer;
}

inline void put_double(std::string& line, double value) {
  if (!std::isfinite(value)) {
    line += "null";
    return;
  }
  char buffer[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  line += buffer;
}

inline void put_int(std::string& line, int64_t value) {
  char buffer[24];
  std::snprintf(buffer, sizeof buffer, "%lld", static_cast<long long>(value));
  line += buffer;
}

// Seconds from integer nanoseconds, exactly: "3.4" rather than 3.4000000000000004.
inline void put_seconds(std::string& line, int64_t timestamp_ns) {
  if (timestamp_ns < 0) {
    put_double(line, static_cast<double>(timestamp_ns) * 1e-9);
    return;
  }
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%lld.%09lld", static_cast<long long>(timestamp_ns / 1000000000),
                static_cast<long long>(timestamp_ns % 1000000000));
  std::string_view text(buffer);
  while (text.back() == '0' && text[text.size() - 2] != '.') text.remove_suffix(1);
  line += text;
}

inline void put_vec3(std::string& line, const Eigen::Vector3f& v) {
  line += '[';
  put_float(line, v.x());
  line += ',';
  put_float(line, v.y());
  line += ',';
  put_float(line, v.z());
  line += ']';
}

/// Appends `"key":value` members to a line, one call per member, so that each field of the
/// output is one line here. Values a contact lacks are written as null.
struct Members {
  std::string& line;

  void text(const char* key, std::string_view value) {
    put_key(line, key);
    put_string(line, value);
  }
  void integer(const char* key, int64_t value) {
    put_key(line, key);
    put_int(line, value);
  }
  void number(const char* key, float value) {
    put_key(line, key);
    put_float(line, value);
  }
  void number(const char* key, double value) {
    put_key(line, key);
    put_double(line, value);
  }
  void boolean(const char* key, bool value) {
    put_key(line, key);
    line += value ? "true" : "false";
  }
  void null(const char* key) {
    put_key(line, key);
    line += "null";
  }
  /// The text, or null when it is empty.
  void text_or_null(const char* key, std::string_view value) {
    if (value.empty()) {
      null(key);
    } else {
      text(key, value);
    }
  }
  void texts(const char* key, const std::vector<std::string>& values) {
    put_key(line, key);
    line += '[';
    for (size_t i = 0; i < values.size(); ++i) {
      if (i > 0) line += ',';
      put_string(line, values[i]);
    }
    line += ']';
  }
  template <typename T>
  void number_or_null(const char* key, bool present, T value) {
    if (present) {
      number(key, value);
    } else {
      null(key);
    }
  }
  void point_or_null(const char* key, bool present, const Eigen::Vector3f& value) {
    put_key(line, key);
    if (present) {
      put_vec3(line, value);
    } else {
      line += "null";
    }
  }
  void open(const char* key) {
    put_key(line, key);
    line += '{';
  }
  void close() { line += '}'; }
};

}  // namespace hrcsense::jsonl_detail
