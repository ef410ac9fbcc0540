// SPDX-License-Identifier: Apache-2.0
// Tests that drive the pipeline frame by frame: the measurement, then the decision a run's
// SafetyMonitor makes of it.
#pragma once

#include "hrcsense/pipeline.hpp"
#include "hrcsense/safety.hpp"

namespace hrcsense::test {

/// Pipeline::process, then the decision of a fresh SafetyMonitor (no hold, no history; an age of
/// 0), as run_pipeline's output thread makes it.
inline void process_and_decide(Pipeline& pipeline, const Frame& frame, const RobotState& state, FrameResult& result) {
  pipeline.process(frame, state, result);
  SafetyMonitor monitor(pipeline.params().safety);
  monitor.decide(result, 0);
}

}  // namespace hrcsense::test
