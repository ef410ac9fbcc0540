// SPDX-License-Identifier: Apache-2.0
// What the ROS 2 message fuzzers share: fields read off the front of the input, as the fuzzer
// builds a message Cyclone could have handed over.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace hrcsense::fuzz {

/// Reads fields off the front of the input; past the end, zeros.
struct FieldReader {
  const uint8_t* data;
  size_t size;

  template <typename T>
  T take() {
    T value{};
    const size_t n = std::min(sizeof(T), size);
    std::memcpy(&value, data, n);
    data += n;
    size -= n;
    return value;
  }

  /// Up to `max_length` bytes (the length is the next byte); a C string stops at its first NUL,
  /// as Cyclone's would.
  std::string text(size_t max_length) {
    const size_t n = std::min<size_t>(take<uint8_t>() % (max_length + 1), size);
    std::string s(reinterpret_cast<const char*>(data), n);
    data += n;
    size -= n;
    return s.c_str();
  }
};

}  // namespace hrcsense::fuzz
