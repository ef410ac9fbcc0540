// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense verify-filters CASES_JSON [--shared DIR]`: runs every case of a
// golden file made by the real RealSense SDK (data/sdk_filter_goldens format) through
// hrcsense's filters and compares every output value for value (verify_filter_goldens,
// hrcsense/eval/goldens.hpp), then prints one line per case and the count of bit-exact ones.
#include "common/app_errors.hpp"
#include "commands.hpp"

#include "hrcsense/eval/goldens.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <string>

namespace hrcsense::app {
namespace {

// A case's stdout line: "NAME: match (K outputs)", "NAME: DIFFERENT (…)" or "NAME: ERROR (…)".
// Other tools read these lines: their text stays as it is.
std::string case_line(const eval::GoldenCaseResult& c) {
  if (!c.error.empty()) return c.name + ": ERROR (" + c.error + ")";
  char text[160];
  if (!c.problem.empty()) {
    std::snprintf(text, sizeof text, "%s: DIFFERENT (%s; %zu values differ, largest difference %g)", c.name.c_str(),
                  c.problem.c_str(), c.values_differing, c.largest_difference);
  } else if (c.values_differing > 0) {
    std::snprintf(text, sizeof text, "%s: DIFFERENT (%zu values differ, largest difference %g)", c.name.c_str(),
                  c.values_differing, c.largest_difference);
  } else {
    std::snprintf(text, sizeof text, "%s: match (%zu outputs)", c.name.c_str(), c.outputs_checked);
  }
  return text;
}

}  // namespace

int verify_filters_command(const CommandArgs& args) {
  const std::string shared_dir = args.shared.empty() ? "../shared" : args.shared;
  eval::GoldenReport report;
  try {
    report = eval::verify_filter_goldens(args.input, shared_dir);
  } catch (const eval::GoldenFileError& e) {
    return report_error(e.what(), kExitUsage);
  }
  for (const eval::GoldenCaseResult& c : report.cases) {
    if (!c.error.empty()) spdlog::error("{}: {}", args.input, c.error);
    std::printf("%s\n", case_line(c).c_str());
  }
  const size_t exact = report.bit_exact();
  std::printf("%zu/%zu cases bit-exact\n", exact, report.cases.size());
  std::fflush(stdout);
  spdlog::info("{}: {} of {} cases bit-exact", args.input, exact, report.cases.size());
  return exact == report.cases.size() ? 0 : kExitRuntime;
}

}  // namespace hrcsense::app
