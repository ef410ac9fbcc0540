// SPDX-License-Identifier: Apache-2.0
// What the DDS tests share: a domain of their own per test process (ctest runs them in
// parallel; the loopback configuration in CYCLONEDDS_URI keeps them on this machine).
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <string>

namespace hrcsense::test {

/// A DDS domain for this process: 1-200 from the pid, so parallel test processes do not
/// hear each other (domain 0 stays free for a user's own ROS 2 system).
inline uint32_t test_domain() { return 1U + static_cast<uint32_t>(getpid()) % 200U; }

/// Skips unless CYCLONEDDS_URI names the loopback configuration (ctest sets it): the tests
/// never put traffic on a real network.
inline bool loopback_configured() {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  return uri != nullptr && std::string(uri).find("cyclonedds-loopback.xml") != std::string::npos;
}

inline constexpr const char* kNoLoopback =
    "CYCLONEDDS_URI is not the tests' loopback configuration (tests/dds/cyclonedds-loopback.xml; ctest sets it)";

}  // namespace hrcsense::test
