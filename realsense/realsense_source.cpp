// SPDX-License-Identifier: Apache-2.0
// hrcsense realsense — RealSenseSource over librealsense2's rs2::pipeline. Only copying between
// the SDK's types and hrcsense's happens here; every decision is a plain function of
// realsense_plan.hpp (tested without the SDK). Built only where the SDK is installed.
#include "realsense/realsense_source.hpp"

#include <librealsense2/rs.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <iterator>
#include <mutex>
#include <optional>

namespace hrcsense {
namespace {

/// How long one wait for a frameset lasts before the link and the stop request are looked at.
constexpr unsigned int kFrameWaitMs = 100;

int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string info_or_empty(const rs2::device& device, rs2_camera_info field) {
  return device.supports(field) ? std::string(device.get_info(field)) : std::string();
}

StreamKind stream_kind(rs2_stream stream) {
  switch (stream) {
    case RS2_STREAM_DEPTH: return StreamKind::depth;
    case RS2_STREAM_COLOR: return StreamKind::color;
    case RS2_STREAM_INFRARED: return StreamKind::infrared;
    default: return StreamKind::other;
  }
}

std::vector<ProfileDescriptor> device_profiles(const rs2::device& device) {
  std::vector<ProfileDescriptor> out;
  for (const rs2::sensor& sensor : device.query_sensors()) {
    for (const rs2::stream_profile& profile : sensor.get_stream_profiles()) {
      if (!profile.is<rs2::video_stream_profile>()) continue;
      const auto video = profile.as<rs2::video_stream_profile>();
      out.push_back({stream_kind(profile.stream_type()), rs2_format_to_string(profile.format()), video.width(),
                     video.height(), profile.fps()});
    }
  }
  return out;
}

SdkIntrinsics sdk_intrinsics(const rs2::video_stream_profile& profile) {
  const rs2_intrinsics in = profile.get_intrinsics();
  SdkIntrinsics out{in.width, in.height, in.ppx, in.ppy, in.fx, in.fy, static_cast<int>(in.model), {}};
  std::copy(std::begin(in.coeffs), std::end(in.coeffs), out.coeffs.begin());
  return out;
}

Extrinsics extrinsics_between(const rs2::stream_profile& from, const rs2::stream_profile& to) {
  const rs2_extrinsics e = from.get_extrinsics_to(to);  // column-major rotation, metres: as ours
  Extrinsics out;
  std::copy(std::begin(e.rotation), std::end(e.rotation), out.rotation.begin());
  std::copy(std::begin(e.translation), std::end(e.translation), out.translation_m.begin());
  return out;
}

/// The SDK's option for a `source.options` name (the names are the SDK's, in snake_case).
rs2_option sdk_option(const std::string& name) {
  if (name == "visual_preset") return RS2_OPTION_VISUAL_PRESET;
  if (name == "laser_power") return RS2_OPTION_LASER_POWER;
  if (name == "emitter_enabled") return RS2_OPTION_EMITTER_ENABLED;
  if (name == "exposure") return RS2_OPTION_EXPOSURE;
  if (name == "enable_auto_exposure") return RS2_OPTION_ENABLE_AUTO_EXPOSURE;
  throw RealSenseError("source.options." + name + ": not an option hrcsense sets");
}

/// Applies the options in their order; one the sensor lacks, or a value beyond the camera's
/// own range (another model or firmware than the D435 the configuration checked for), names the key.
void apply_options(const rs2::sensor& depth_sensor, const std::vector<RealSenseOption>& options) {
  for (const RealSenseOption& option : options) {
    const rs2_option id = sdk_option(option.name);
    const std::string key = "source.options." + option.name;
    if (!depth_sensor.supports(id)) throw RealSenseError(key + ": the camera's depth sensor has no such option");
    const rs2::option_range range = depth_sensor.get_option_range(id);
    if (option.value < range.min || option.value > range.max) {
      throw RealSenseError(key + ": " + std::to_string(option.value) + " is outside the camera's range [" +
                           std::to_string(range.min) + ", " + std::to_string(range.max) + "]");
    }
    depth_sensor.set_option(id, option.value);
  }
}

}  // namespace

struct RealSenseSource::Impl {
  RealSenseParams params;
  rs2::context context;
  rs2::pipeline pipeline{context};
  rs2::config config;
  rs2::device device;
  rs2::pipeline_profile profile;
  bool from_file = false;
  SourceInfo info;
  float depth_scale_m = 0.001F;
  std::optional<Extrinsics> depth_to_color;
  Intrinsics color_intrinsics;

