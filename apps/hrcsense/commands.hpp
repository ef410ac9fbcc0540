// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — the subcommands. Each returns the process exit code and logs to stderr.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::app {

/// Flags shared by the subcommands (DESIGN.md "Names other tools rely on").
struct CommandArgs {
  std::string config_path;          ///< --config FILE
  std::vector<std::string> sets;    ///< repeatable --set KEY=VALUE
  int64_t frames = -1;              ///< --frames N; -1: the source's length
  std::string out;                  ///< --out FILE; empty: stdout
  std::string input;                ///< positional path (info on a recording)
  std::string shared;               ///< verify-filters --shared DIR; empty: ../shared
};

int run_command(const CommandArgs& args);
int info_command(const CommandArgs& args);
int bench_command(const CommandArgs& args);
/// verify-filters CASES_JSON [--shared DIR]: one stdout line per case, last "N/M cases bit-exact".
int verify_filters_command(const CommandArgs& args);

}  // namespace hrcsense::app
