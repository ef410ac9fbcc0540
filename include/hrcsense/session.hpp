// SPDX-License-Identifier: Apache-2.0
// hrcsense — the process's session: a random number drawn once per process start, so that a
// receiver tells a restarted hrcsense from the one that died (the link datagram's `session`,
// the JSON Lines header's `session`; docs/SAFETY.md, "Receiving").
#pragma once

#include <cstdint>

namespace hrcsense {

/// This process's session: random, never 0, the same value for every call in one process (drawn
/// on the first call, thread-safe). Not a secret and not an authentication: it only makes two
/// starts differ, with a chance of 1 in 2^32 - 1 that two starts draw the same value.
uint32_t process_session();

}  // namespace hrcsense
