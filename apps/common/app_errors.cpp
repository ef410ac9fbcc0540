// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — one-line error reports and the exit codes they map to.
#include "common/app_errors.hpp"

#include "hrcsense/config/config.hpp"

#include <cstdio>

namespace hrcsense::app {

int report_error(const std::string& message, int exit_code) {
  // Multi-line messages (yaml-cpp, CLI11) are folded so that scripts see exactly one line.
  std::string line = message;
  for (char& ch : line) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  std::fprintf(stderr, "hrcsense: error: %s\n", line.c_str());
  std::fflush(stderr);
  return exit_code;
}

int report_error(const std::exception& error) {
  const bool usage = dynamic_cast<const ConfigError*>(&error) != nullptr;
  return report_error(error.what(), usage ? kExitUsage : kExitRuntime);
}

}  // namespace hrcsense::app
