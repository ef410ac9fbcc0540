// SPDX-License-Identifier: Apache-2.0
// hrcsense — process_session(): std::random_device once per process (session.hpp).
#include "hrcsense/session.hpp"

#include <chrono>
#include <exception>
#include <random>

namespace hrcsense {
namespace {

// SplitMix64's finaliser: spreads the bits of a poor seed over the whole word.
uint64_t mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

uint32_t draw_session() {
  uint32_t session = 0;
  try {
    std::random_device device;
    // 0 is reserved (a receiver rejects it): draw again. Bounded: a device that keeps
    // answering 0 is broken, and the fallback below takes over.
    for (int attempt = 0; attempt < 8 && session == 0; ++attempt) session = static_cast<uint32_t>(device());
  } catch (const std::exception&) {
    // No entropy source (random_device may throw where none exists): fall back below.
  }
  if (session == 0) {
    // The start time in ns and where this function's local lives (address space layout
    // randomisation) differ between two starts, which is all a session must do.
    const auto now_ns = static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) ^
                        static_cast<uint64_t>(std::chrono::system_clock::now().time_since_epoch().count());
    const uint64_t mixed = mix(now_ns ^ reinterpret_cast<uintptr_t>(&session));
    session = static_cast<uint32_t>(mixed ^ (mixed >> 32));
    if (session == 0) session = 1;
  }
  return session;
}

}  // namespace

uint32_t process_session() {
  static const uint32_t session = draw_session();  // C++11: initialised once, thread-safe
  return session;
}

}  // namespace hrcsense
