// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — what `hrcsense-view --fused` knows of a cell with several cameras, as plain
// values (docs/VIEWER.md, "A cell with several cameras"): each camera's newest foreground cloud,
// depth preview and measurement, and the fused verdict. No Cyclone header here: the viewer's
// model reads these without DDS; FusedViewReader (fused_view_reader.hpp) fills them from the wire.
#pragma once

#include "hrcsense/fusion.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense::ros2 {

/// A decimated depth image as a cell camera publishes it on `<ns>/<NAME>/depth_preview`.
struct DepthPreview {
  int width = 0;
  int height = 0;
  std::vector<uint16_t> depth_mm;  ///< row-major, width · height; 0: no depth
  int64_t timestamp_ns = 0;        ///< the frame's capture stamp
};

/// One configured camera as the viewer last heard it. Ages are the viewer host's shared clock
/// (CLOCK_REALTIME) minus the camera's capture stamps, so they hold across hosts as far as the
/// clocks agree (docs/MULTICAMERA.md, clock sync).
struct FusedCameraView {
  std::string name;
  Pose T_base_camera = Pose::Identity();  ///< the configuration's (the measurement's once one came)
  Intrinsics intrinsics;                  ///< the measurement's; width 0 before one came
  PointCloud cloud_base;                  ///< the newest foreground cloud, robot base frame, m
  int64_t cloud_stamp_ns = 0;             ///< 0: no cloud yet
  DepthPreview preview;                   ///< width 0: none yet
  std::optional<CameraMeasurement> measurement;  ///< the newest readable one
  int64_t measurements = 0;               ///< readable measurements received
  int64_t rejected = 0;                   ///< samples that could not be read (clouds, previews, measurements)
  std::string last_problem;               ///< why the last of them could not
};

/// The fused verdict (`<ns>/verdict` of `hrcsense fuse` with ros2.publish).
struct FusedVerdictView {
  bool received = false;
  VerdictState verdict = VerdictState::stop;
  int reason_code = 0;
  float distance_m = 0.0F;  ///< NaN without a contact
  int governing_link = -1;
  int64_t stamp_ns = 0;     ///< the verdict's stamp (its capture time, shared clock)
  int64_t received_steady_ns = 0;  ///< the viewer's steady clock when it came
};

/// Everything the fused view shows, one entry per configured camera in configuration order.
struct FusedView {
  std::vector<FusedCameraView> cameras;
  FusedVerdictView verdict;
};

/// A camera's age: `now_shared_ns` minus the capture stamp of its newest measurement, ms;
/// none before its first.
inline std::optional<double> camera_age_ms(const FusedCameraView& camera, int64_t now_shared_ns) {
  if (!camera.measurement) return std::nullopt;
  return static_cast<double>(now_shared_ns - camera.measurement->capture_ns) * 1e-6;
}

/// The camera's newest measurement withholds (learning, blocked, no robot state, ...): its last
/// cloud no longer says what it sees, so the view does not draw it. A camera without a
/// measurement yet has nothing to withhold.
inline bool camera_withholds(const FusedCameraView& camera) {
  return camera.measurement && !camera.measurement->valid;
}

}  // namespace hrcsense::ros2
