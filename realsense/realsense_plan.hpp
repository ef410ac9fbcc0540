// SPDX-License-Identifier: Apache-2.0
// hrcsense realsense — every decision of the live RealSense camera source, as plain functions and
// small structs over plain values: built and tested everywhere, SDK or not. The adapter
// (realsense_source.cpp, built only with librealsense2) copies the SDK's values into these
// types, asks these functions, and copies the answers back; it decides nothing itself.
#pragma once

#include "hrcsense/types.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense {

/// A problem with the camera or what it offers; what() says what and, where it helps, what the
/// camera offers instead.
class RealSenseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One SDK option for the depth sensor: the SDK's name in snake_case (visual_preset,
/// laser_power, emitter_enabled, exposure, enable_auto_exposure) and the value the SDK takes
/// (a visual preset is its rs2_rs400_visual_preset number).
struct RealSenseOption {
  std::string name;
  float value = 0.0F;
};

/// What the RealSense source is built from; the assembly fills it from `source.*`
/// (docs/CAMERAS.md), which has checked every value against the D435's modes and ranges.
struct RealSenseParams {
  std::string serial;     ///< the camera's serial number; empty: the first camera found
  int width = 848;        ///< depth width, pixels
  int height = 480;       ///< depth height, pixels
  int fps = 30;           ///< depth rate, frames/s
  bool color = false;     ///< stream colour too
  int color_width = 848;  ///< colour width, pixels
  int color_height = 480; ///< colour height, pixels
  int color_fps = 30;     ///< colour rate, frames/s
  /// Applied in this order (a visual preset first: it resets the other options).
  std::vector<RealSenseOption> options;
  int settle_frames = 30;  ///< frames skipped after a start or reconnect while auto exposure settles
  std::string path;        ///< a .bag to play through the SDK instead of a camera; empty: a camera
  bool loop = false;       ///< the .bag starts over at its end
  /// Ends a wait for an unplugged camera (SIGINT, SIGTERM): next() then says `end`. Null: never.
  const std::atomic<bool>* stop_requested = nullptr;
};

/// The one message for a RealSense feature in a build without the SDK: `what` names it
/// ("source.type 'realsense'", "hrcsense devices").
std::string realsense_missing_message(const std::string& what);

// ---- Intrinsics

/// The fields of the SDK's rs2_intrinsics, copied one to one (model is the rs2_distortion number).
struct SdkIntrinsics {
  int width = 0;
  int height = 0;
  float ppx = 0.0F;
  float ppy = 0.0F;
  float fx = 0.0F;
  float fy = 0.0F;
  int model = 0;
  std::array<float, 5> coeffs{};
};

/// hrcsense's Intrinsics from the SDK's; the distortion numbers are the same (types.hpp).
/// Throws RealSenseError for a model number hrcsense does not know, naming it.
Intrinsics intrinsics_from_sdk(const SdkIntrinsics& sdk);

// ---- Profiles

enum class StreamKind { depth, color, infrared, other };

/// One stream profile a camera offers (rs2::video_stream_profile): stream, format as the SDK
/// names it (rs2_format_to_string: "Z16", "RGB8", ...), size and rate.
struct ProfileDescriptor {
  StreamKind stream = StreamKind::other;
  std::string format;
  int width = 0;   ///< pixels
  int height = 0;  ///< pixels
  int fps = 0;     ///< frames/s
};

/// The profiles to start: depth Z16 always, colour RGB8 when RealSenseParams::color.
struct ProfileChoice {
  ProfileDescriptor depth;
  std::optional<ProfileDescriptor> color;
};

/// The profiles the configuration asks for (`source.width`, `source.height`, `source.fps`,
/// `source.color.*`) among those the camera offers. Throws RealSenseError when one is not
/// offered, listing what the camera does offer for that stream; on a USB 2 connection
/// (`usb2`) the message adds usb2_limit_note().
ProfileChoice choose_profiles(const std::vector<ProfileDescriptor>& offered, const RealSenseParams& params, bool usb2);

/// "640x480 @ 30, 15, 6; 480x270 @ 60, 30" — the sizes and rates offered for `stream` in
/// `format`, largest first; "none" when there are none.
std::string offered_text(const std::vector<ProfileDescriptor>& offered, StreamKind stream, const std::string& format);

// ---- USB

