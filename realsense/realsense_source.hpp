// SPDX-License-Identifier: Apache-2.0
// hrcsense realsense — the live camera (or a .bag played through the SDK) as a Source: a thin
// adapter over librealsense2, built only where the SDK is installed (CMake finds it). No SDK
// type appears here (the SDK's objects live behind Impl), so the rest of hrcsense compiles
// without its headers; every decision is in realsense_plan.hpp.
#pragma once

#include "realsense/realsense_plan.hpp"

#include "hrcsense/source.hpp"

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace hrcsense {

/// A D400 camera through rs2::pipeline: the configured profiles (848x480 @ 30 by default), the
/// SDK options applied to the depth sensor, frames after auto exposure settled, timestamps
/// mapped to the host's steady clock, frame-number gaps counted, and an unplugged camera
/// reported (camera_disconnected) until the same serial is back. With source.path naming a
/// `.bag`, the same pipeline plays the file, every frame (not in real time), as BagSource would:
/// only the streams asked for, the host time left to run_pipeline, looped timestamps rising
/// (file_streams, FrameClock; docs/CAMERAS.md, "`.bag` playback through the SDK").
class RealSenseSource : public Source {
 public:
  /// Opens and starts the camera or file; throws RealSenseError (no camera, a profile it does
  /// not offer, an option it refuses) or the SDK's own error.
  explicit RealSenseSource(const RealSenseParams& params);
  ~RealSenseSource() override;
  RealSenseSource(const RealSenseSource&) = delete;
  RealSenseSource& operator=(const RealSenseSource&) = delete;

  SourceInfo info() const override;
  Status next(Frame& out) override;
  std::string error() const override;
  int64_t frames_dropped_camera() const override;
  ReasonCode silence_reason() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Every RealSense camera connected, with all its stream profiles (`hrcsense devices`).
std::vector<DeviceDescriptor> list_realsense_devices();

}  // namespace hrcsense