  // The link is fed from the SDK's callback thread and read by the watchdog: under the mutex,
  // its silence code mirrored in an atomic for silence_reason().
  std::mutex mutex;
  std::condition_variable changed;
  CameraLink link;
  std::atomic<ReasonCode> silence{ReasonCode::no_frame};

  FrameClock clock;
  FrameGapCounter gaps;
  SettleGate settle;
  std::string error;
  int64_t index = 0;

  explicit Impl(const RealSenseParams& p) : params(p) {
    from_file = !params.path.empty();
    if (from_file) {
      config.enable_device_from_file(params.path, params.loop);
      // Only the streams asked for: with all of the file's, the SDK drops its first depth frame.
      for (const StreamKind stream : file_streams(params)) {
        if (stream == StreamKind::depth) config.enable_stream(RS2_STREAM_DEPTH, RS2_FORMAT_Z16);
        if (stream == StreamKind::color) config.enable_stream(RS2_STREAM_COLOR, RS2_FORMAT_RGB8);
      }
    } else {
      select_camera();
    }
    start();
    if (!from_file) {
      link.serial = info.camera_serial;
      context.set_devices_changed_callback([this](rs2::event_information& event) { on_devices_changed(event); });
    }
  }

  // The configured serial, or the first camera; its profiles decide what is enabled.
  void select_camera() {
    const rs2::device_list devices = context.query_devices();
    for (const rs2::device& candidate : devices) {
      const std::string serial = info_or_empty(candidate, RS2_CAMERA_INFO_SERIAL_NUMBER);
      if (params.serial.empty() || serial == params.serial) {
        device = candidate;
        break;
      }
    }
    if (!device) {
      throw RealSenseError(params.serial.empty() ? "no RealSense camera found ('hrcsense devices' lists them)"
                                                 : "no RealSense camera with serial " + params.serial +
                                                       " ('hrcsense devices' lists them)");
    }
    const bool usb2 = is_usb2(info_or_empty(device, RS2_CAMERA_INFO_USB_TYPE_DESCRIPTOR));
    const ProfileChoice choice = choose_profiles(device_profiles(device), params, usb2);
    config.enable_device(info_or_empty(device, RS2_CAMERA_INFO_SERIAL_NUMBER));
    config.enable_stream(RS2_STREAM_DEPTH, choice.depth.width, choice.depth.height, RS2_FORMAT_Z16, choice.depth.fps);
    if (choice.color) {
      config.enable_stream(RS2_STREAM_COLOR, choice.color->width, choice.color->height, RS2_FORMAT_RGB8,
                           choice.color->fps);
    }
  }