/// True for a USB 2 connection, from the SDK's RS2_CAMERA_INFO_USB_TYPE_DESCRIPTOR ("2.1",
/// "2.0"; "3.2" is USB 3). Unknown or empty (a file, a non-USB device): false.
bool is_usb2(const std::string& usb_type);

/// What a USB 2 connection costs a D435: which depth modes remain, and the fix.
std::string usb2_limit_note();

// ---- Options

/// Whether auto exposure is on after `options` are applied: the D435 starts with it on;
/// enable_auto_exposure 0 (or a manual exposure, which config turns into it) switches it off.
bool auto_exposure_on(const std::vector<RealSenseOption>& options);

/// Frames to skip after a start or reconnect while auto exposure settles: `source.settle_frames`
/// with auto exposure on, 0 with it off (a fixed exposure needs no settling).
int frames_to_settle(const RealSenseParams& params);

// ---- Time

/// rs2_timestamp_domain, with the SDK's numbers.
enum class TimestampDomain : int { hardware_clock = 0, system_time = 1, global_time = 2 };

/// Maps a frame's own timestamp (any of the SDK's domains, ms) onto the host's monotonic clock.
/// None of the SDK's domains is that clock (hardware_clock is the camera's, system_time and
/// global_time are the host's wall clock, which can be stepped), so the offset is learnt: the
/// smallest (arrival − timestamp) seen, the frame that travelled fastest. A mapped time is never
/// after the frame's arrival; a frame that arrives more than max_lag_ns after its mapped time,
/// or a change of domain, means the clock jumped (camera reset, wall clock stepped), and the
/// offset is learnt again from that frame.
struct HostClockMapper {
  int64_t max_lag_ns = 200'000'000;  ///< USB transport takes tens of ms; beyond this the clock jumped

  /// The host time of a frame stamped `timestamp_ms` in `domain` that arrived at `arrival_ns`
  /// (host steady clock).
  int64_t host_time_ns(double timestamp_ms, TimestampDomain domain, int64_t arrival_ns);
  /// Forget the offset (after a reconnect: a new device clock).
  void reset() { learnt = false; }

  bool learnt = false;
  TimestampDomain domain = TimestampDomain::hardware_clock;
  int64_t offset_ns = 0;     ///< host = timestamp + offset
  int64_t relearned = 0;     ///< how often the clock jumped
};

/// The frame's own timestamp (ms, as the SDK gives it) in integer ns, rounded.
int64_t timestamp_ms_to_ns(double timestamp_ms);

// ---- Playing a file (source.path names a .bag)

/// The streams to enable when the SDK plays a file: depth (Z16), and colour (RGB8) when
/// RealSenseParams::color; never the file's other streams. With every stream enabled the SDK's
/// pipeline drops the file's first depth frame (it holds it back to match streams nobody reads).
std::vector<StreamKind> file_streams(const RealSenseParams& params);

/// A frame's times as the adapter hands them on.
struct FrameTimes {
  bool deliver = true;        ///< false: the same frame again (a looped file's last frame): skip it
  int64_t timestamp_ns = 0;   ///< Frame::timestamp_ns
  /// Frame::host_time_ns: a live camera's capture time on the host's steady clock; 0 for a file,
  /// so that run_pipeline gives it the host time it gives a bag source (docs/ROBOT.md, "Clocks").
  int64_t host_time_ns = 0;
};

/// Turns the SDK's frame timestamps into hrcsense's, for a live camera or a file.
/// Live: the timestamp as the SDK gives it, the host time mapped by `host_clock`.
/// File: host time 0 (above), and the timestamps of a looped file keep rising as BagSource's do:
/// the SDK starts a file over with earlier timestamps and first hands on the file's last frame
/// again. A frame with the number of the one before and a timestamp not after it is that repeat
/// (in a file whose frames are numbered: numbers that never change say nothing) and is skipped;
/// a timestamp not after the one before starts a lap, placed one nominal period after the
/// last frame delivered, its frames keeping their steps.
struct FrameClock {
  bool from_file = false;
  double nominal_fps = 30.0;   ///< file: the depth stream's rate, which spaces the laps (frames/s)
  HostClockMapper host_clock;  ///< live only

  /// The times of a depth frame stamped `timestamp_ms` in `domain`, numbered `frame_number`, that
  /// arrived at `arrival_ns` (host steady clock).
  FrameTimes times(double timestamp_ms, TimestampDomain domain, uint64_t frame_number, int64_t arrival_ns);
  /// A restart of the camera (reconnect): a new device clock, a new stream.
  void reset();

