// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: any bytes as one udp_json datagram, read by parse_udp_json_state. The
// contract checked here: no crash or sanitizer report; a result is either ok with finite
// joints, t_ns in 0..2^62 and speed_fraction NaN (absent) or in 0..1, non_finite with a
// message naming q or qd, or an error message; never an exception.
#include "hrcsense/net/udp_json.hpp"

#include <cmath>
#include <cstdlib>

namespace {

bool all_finite(const hrcsense::JointAngles& values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const hrcsense::UdpJsonDatagram d = hrcsense::parse_udp_json_state(reinterpret_cast<const char*>(data), size);
  if (d.ok) {
    if (!d.error.empty() || d.non_finite || d.t_ns < 0 || d.t_ns > hrcsense::kUdpJsonMaxTimeNs ||
        !all_finite(d.q_rad) || !all_finite(d.qd_rad_s) || size > hrcsense::kUdpJsonMaxBytes ||
        !(std::isnan(d.speed_fraction) || (d.speed_fraction >= 0.0 && d.speed_fraction <= 1.0))) {
      std::abort();
    }
  } else if (d.error.empty() || (d.non_finite && d.error.rfind("q", 0) != 0)) {
    std::abort();  // every rejection says why; a non-finite one names q[i] or qd[i]
  }
  return 0;
}
