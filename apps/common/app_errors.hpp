// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — one-line error reports and the exit codes they map to.
#pragma once

#include <exception>
#include <string>

namespace hrcsense::app {

/// Exit code for a runtime failure (damaged file, source error).
inline constexpr int kExitRuntime = 1;
/// Exit code for a configuration or usage error.
inline constexpr int kExitUsage = 2;

/// Writes "hrcsense: error: <message>" as one line on stderr and returns `exit_code`.
int report_error(const std::string& message, int exit_code);

/// Reports `error` with the exit code its type implies: ConfigError → 2, anything else → 1.
int report_error(const std::exception& error);

}  // namespace hrcsense::app
