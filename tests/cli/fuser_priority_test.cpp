// SPDX-License-Identifier: Apache-2.0
// cell.fuser_priority: run_under_fifo puts the calling thread, and the threads it starts
// afterwards, under SCHED_FIFO, or says why the kernel refused. Each case runs in a thread of
// its own, so that the test process keeps the normal scheduler. What the kernel must do is
// decided here from the rules of sched(7), not from the function: CAP_SYS_NICE, or an
// RLIMIT_RTPRIO at least the priority asked for.
#include "common/fuser_priority.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/resource.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace hrcsense::app {
namespace {

// Bit 23 of the effective capabilities (/proc/self/status, CapEff) is CAP_SYS_NICE.
bool has_cap_sys_nice() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("CapEff:", 0) != 0) continue;
    uint64_t caps = 0;
    std::istringstream(line.substr(7)) >> std::hex >> caps;
    return ((caps >> 23U) & 1U) != 0;
  }
  return false;
}

bool fifo_allowed(int priority) {
  if (has_cap_sys_nice()) return true;
  rlimit limit{};
  return getrlimit(RLIMIT_RTPRIO, &limit) == 0 && limit.rlim_cur >= static_cast<rlim_t>(priority);
}

struct Policy {
  int policy = -1;
  int priority = -1;
};

Policy policy_of_this_thread() {
  sched_param param{};
  sched_getparam(0, &param);
  return {sched_getscheduler(0), param.sched_priority};
}

TEST(FuserPriority, ZeroLeavesTheNormalScheduler) {
  std::string error = "not run";
  Policy after;
  std::thread([&] {
    error = run_under_fifo(0);
    after = policy_of_this_thread();
  }).join();
  EXPECT_EQ(error, "");
  EXPECT_EQ(after.policy, SCHED_OTHER);
}

TEST(FuserPriority, OutsideTheRangeIsRefusedByName) {
  std::string error;
  Policy after;
  std::thread([&] {
    error = run_under_fifo(100);
    after = policy_of_this_thread();
  }).join();
  EXPECT_NE(error.find("cell.fuser_priority: 100"), std::string::npos) << error;
  EXPECT_EQ(after.policy, SCHED_OTHER);
}

TEST(FuserPriority, TheThreadAndThoseItStartsRunUnderFifoOrTheRefusalSaysWhatToGrant) {
  constexpr int kPriority = 7;
  std::string error = "not run";
  Policy self;
  Policy child;
  std::thread([&] {
    error = run_under_fifo(kPriority);
    self = policy_of_this_thread();
    std::thread([&] { child = policy_of_this_thread(); }).join();
  }).join();
  if (fifo_allowed(kPriority)) {
    EXPECT_EQ(error, "");
    EXPECT_EQ(self.policy, SCHED_FIFO);
    EXPECT_EQ(self.priority, kPriority);
    EXPECT_EQ(child.policy, SCHED_FIFO);  // DDS's and the links' threads start after the call
    EXPECT_EQ(child.priority, kPriority);
  } else {
    EXPECT_NE(error.find("cell.fuser_priority: 7: SCHED_FIFO refused"), std::string::npos) << error;
    EXPECT_NE(error.find("CAP_SYS_NICE"), std::string::npos) << error;
    EXPECT_EQ(self.policy, SCHED_OTHER);
  }
  // The test process itself was never touched.
  EXPECT_EQ(policy_of_this_thread().policy, SCHED_OTHER);
}

}  // namespace
}  // namespace hrcsense::app
