// SPDX-License-Identifier: Apache-2.0
// hrcsense — what the Pipeline's two source files (pipeline.cpp, pipeline_checks.cpp) share.
#pragma once

#include "hrcsense/pipeline.hpp"

#include <chrono>

namespace hrcsense::pipeline_detail {

/// Withholds the measurement: not valid, with `code` and `reason` (the reason's buffer reused).
inline void withhold(Measurement& m, ReasonCode code, const char* reason) {
  m.valid = false;
  m.withheld_code = code;
  m.withheld_reason.assign(reason);
}

/// Runs `stage` and appends its duration to `m`'s timings under the static name `name`.
template <typename Stage>
void timed_stage(Measurement& m, const char* name, Stage&& stage) {
  const auto start = std::chrono::steady_clock::now();
  stage();
  m.timings.push_back({name, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count()});
}

}  // namespace hrcsense::pipeline_detail
