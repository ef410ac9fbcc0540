// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — `hrcsense fuse`: the decision of a cell with several cameras
// (docs/MULTICAMERA.md). It reads every configured camera's measurements over DDS, fuses each
// scene instant into one measurement (CellFusion), decides it once (SafetyMonitor) and writes it
// as `hrcsense run` does: JSON Lines, the UDP link, RTDE, the ROS 2 outputs.
#pragma once

#include "hrcsense/config/config.hpp"

#include <atomic>
#include <cstdint>
#include <string>

namespace hrcsense::app {

struct FuseOptions {
  int64_t frames = -1;  ///< --frames N: end after N fused instants; -1: when every camera has ended
  std::string out;      ///< --out FILE; empty: stdout
};

/// Runs the fuser until every camera's run has ended (each sent its end), --frames, or a signal
/// (SIGINT, SIGTERM, SIGHUP), then writes a final stop and the summary. Returns the exit code:
/// 0, or 1 when the output failed; throws ConfigError for a configuration without `cameras:`
/// or a build without Cyclone DDS.
int fuse_session(const Config& config, const FuseOptions& options);

/// How long the fuser waits for the other cameras' measurements of an instant after the first
/// arrived: half the fastest camera's period. A camera later than that contributes its older
/// measurement (T_r then counts from its capture).
double fuse_wait_s(const Config& config);

/// The scene clock's epoch the fuser publishes on `<ros2.namespace>/cell_clock` (realtime ns):
/// `sim.epoch` when set, else a second after the fuser's start, so that the cameras started
/// with it have joined before frame 0.
int64_t cell_clock_epoch_ns(const Config& config, int64_t fuser_start_ns);

}  // namespace hrcsense::app
