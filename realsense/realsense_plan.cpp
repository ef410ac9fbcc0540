// SPDX-License-Identifier: Apache-2.0
// hrcsense realsense — the plain decisions of the live camera source (realsense_plan.hpp).
#include "realsense/realsense_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

namespace hrcsense {

std::string realsense_missing_message(const std::string& what) {
  return what + ": this hrcsense was built without the RealSense SDK (librealsense2); install Intel's "
                "librealsense2-dev and rebuild (README, 'Cameras')";
}

Intrinsics intrinsics_from_sdk(const SdkIntrinsics& sdk) {
  if (sdk.model < static_cast<int>(Distortion::none) || sdk.model > static_cast<int>(Distortion::kannala_brandt4)) {
    throw RealSenseError("unknown distortion model " + std::to_string(sdk.model) +
                         " in the camera's intrinsics (hrcsense knows rs2_distortion 0-5)");
  }
  Intrinsics out;
  out.width = sdk.width;
  out.height = sdk.height;
  out.fx = sdk.fx;
  out.fy = sdk.fy;
  out.ppx = sdk.ppx;
  out.ppy = sdk.ppy;
  out.model = static_cast<Distortion>(sdk.model);
  out.coeffs = sdk.coeffs;
  return out;
}

namespace {

const char* stream_name(StreamKind stream) {
  switch (stream) {
    case StreamKind::depth: return "depth";
    case StreamKind::color: return "colour";
    case StreamKind::infrared: return "infrared";
    case StreamKind::other: break;
  }
  return "other";
}

std::string mode_text(int width, int height, int fps) {
  return std::to_string(width) + "x" + std::to_string(height) + " @ " + std::to_string(fps);
}

const ProfileDescriptor* find_profile(const std::vector<ProfileDescriptor>& offered, StreamKind stream,
                                      const std::string& format, int width, int height, int fps) {
  for (const ProfileDescriptor& p : offered) {
    if (p.stream == stream && p.format == format && p.width == width && p.height == height && p.fps == fps) return &p;
  }
  return nullptr;
}

ProfileDescriptor pick(const std::vector<ProfileDescriptor>& offered, StreamKind stream, const std::string& format,
                       int width, int height, int fps, bool usb2, const char* keys) {
  if (const ProfileDescriptor* p = find_profile(offered, stream, format, width, height, fps)) return *p;
  std::string message = "the camera offers no " + std::string(stream_name(stream)) + " " + format + " " +
                        mode_text(width, height, fps) + " (" + keys + "); it offers " +
                        offered_text(offered, stream, format);
  if (usb2) message += "; " + usb2_limit_note();
  throw RealSenseError(message);
}

}  // namespace

std::string offered_text(const std::vector<ProfileDescriptor>& offered, StreamKind stream, const std::string& format) {
  // Sizes largest first (by pixel count, then width), each with its rates fastest first.
  std::map<std::pair<int64_t, int>, std::pair<int, std::vector<int>>, std::greater<>> sizes;
  for (const ProfileDescriptor& p : offered) {
    if (p.stream != stream || p.format != format) continue;
    auto& entry = sizes[{int64_t{p.width} * p.height, p.width}];
    entry.first = p.height;
    if (std::find(entry.second.begin(), entry.second.end(), p.fps) == entry.second.end()) entry.second.push_back(p.fps);
  }
  if (sizes.empty()) return "none";
  std::string text;
  for (auto& [key, entry] : sizes) {
    std::sort(entry.second.begin(), entry.second.end(), std::greater<>());
    text += (text.empty() ? "" : "; ") + std::to_string(key.second) + "x" + std::to_string(entry.first) + " @ ";
    for (size_t i = 0; i < entry.second.size(); ++i) text += (i == 0 ? "" : ", ") + std::to_string(entry.second[i]);
  }
  return text;
}

ProfileChoice choose_profiles(const std::vector<ProfileDescriptor>& offered, const RealSenseParams& params, bool usb2) {
  ProfileChoice choice;
  choice.depth = pick(offered, StreamKind::depth, "Z16", params.width, params.height, params.fps, usb2,
                      "source.width, source.height, source.fps");
  if (params.color) {
    choice.color = pick(offered, StreamKind::color, "RGB8", params.color_width, params.color_height, params.color_fps,
                        usb2, "source.color");
  }
  return choice;
}

bool is_usb2(const std::string& usb_type) { return !usb_type.empty() && usb_type[0] == '2'; }

std::string usb2_limit_note() {
  return "the camera is on a USB 2 connection, where a D435 gives depth at most 640x480 @ 30 (1280x720 only "
         "@ 6; no 848x480, no 90 frames/s); plug it into a USB 3 port with a USB 3 cable";
}

bool auto_exposure_on(const std::vector<RealSenseOption>& options) {
  bool on = true;  // the D435's depth sensor starts with auto exposure on
  for (const RealSenseOption& option : options) {
    if (option.name == "enable_auto_exposure") on = option.value != 0.0F;
  }
  return on;
}

int frames_to_settle(const RealSenseParams& params) {
  return auto_exposure_on(params.options) ? params.settle_frames : 0;
}

int64_t timestamp_ms_to_ns(double timestamp_ms) {
  // Beyond ±9.2e12 ms (292 years) int64 ns overflow; no camera clock gets there, clamp anyway.
  constexpr double kMaxMs = 9.2e12;
  if (!std::isfinite(timestamp_ms)) return 0;
  return std::llround(std::clamp(timestamp_ms, -kMaxMs, kMaxMs) * 1e6);
}

int64_t HostClockMapper::host_time_ns(double timestamp_ms, TimestampDomain frame_domain, int64_t arrival_ns) {
  const int64_t stamp_ns = timestamp_ms_to_ns(timestamp_ms);
  const int64_t candidate_ns = arrival_ns - stamp_ns;
  if (learnt && frame_domain == domain) {
    offset_ns = std::min(offset_ns, candidate_ns);  // a faster frame: a tighter offset
    const int64_t mapped_ns = stamp_ns + offset_ns;
    if (arrival_ns - mapped_ns <= max_lag_ns) return mapped_ns;
    ++relearned;  // the clock jumped: learn again from this frame
  } else if (learnt) {
    ++relearned;  // a new domain (metadata appeared or vanished): a new clock
  }
  learnt = true;
  domain = frame_domain;
  offset_ns = candidate_ns;
  return arrival_ns;
}

std::vector<StreamKind> file_streams(const RealSenseParams& params) {
  std::vector<StreamKind> streams = {StreamKind::depth};
  if (params.color) streams.push_back(StreamKind::color);
  return streams;
}

FrameTimes FrameClock::times(double timestamp_ms, TimestampDomain domain, uint64_t frame_number,
                             int64_t arrival_ns) {
  FrameTimes out;
  const int64_t stamp_ns = timestamp_ms_to_ns(timestamp_ms);
  if (!from_file) {
    out.timestamp_ns = stamp_ns;
    out.host_time_ns = host_clock.host_time_ns(timestamp_ms, domain, arrival_ns);
    return out;
  }
  if (has_last) {
    if (frame_number != last_number) numbered = true;
    if (numbered && frame_number == last_number && stamp_ns <= last_stamp_ns) {
      out.deliver = false;  // the same frame again: the previous one was delivered
      return out;
    }
    if (stamp_ns <= last_stamp_ns) {  // earlier, or a one-frame file again: timestamps must rise
      // A new lap: its first frame one nominal period after the last one delivered.
      const double fps = nominal_fps > 0.0 ? nominal_fps : 30.0;
      lap_offset_ns = last_stamp_ns + lap_offset_ns + std::llround(1e9 / fps) - stamp_ns;
      ++laps;
    }
  }
  has_last = true;
  last_stamp_ns = stamp_ns;
  last_number = frame_number;
  out.timestamp_ns = stamp_ns + lap_offset_ns;
  return out;  // host_time_ns 0: run_pipeline decides, as for every recorded source
}

void FrameClock::reset() {
  host_clock.reset();
  has_last = false;
  numbered = false;
  lap_offset_ns = 0;
}

void FrameGapCounter::add(uint64_t frame_number) {
  constexpr uint64_t kWrap32 = uint64_t{1} << 32;
  if (has_last) {
    if (frame_number > last && frame_number - last <= max_gap) {
      dropped += static_cast<int64_t>(frame_number - last - 1);
    } else if (frame_number < last && last < kWrap32 && kWrap32 - last + frame_number <= max_gap) {
      dropped += static_cast<int64_t>(kWrap32 - last + frame_number - 1);  // a 32-bit counter wrapped
    }
    // Anything else (repeated, backwards, a huge jump) is a new stream: nothing counted.
  }
  has_last = true;
  last = frame_number;
}

void CameraLink::frame_arrived(int64_t /*now_ns*/) {
  // A frame still queued from before a removal does not bring the camera back.
  if (state == State::reconnecting) state = State::streaming;
}

void CameraLink::device_removed(const std::string& removed_serial, int64_t now_ns) {
  if (removed_serial != serial || state == State::disconnected) return;
  state = State::disconnected;
  disconnected_at_ns = now_ns;
  attempted = false;
  started = false;
  ++disconnects;
}

void CameraLink::device_added(const std::string& added_serial, int64_t /*now_ns*/) {
  if (added_serial != serial || state != State::disconnected) return;
  state = State::reconnecting;
  attempted = false;
  started = false;
}

void CameraLink::restart_failed(int64_t now_ns) {
  attempted = true;
  last_attempt_ns = now_ns;
}

bool CameraLink::restart_due(int64_t now_ns) {
  if (state != State::reconnecting || started) return false;
  if (attempted && now_ns - last_attempt_ns < retry_ns) return false;
  attempted = true;
  last_attempt_ns = now_ns;
  return true;
}

ReasonCode CameraLink::silence_code() const {
  return state == State::streaming ? ReasonCode::no_frame : ReasonCode::camera_disconnected;
}

std::string CameraLink::describe(int64_t now_ns) const {
  if (state == State::streaming) return {};
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.3f", static_cast<double>(now_ns - disconnected_at_ns) * 1e-9);
  return "camera " + serial + " disconnected " + seconds + " s ago, " +
         (state == State::disconnected ? "waiting for it" : "restarting it");
}

std::string format_devices(const std::vector<DeviceDescriptor>& devices) {
  if (devices.empty()) return "no RealSense camera found\n";
  std::string text;
  for (const DeviceDescriptor& d : devices) {
    text += d.name + "\n  serial: " + d.serial + "\n  firmware: " + d.firmware + "\n  usb: " +
            (d.usb_type.empty() ? std::string("unknown") : d.usb_type) + "\n";
    if (is_usb2(d.usb_type)) text += "  warning: " + usb2_limit_note() + "\n";
    text += "  depth (Z16): " + offered_text(d.profiles, StreamKind::depth, "Z16") + "\n";
    text += "  colour (RGB8): " + offered_text(d.profiles, StreamKind::color, "RGB8") + "\n";
  }
  return text;
}

}  // namespace hrcsense
