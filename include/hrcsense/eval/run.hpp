// SPDX-License-Identifier: Apache-2.0
// hrcsense — one evaluation run (`hrcsense eval`): a configured source processed unpaced by
// run_pipeline, as `hrcsense run` would, with every processed frame kept as an EvalSample
// (eval/metrics.hpp) instead of a JSON line. Nothing is pre-rendered: memory stays bounded
// by the samples (a few dozen bytes a frame).
#pragma once

#include "hrcsense/config/config.hpp"
#include "hrcsense/eval/metrics.hpp"

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::eval {

struct EvalRun {
  /// One per processed source frame after background learning (valid frames), in order.
  std::vector<eval::EvalSample> samples;
  int64_t source_frames = 0;  ///< source frames processed, learning included
  std::string error;          ///< the run's error (a source that failed), empty when none
  double wall_s = 0.0;        ///< the run's wall time (RunSummary::wall_s)
  int64_t frames_dropped = 0; ///< frames a paced run dropped (RunSummary::frames_dropped)
};

/// Runs `config`'s source for at most `max_frames` frames (-1: to its end), unpaced unless
/// `source.pace` is set (then at the source's own rate, for an end-to-end rate), learning
/// the background in the run (background.path is neither read nor written). `frames_done`,
/// when given, counts processed frames as they come (for a progress bar on another thread).
EvalRun run_eval(const Config& config, int64_t max_frames, std::atomic<int64_t>* frames_done = nullptr);

}  // namespace hrcsense::eval
