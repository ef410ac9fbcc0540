// SPDX-License-Identifier: Apache-2.0
// Test support: a program run as a child process, its standard output a pipe the test reads line
// by line, its standard error a file (or /dev/null). Every wait is bounded; a child still
// running when the object goes is killed.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::test {

class ChildProcess {
 public:
  using Clock = std::chrono::steady_clock;

  /// Runs `args[0]` with `args`; its stderr to `err_path` (empty: /dev/null).
  explicit ChildProcess(const std::vector<std::string>& args, const std::string& err_path = {}) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(fds[1], STDOUT_FILENO);
      const int err = err_path.empty() ? ::open("/dev/null", O_WRONLY)
                                       : ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(err, STDERR_FILENO);
      std::vector<std::string> copy = args;
      std::vector<char*> argv;
      for (std::string& a : copy) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(fds[1]);
    out_ = fds[0];
  }
  ~ChildProcess() {
    close_output();
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  /// Closes our end of the pipe: the child's next write to stdout fails (a reader that left).
  void close_output() {
    if (out_ >= 0) ::close(out_);
    out_ = -1;
  }
  /// The next line of stdout, waiting at most `timeout_s`; false at the end or on timeout.
  bool read_line(std::string& line, double timeout_s) {
    const Clock::time_point deadline = after(timeout_s);
    for (;;) {
      const size_t newline = buffer_.find('\n');
      if (newline != std::string::npos) {
        line = buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        return true;
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0 || out_ < 0) return false;
      pollfd p{out_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left)) <= 0) return false;
      char chunk[4096];
      const ssize_t n = ::read(out_, chunk, sizeof chunk);
      if (n <= 0) return false;
      buffer_.append(chunk, static_cast<size_t>(n));
    }
  }
  /// Whether the child is still running (not yet reaped).
  bool running() {
    if (reaped_) return false;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      reaped_ = true;
      status_ = status;
    }
    return !reaped_;
  }
  /// Waits at most `timeout_s` for the child to end; its wait status, or -1 after killing it.
  int wait(double timeout_s) {
    const Clock::time_point deadline = after(timeout_s);
    while (running()) {
      if (Clock::now() > deadline) {
        ::kill(pid_, SIGKILL);
        ::waitpid(pid_, nullptr, 0);
        reaped_ = true;
        return -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return status_;
  }
  /// Sends `signal` (0: none, just wait) and waits as wait() does.
  int stop(int signal, double timeout_s) {
    if (signal != 0 && !reaped_) ::kill(pid_, signal);
    return wait(timeout_s);
  }

 private:
  static Clock::time_point after(double seconds) {
    return Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  }

  pid_t pid_ = -1;
  int out_ = -1;
  bool reaped_ = false;
  int status_ = 0;
  std::string buffer_;
};

}  // namespace hrcsense::test