  // Starts the pipeline (again, after a reconnect) and reads what the frames need.
  void start() {
    profile = pipeline.start(config);
    {
      std::lock_guard<std::mutex> lock(mutex);  // the devices-changed callback reads `device`
      device = profile.get_device();
    }
    const rs2::depth_sensor depth_sensor = device.first<rs2::depth_sensor>();
    if (auto playback = device.as<rs2::playback>()) {
      playback.set_real_time(false);  // every frame of the file, as fast as processing takes them
    } else {
      apply_options(depth_sensor, params.options);
    }
    depth_scale_m = depth_sensor.get_depth_scale();
    const auto depth = profile.get_stream(RS2_STREAM_DEPTH).as<rs2::video_stream_profile>();
    info.type = "realsense";
    info.live = !device.as<rs2::playback>();  // a file played through the SDK comes when asked
    info.intrinsics = intrinsics_from_sdk(sdk_intrinsics(depth));
    info.nominal_fps = depth.fps();
    info.camera_name = info_or_empty(device, RS2_CAMERA_INFO_NAME);
    info.camera_serial = info_or_empty(device, RS2_CAMERA_INFO_SERIAL_NUMBER);
    info.camera_firmware = info_or_empty(device, RS2_CAMERA_INFO_FIRMWARE_VERSION);
    const std::string usb = info_or_empty(device, RS2_CAMERA_INFO_USB_TYPE_DESCRIPTOR);
    info.description = from_file ? params.path : info.camera_name + (usb.empty() ? "" : ", USB " + usb);
    if (is_usb2(usb)) info.description += "; " + usb2_limit_note();
    // The stereo baseline: the sensor's own option (mm), else the depth → infrared 2 extrinsics.
    if (depth_sensor.supports(RS2_OPTION_STEREO_BASELINE)) {
      info.stereo_baseline_mm = depth_sensor.get_option(RS2_OPTION_STEREO_BASELINE);
    } else {
      for (const rs2::stream_profile& p : depth_sensor.get_stream_profiles()) {
        if (p.stream_type() == RS2_STREAM_INFRARED && p.stream_index() == 2) {
          info.stereo_baseline_mm = 1000.0F * std::abs(extrinsics_between(depth, p).translation_m[0]);
          break;
        }
      }
    }
    depth_to_color.reset();
    color_intrinsics = Intrinsics{};
    for (const rs2::stream_profile& p : profile.get_streams()) {
      if (p.stream_type() != RS2_STREAM_COLOR || p.format() != RS2_FORMAT_RGB8) continue;
      depth_to_color = extrinsics_between(depth, p);
      color_intrinsics = intrinsics_from_sdk(sdk_intrinsics(p.as<rs2::video_stream_profile>()));
    }
    clock.reset();
    clock.from_file = from_file;
    clock.nominal_fps = info.nominal_fps;
    gaps.reset();
    settle.frames = from_file ? 0 : frames_to_settle(params);  // a file's exposure settled when it was made
    settle.restart();
  }

  void on_devices_changed(rs2::event_information& event) {
    const int64_t now_ns = steady_now_ns();
    std::lock_guard<std::mutex> lock(mutex);
    if (event.was_removed(device)) link.device_removed(link.serial, now_ns);
    for (const rs2::device& added : event.get_new_devices()) {
      link.device_added(info_or_empty(added, RS2_CAMERA_INFO_SERIAL_NUMBER), now_ns);
    }
    silence = link.silence_code();
    changed.notify_all();
  }

  bool stop_requested() const { return params.stop_requested != nullptr && params.stop_requested->load(); }

  // While the camera is away: waits, and restarts it when its serial is back. True when the
  // pipeline may be read now.
  bool link_ready() {
    std::unique_lock<std::mutex> lock(mutex);
    const int64_t now_ns = steady_now_ns();
    if (link.readable()) return true;
    if (!link.restart_due(now_ns)) {
      changed.wait_for(lock, std::chrono::milliseconds(kFrameWaitMs));
      return false;
    }
    lock.unlock();
    try {
      try {
        pipeline.stop();
      } catch (const rs2::error&) {
        // the old pipeline may have gone with the device
      }
      start();
      lock.lock();
      link.restart_started();
      return true;
    } catch (const std::exception&) {
      if (!lock.owns_lock()) lock.lock();
      link.restart_failed(now_ns);  // still booting: again after retry_ns
      return false;
    }
  }

