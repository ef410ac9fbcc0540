// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — the stop signals of a command's loop (stop_signals.hpp).
#include "common/stop_signals.hpp"

#include <csignal>

namespace hrcsense::app {
namespace {

extern "C" void on_command_stop_signal(int signal) {
  StopSignals::flag().store(true);
  std::signal(signal, SIG_DFL);  // a second one kills
}

constexpr int kCommandStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

}  // namespace

std::atomic<bool>& StopSignals::flag() {
  static std::atomic<bool> stop{false};
  return stop;
}

StopSignals::StopSignals() {
  flag().store(false);
  for (const int signal : kCommandStopSignals) std::signal(signal, on_command_stop_signal);
}

StopSignals::~StopSignals() {
  for (const int signal : kCommandStopSignals) std::signal(signal, SIG_DFL);
}

}  // namespace hrcsense::app
