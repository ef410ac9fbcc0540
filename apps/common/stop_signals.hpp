// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — a command's loop that SIGINT, SIGTERM and SIGHUP end (`record`, `calibrate`).
#pragma once

#include <atomic>

namespace hrcsense::app {

/// While it lives, SIGINT, SIGTERM and SIGHUP set stop_requested() instead of killing the
/// process (a second signal kills: the handler restores the default); the destructor restores
/// the defaults. One at a time per process (a single flag).
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  /// The flag, for CellOptions::stop_requested and the loop's test.
  static std::atomic<bool>& flag();
  static bool stop_requested() { return flag().load(); }
};

}  // namespace hrcsense::app
