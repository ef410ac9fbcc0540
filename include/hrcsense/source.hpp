// SPDX-License-Identifier: Apache-2.0
// hrcsense — a source of depth frames: one of hrcsense's four one-level virtual interfaces,
// with Sink (sink.hpp), RobotStateSource (robot_state.hpp) and RunClock (clock.hpp). The
// simulator, the recordings and the live cameras implement it.
#pragma once

#include "hrcsense/types.hpp"

#include <cstdint>
#include <string>

namespace hrcsense {

/// What a source says about itself before the first frame.
struct SourceInfo {
  std::string type;             ///< "sim", "folder", "bag", ...
  std::string description;      ///< e.g. the scene or file
  Intrinsics intrinsics;        ///< of the depth stream
  float stereo_baseline_mm = 0.0F;  ///< 0 when unknown
  double nominal_fps = 30.0;    ///< for pacing when frames carry no usable timestamps
  int64_t frame_count = -1;     ///< -1 when unknown
  /// Frames come at the camera's own rate, not when asked for (a live camera, ROS 2 topics):
  /// the watchdog then also fires after safety.max_frame_gap_periods nominal periods.
  bool live = false;
  /// A live camera's own name, serial number and firmware version (empty for other sources);
  /// the JSON header reports them so a log names the device it came from.
  std::string camera_name;
  std::string camera_serial;
  std::string camera_firmware;
  /// The sensor a simulated source imitates ("d435", "structured_light": `sim.sensor`); empty
  /// for other sources, written as null.
  std::string sensor_model;
};

/// A source of depth frames. One of the four virtual interfaces of hrcsense (listed above).
class Source {
 public:
  /// `idle`: a live source had no frame within its own short wait (a silent camera); the run
  /// checks for a stop request and asks again, and its watchdog reports the silence.
  enum class Status { frame, end, error, idle };
  virtual ~Source() = default;
  virtual SourceInfo info() const = 0;
  /// Reads the next frame into `out`, reusing its buffers. After `error`, error() says why.
  /// A live source waits a bounded time (well below a second) and returns `idle` rather than
  /// blocking for ever, so that a stop request ends the run.
  virtual Status next(Frame& out) = 0;
  virtual std::string error() const { return {}; }
  /// Frames the camera produced that never reached next() (frame-number or timestamp gaps,
  /// samples lost in transport): `frames_dropped_camera` in the summary, apart from the
  /// pipeline's own `frames_dropped`. Read after the capture thread has finished.
  virtual int64_t frames_dropped_camera() const { return 0; }
  /// Why no frame arrives, for the watchdog's stop when none came for safety.max_frame_age_s:
  /// no_frame (the default) when the source does not know; a live camera that is unplugged says
  /// camera_disconnected. Called from the output thread while next() runs on the capture
  /// thread: an implementation reads only what is safe to read concurrently (an atomic).
  virtual ReasonCode silence_reason() const { return ReasonCode::no_frame; }
};

}  // namespace hrcsense