  void copy_frame(const rs2::frameset& frames, const rs2::depth_frame& depth, const FrameTimes& times, Frame& out) {
    out.index = index++;
    out.timestamp_ns = times.timestamp_ns;
    out.host_time_ns = times.host_time_ns;
    out.intrinsics = info.intrinsics;
    out.stereo_baseline_mm = info.stereo_baseline_mm;
    out.depth.depth_scale_m = depth_scale_m;
    out.depth.resize(depth.get_width(), depth.get_height());
    const auto* row = static_cast<const uint8_t*>(depth.get_data());
    const size_t row_bytes = static_cast<size_t>(depth.get_width()) * sizeof(uint16_t);
    for (int v = 0; v < depth.get_height(); ++v) {
      std::memcpy(out.depth.pixels.data() + static_cast<size_t>(v) * depth.get_width(),
                  row + static_cast<size_t>(v) * depth.get_stride_in_bytes(), row_bytes);
    }
    out.color.reset();
    out.color_intrinsics = Intrinsics{};
    out.depth_to_color.reset();
    const rs2::video_frame color = frames.get_color_frame();
    if (color && depth_to_color && color.get_profile().format() == RS2_FORMAT_RGB8) {
      ColorImage& image = out.color.emplace();
      image.width = color.get_width();
      image.height = color.get_height();
      image.rgb.resize(static_cast<size_t>(image.width) * image.height * 3);
      const auto* src = static_cast<const uint8_t*>(color.get_data());
      for (int v = 0; v < image.height; ++v) {
        std::memcpy(image.rgb.data() + static_cast<size_t>(v) * image.width * 3,
                    src + static_cast<size_t>(v) * color.get_stride_in_bytes(), static_cast<size_t>(image.width) * 3);
      }
      out.color_intrinsics = color_intrinsics;
      out.depth_to_color = depth_to_color;
    }
  }

  Status next(Frame& out) {
    for (;;) {
      if (stop_requested()) return Status::end;
      if (!from_file && !link_ready()) continue;
      rs2::frameset frames;
      bool got = false;
      try {
        got = pipeline.try_wait_for_frames(&frames, kFrameWaitMs);
      } catch (const rs2::error& e) {
        if (from_file) {
          error = e.what();
          return Status::error;
        }
        continue;  // the camera went away under the wait: the removal event says so
      }
      if (!got) {
        if (from_file) {
          const auto playback = device.as<rs2::playback>();
          if (playback && playback.current_status() == RS2_PLAYBACK_STATUS_STOPPED) return Status::end;
        }
        continue;  // a stall: the watchdog stops the robot meanwhile
      }
      const int64_t arrival_ns = steady_now_ns();
      const rs2::depth_frame depth = frames.get_depth_frame();
      if (!depth) continue;
      {
        std::lock_guard<std::mutex> lock(mutex);
        link.frame_arrived(arrival_ns);
        silence = link.silence_code();
      }
      const FrameTimes times =
          clock.times(depth.get_timestamp(), static_cast<TimestampDomain>(depth.get_frame_timestamp_domain()),
                      depth.get_frame_number(), arrival_ns);
      if (!times.deliver) continue;  // a looped file's last frame, handed on again
      gaps.add(depth.get_frame_number());
      if (settle.skip()) continue;  // auto exposure still settling: not for background learning
      copy_frame(frames, depth, times, out);
      return Status::frame;
    }
  }
};

RealSenseSource::RealSenseSource(const RealSenseParams& params) : impl_(std::make_unique<Impl>(params)) {}
RealSenseSource::~RealSenseSource() {
  try {
    impl_->pipeline.stop();
  } catch (const std::exception&) {
    // already stopped, or the camera is gone
  }
}
SourceInfo RealSenseSource::info() const { return impl_->info; }
Source::Status RealSenseSource::next(Frame& out) { return impl_->next(out); }
std::string RealSenseSource::error() const { return impl_->error; }
int64_t RealSenseSource::frames_dropped_camera() const { return impl_->gaps.dropped; }
ReasonCode RealSenseSource::silence_reason() const { return impl_->silence.load(); }

std::vector<DeviceDescriptor> list_realsense_devices() {
  std::vector<DeviceDescriptor> out;
  rs2::context context;
  for (const rs2::device& device : context.query_devices()) {
    out.push_back({info_or_empty(device, RS2_CAMERA_INFO_NAME), info_or_empty(device, RS2_CAMERA_INFO_SERIAL_NUMBER),
                   info_or_empty(device, RS2_CAMERA_INFO_FIRMWARE_VERSION),
                   info_or_empty(device, RS2_CAMERA_INFO_USB_TYPE_DESCRIPTOR), device_profiles(device)});
  }
  return out;
}

}  // namespace hrcsense
