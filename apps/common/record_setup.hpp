// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — the recorder's set-up that `hrcsense record`, `hrcsense run --record` and
// `hrcsense-view --record` share.
#pragma once

#include "hrcsense/config/config.hpp"
#include "hrcsense/recordings/recorder.hpp"
#include "hrcsense/sim/sim.hpp"

#include <memory>
#include <string>

namespace hrcsense::app {

/// The recorder of `record` and `run --record` from record.* (creates the file's folder).
RecorderParams recorder_params(const Config& config, const std::string& path, const SourceInfo& info);
/// Logs the files written and the counters (and the error, naming the file) to stderr.
void log_recording(const RecorderStats& stats);
/// How a recording of `source`'s frames finds each frame's robot state: as the run's processing
/// looks it up in `run_states` (paced or not). A `sim` or `fixed` state is asked of a second
/// source of the configuration, made into `own` (the same answers; a late simulated state
/// keeps a history that the recorder's lookups, a frame ahead of processing's, would reset);
/// live and recorded ones are shared (one connection; their lookups change nothing). A `sim`
/// state follows `trajectory_clock` when given (follow_link), as the run's does.
/// Refuses a recording that would destroy a file, before anything is opened: `out` when it
/// exists (with record.split_mb: any existing part of the set, FILE-000.bag, FILE-001.bag, ...)
/// unless `overwrite` (--overwrite), and an output that is the configured source itself
/// (std::filesystem::equivalent: the bag being played) even then. Throws ConfigError (exit 2)
/// naming the file.
void check_record_output(const Config& config, const std::string& out, bool overwrite);

RecordStateLookup record_state_lookup(const Config& config, Source& source, RobotStateSource& run_states, bool paced,
                                      std::unique_ptr<RobotStateSource>& own,
                                      std::shared_ptr<TrajectoryClock> trajectory_clock = nullptr);

}  // namespace hrcsense::app