  bool has_last = false;
  int64_t last_stamp_ns = 0;      ///< the SDK's timestamp of the last frame seen
  uint64_t last_number = 0;       ///< its frame number
  bool numbered = false;          ///< two frames of the file had different numbers
  int64_t lap_offset_ns = 0;      ///< added to the SDK's timestamps of the current lap
  int64_t laps = 0;               ///< how often the file started over
};

// ---- Drops

/// Counts the frames a camera made that never arrived, from gaps in its frame numbers
/// (`frames_dropped_camera`). A number that does not go forward (a reset of the counter, a new
/// stream) or jumps by more than max_gap starts counting afresh; a 32-bit counter that wraps
/// counts the frames across the wrap.
struct FrameGapCounter {
  uint64_t max_gap = 100'000;  ///< beyond this (18 min at 90 frames/s) it is a new stream, not drops

  void add(uint64_t frame_number);
  /// A new stream (reconnect): the next number is not compared with the last.
  void reset() { has_last = false; }

  int64_t dropped = 0;
  bool has_last = false;
  uint64_t last = 0;
};

/// Skips the first frames after a start or reconnect (frames_to_settle) while auto exposure
/// settles, so that background learning never sees them.
struct SettleGate {
  int frames = 0;    ///< to skip after each restart()
  int skipped = 0;   ///< since the last restart()

  /// True when this frame is to be skipped.
  bool skip() {
    if (skipped >= frames) return false;
    ++skipped;
    return true;
  }
  void restart() { skipped = 0; }
};

// ---- Disconnect and reconnect

/// The camera's link, fed the events of the SDK (frames, devices removed and added) and the
/// time: while the camera is gone the source reports camera_disconnected (the pipeline stops)
/// until the same serial is back and streams again. Another camera plugged in is ignored: it
/// is not the calibrated one.
struct CameraLink {
  enum class State {
    streaming,      ///< frames arrive (or the first is awaited after the start)
    disconnected,   ///< the camera was removed; waiting for the same serial
    reconnecting,   ///< the serial is back: the pipeline is (re)started until a frame arrives
  };

  std::string serial;                   ///< the camera's serial number
  int64_t retry_ns = 1'000'000'000;     ///< between attempts to start a camera that is back

  void frame_arrived(int64_t now_ns);
  void device_removed(const std::string& removed_serial, int64_t now_ns);
  void device_added(const std::string& added_serial, int64_t now_ns);
  /// A start of the pipeline after a reconnect failed (the camera is still booting): try again
  /// after retry_ns.
  void restart_failed(int64_t now_ns);
  /// The pipeline was started again: no more attempts until the first frame (or another removal).
  void restart_started() { started = true; }
  /// True when the pipeline is to be started now (reconnecting, not started, and the last
  /// attempt is retry_ns old); the caller then starts it and says restart_started() or, if
  /// that threw, restart_failed().
  bool restart_due(int64_t now_ns);
  /// True when frames are to be read: streaming, or restarted and awaiting the first frame.
  bool readable() const { return state == State::streaming || (state == State::reconnecting && started); }
  /// The reason code while no frames arrive: camera_disconnected while the camera is away,
  /// no_frame otherwise.
  ReasonCode silence_code() const;
  /// For people: "camera 123 disconnected 2.500 s ago, waiting for it" or "" when streaming.
  std::string describe(int64_t now_ns) const;

  State state = State::streaming;
  int64_t disconnected_at_ns = 0;
  int64_t last_attempt_ns = 0;
  bool attempted = false;               ///< a start was tried since the serial came back
  bool started = false;                 ///< the pipeline was started again since the serial came back
  int64_t disconnects = 0;              ///< how often the camera went away
};

// ---- Devices

/// One camera as `hrcsense devices` lists it.
struct DeviceDescriptor {
  std::string name;
  std::string serial;
  std::string firmware;
  std::string usb_type;
  std::vector<ProfileDescriptor> profiles;  ///< all it offers; the listing shows depth Z16
};

/// The text of `hrcsense devices`: one block per camera (name, serial, firmware, USB type, a
/// USB 2 warning, depth profiles), or a line saying none was found.
std::string format_devices(const std::vector<DeviceDescriptor>& devices);

}  // namespace hrcsense
