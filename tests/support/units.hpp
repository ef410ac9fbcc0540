// SPDX-License-Identifier: Apache-2.0
// Test support: time units for timestamps in nanoseconds.
#pragma once

#include <cstdint>

namespace hrcsense::test {

constexpr int64_t kMs = 1'000'000;  // one millisecond, in nanoseconds

}  // namespace hrcsense::test
