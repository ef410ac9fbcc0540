// SPDX-License-Identifier: Apache-2.0
// hrcsense — a cell with several cameras (docs/MULTICAMERA.md): each camera's process measures
// and publishes a CameraMeasurement; the fuser keeps the newest of each camera and makes one
// Measurement for the cell's SafetyMonitor: per robot link the nearest contact over the
// cameras, T_r from the oldest contributing capture, a stop naming the camera when one is
// stale, restarted, or stops itself.
#pragma once

#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/types.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {

/// What one camera's process sends for one of its frames: everything the decision needs and
/// nothing of the image. Times are on the cell's shared clock: CLOCK_REALTIME ns, kept in step
/// across hosts by chrony or PTP (docs/MULTICAMERA.md, "Clocks").
struct CameraMeasurement {
  std::string camera_name;   ///< the scene's `cameras:` entry (a ROS name token)
  uint32_t session = 0;      ///< random per process start: a new value is a restart
  uint64_t sequence = 0;     ///< 1 for a session's first measurement, +1 per measurement
  int64_t frame = 0;         ///< the camera's frame index (simulated: the scene frame)
  int64_t capture_ns = 0;    ///< when the frame was captured, the shared clock
  double nominal_fps = 0.0;  ///< the camera's nominal rate (the stale rule counts its periods)
  Intrinsics intrinsics;     ///< of the depth image measured (the fused header shows it)
  Pose T_base_camera = Pose::Identity();  ///< the pose the camera measured with
  /// The measurement can be decided on; false: `reason_code` / `reason` say why (a stop).
  bool valid = false;
  ReasonCode reason_code = ReasonCode::no_valid_depth;
  std::string reason;
  Contact contact;                ///< the camera's overall closest pair; invalid: no foreground
  std::vector<LinkContact> links; ///< per link with a contact, link order
  /// The camera's own per-ray unknown distance (docs/SAFETY.md), m; NaN: none known.
  float unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
  SeenFreeGrid seen_free;         ///< cubes of the shared grid seen free; cells 0: none computed
  uint32_t foreground_points = 0;
  uint32_t self_filtered_pixels = 0;
  uint32_t invalid_pixels = 0;
  float valid_share = 0.0F;
  /// The robot state the capsules were built from (its sample time on the shared clock).
  RobotState robot_state;
  double robot_state_age_ms = 0.0;
  /// Processing time, frame in to measurement out, µs (the fused latency's camera part).
  double latency_us = 0.0;
  /// Simulated cameras: the truth for this camera's pixels (GroundTruth::contact, ::links).
  std::optional<Contact> truth;
  std::vector<LinkTruth> truth_links;
};

}  // namespace hrcsense
