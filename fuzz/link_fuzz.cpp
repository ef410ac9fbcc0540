// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: any bytes as one HRCS link datagram, read by decode_link_datagram (what a
// controller-side receiver, or a test, runs on what arrives). The contract checked here: no
// crash or sanitizer report; a result is either ok, with exactly 45 bytes (version 2) and every
// value in its documented range, a non-zero session among them, and the same bytes again when
// encoded, or an error naming a field; never an exception. Each 45-byte input is decoded a second
// time with its CRC made right.
#include "hrcsense/net/link.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>

namespace {

// The contract for one decode of `data`.
void check(const uint8_t* data, size_t size) {
  const hrcsense::LinkDecodeResult r = hrcsense::decode_link_datagram(data, size);
  if (!r.ok) {
    if (r.error.empty()) std::abort();  // every rejection says why
    return;
  }
  const hrcsense::LinkDatagram& d = r.datagram;
  const auto kind = static_cast<uint16_t>(d.kind);
  const bool in_range = size == hrcsense::kLinkDatagramSize && r.error.empty() && kind >= 1 && kind <= 3 &&
                        d.session != 0 &&
                        d.timestamp_ns >= 0 && static_cast<int>(d.verdict) <= 2 && d.speed_scale >= 0.0F &&
                        d.speed_scale <= 1.0F && (std::isnan(d.distance_m) || (std::isfinite(d.distance_m) &&
                                                                                d.distance_m >= 0.0F)) &&
                        std::isfinite(d.protective_distance_m) && d.protective_distance_m >= 0.0F &&
                        (d.kind == hrcsense::LinkKind::frame || d.verdict == hrcsense::VerdictState::stop);
  if (!in_range) std::abort();
  // Decoding loses nothing: a NaN distance (bytes 27..30) may carry another payload, so compare
  // all but it, up to the CRC (bytes 41..44) which follows from the rest.
  const hrcsense::LinkBytes again = hrcsense::encode_link_datagram(d);
  if (std::memcmp(again.data(), data, 27) != 0 || std::memcmp(again.data() + 31, data + 31, 10) != 0) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check(data, size);
  // Random bytes almost never carry a right CRC: decode them once more with the CRC made right,
  // so that every field's check is reached too.
  if (size == hrcsense::kLinkDatagramSize) {
    uint8_t fixed[hrcsense::kLinkDatagramSize];
    std::memcpy(fixed, data, size);
    constexpr size_t kCrcAt = hrcsense::kLinkDatagramSize - 4;
    const uint32_t crc = hrcsense::crc32_ieee(fixed, kCrcAt);
    for (size_t i = 0; i < 4; ++i) fixed[kCrcAt + i] = static_cast<uint8_t>(crc >> (8 * i));
    check(fixed, size);
  }
  return 0;
}
