// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — `cell.fuser_priority`: the fuser's threads under SCHED_FIFO, so that the
// cameras measuring on the same host cannot keep its decision waiting for a core
// (docs/MULTICAMERA.md, "The fuser's host").
#pragma once

#include <string>

namespace hrcsense::app {

/// Puts the calling thread under SCHED_FIFO at `priority` (1..99); threads it starts afterwards
/// inherit it, so the fuser calls this before it starts any (DDS, links, relay). 0 does nothing.
/// Returns "" or why it could not: the kernel's refusal, with what to grant (CAP_SYS_NICE, an
/// rtprio limit, systemd's LimitRTPRIO=) and the key's name.
std::string run_under_fifo(int priority);

}  // namespace hrcsense::app
