// SPDX-License-Identifier: Apache-2.0
// hrcsense — what the Pipeline's two source files (pipeline.cpp, pipeline_checks.cpp) share.
#pragma once

#include "hrcsense/pipeline.hpp"

namespace hrcsense::pipeline_detail {

/// Withholds the measurement: not valid, with `code` and `reason` (the reason's buffer reused).
inline void withhold(Measurement& m, ReasonCode code, const char* reason) {
  m.valid = false;
  m.withheld_code = code;
  m.withheld_reason.assign(reason);
}

}  // namespace hrcsense::pipeline_detail
