// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — cell.fuser_priority (fuser_priority.hpp).
#include "common/fuser_priority.hpp"

#include <sched.h>

#include <cerrno>
#include <cstring>

namespace hrcsense::app {

std::string run_under_fifo(int priority) {
  if (priority == 0) return {};
  if (priority < sched_get_priority_min(SCHED_FIFO) || priority > sched_get_priority_max(SCHED_FIFO)) {
    return "cell.fuser_priority: " + std::to_string(priority) + " is outside SCHED_FIFO's range";
  }
  sched_param param{};
  param.sched_priority = priority;
  // pid 0: the calling thread (Linux schedules threads, not processes).
  if (sched_setscheduler(0, SCHED_FIFO, &param) == 0) return {};
  const int error = errno;
  std::string text = "cell.fuser_priority: " + std::to_string(priority) + ": SCHED_FIFO refused (" + std::strerror(error) + ")";
  if (error == EPERM) {
    text += "; the fuser needs CAP_SYS_NICE or an rtprio limit of at least " + std::to_string(priority) +
            " (systemd: LimitRTPRIO=, or /etc/security/limits.conf), or set cell.fuser_priority: 0";
  }
  return text;
}

}  // namespace hrcsense::app
