// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: the scene clock's epoch on `<ns>/cell_clock` (builtin_interfaces/Time) as
// Cyclone hands it to a camera after deserialising (its CDR reader is Cyclone's, fuzzed
// upstream), read against a reader clock that is today's, or any int64 (a host whose clock is
// wrong). Any bytes become a message — sec and nanosec of any value — and go through
// parse_cell_clock. The contract: no crash or sanitizer report; an accepted epoch has
// nanosec below 10^9, equals sec · 10^9 + nanosec and is within a day of the reader's clock; a
// refused one names a field.
#include "field_reader.hpp"
#include "dds/ros2_cell_clock.hpp"

#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hrcsense;
  fuzz::FieldReader in{data, size};
  const int64_t now_ns = (in.take<uint8_t>() & 1U) != 0 ? 1'800'000'000'000'000'000 : in.take<int64_t>();
  builtin_interfaces_msg_dds__Time_ msg{};
  msg.sec = (in.take<uint8_t>() & 1U) != 0 ? 1'800'000'000 + in.take<int16_t>() : in.take<int32_t>();
  msg.nanosec = in.take<uint32_t>();
  const ros2::CellClockEpoch read = ros2::parse_cell_clock(msg, now_ns);
  if (read.ok) {
    if (msg.nanosec >= 1'000'000'000U) std::abort();
    if (read.epoch_ns != int64_t{msg.sec} * 1'000'000'000 + int64_t{msg.nanosec}) std::abort();
    // |epoch − now| in unsigned arithmetic: exact for any two int64 values, the larger first.
    const auto e = static_cast<uint64_t>(read.epoch_ns), n = static_cast<uint64_t>(now_ns);
    const uint64_t distance = read.epoch_ns >= now_ns ? e - n : n - e;
    if (distance > static_cast<uint64_t>(ros2::kCellClockMaxOffsetNs)) std::abort();
  } else if (read.error.find(':') == std::string::npos) {
    std::abort();
  }
  return 0;
}
