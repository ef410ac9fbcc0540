// SPDX-License-Identifier: Apache-2.0
// Test support: FIFOs and other non-regular files, and running code that might block on them
// (open() of a FIFO with no writer never returns) in a child process with a deadline, so that a
// missing check fails the test instead of hanging it.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <csignal>
#include <functional>
#include <string>
#include <thread>

#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

namespace hrcsense::test {

/// Creates a FIFO at `path`; fails the test when the system refuses.
inline void make_fifo(const std::string& path) { ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0) << path; }

/// What run_with_deadline saw.
enum class ChildOutcome { passed, failed, timed_out };

/// Runs `check` in a forked child (which may block forever on a FIFO) and waits at most
/// `seconds`; a child still running then is killed. `check` returns true when its expectations
/// held; it should not use gtest assertions (they would be recorded in the child only), but
/// may print what went wrong.
inline ChildOutcome run_with_deadline(const std::function<bool()>& check, double seconds = 10.0) {
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = ::fork();
  if (child < 0) return ChildOutcome::failed;
  if (child == 0) {
    bool ok = false;
    try {
      ok = check();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "child: unexpected exception: %s\n", e.what());
    }
    std::fflush(stderr);
    ::_exit(ok ? 0 : 1);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      return ChildOutcome::timed_out;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? ChildOutcome::passed : ChildOutcome::failed;
}

/// True when `message` contains every one of `needles`; prints the message otherwise.
inline bool mentions(const std::string& message, std::initializer_list<std::string> needles) {
  for (const std::string& needle : needles) {
    if (message.find(needle) == std::string::npos) {
      std::fprintf(stderr, "'%s' not in: %s\n", needle.c_str(), message.c_str());
      return false;
    }
  }
  return true;
}

}  // namespace hrcsense::test
