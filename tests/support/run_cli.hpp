// SPDX-License-Identifier: Apache-2.0
// Test support: runs the `hrcsense` command line (HRCSENSE_CLI) and captures what it prints.
#pragma once

#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace hrcsense::test {

struct CliResult {
  int exit_code = -1;
  std::string out;  ///< stdout and stderr together
};

inline CliResult cli(const std::string& arguments) {
  CliResult result;
  const std::string command = std::string(HRCSENSE_CLI) + " " + arguments + " 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.out.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace hrcsense::test
