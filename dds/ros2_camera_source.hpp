// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — `source.type: ros2`: a realsense-ros camera's topics read over Cyclone DDS as
// a Source, no ROS installation needed (docs/CAMERAS.md).
#pragma once

#include "dds/ros2_messages.hpp"
#include "hrcsense/source.hpp"

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

namespace hrcsense::ros2 {

/// The camera never became usable at start-up: no depth CameraInfo within startup_timeout_s,
/// an unusable one, or a stop requested while waiting. The run reports it as its source's
/// error (header, stop, summary; exit 1), not as a configuration error.
class Ros2StartupError : public Ros2Error {
 public:
  using Ros2Error::Ros2Error;
};

struct Ros2SourceParams {
  CameraTopics topics;               ///< ROS 2 names; the DDS ones are "rt" + these
  bool color = true;                 ///< read colour and pair it with depth by stamp
  uint32_t domain_id = 0;
  double startup_timeout_s = 10.0;   ///< for the first depth CameraInfo
  float stereo_baseline_mm = 0.0F;   ///< the topics carry none (source.stereo_baseline_mm)
  /// How long next() waits for a depth image before it returns idle (the run then checks for
  /// a stop; its watchdog reports a silent camera after safety.max_frame_age_s).
  int64_t idle_after_ns = 100'000'000;
  /// Ends the start-up wait early (SIGINT while no camera answers); null: only the timeout does.
  const std::atomic<bool>* stop_requested = nullptr;
};

/// Reads depth Images with their CameraInfo, optional colour and the latched depth→colour
/// Extrinsics. Readers are best-effort and volatile for images and infos (they match any
/// camera node's QoS) and reliable transient-local for the extrinsics. Frames keep the
/// header stamp as timestamp_ns; host_time_ns is the stamp on the host's monotonic clock
/// (host_time_of_stamp). A message of the wrong encoding, size or step is rejected, logged
/// and counted; lost frames (stamp gaps), rejected ones and ones overtaken by a newer image
/// are frames_dropped_camera. When the publisher goes away, next() returns idle until it is
/// back, then frames resume.
class Ros2CameraSource final : public Source {
 public:
  /// Joins the domain and waits for the first depth CameraInfo; throws Ros2StartupError naming
  /// the topic and domain when none comes within startup_timeout_s, when it cannot be used, or
  /// when a stop is requested meanwhile (Ros2Error for a DDS call that fails).
  explicit Ros2CameraSource(Ros2SourceParams params);
  ~Ros2CameraSource() override;
  Ros2CameraSource(const Ros2CameraSource&) = delete;
  Ros2CameraSource& operator=(const Ros2CameraSource&) = delete;

  SourceInfo info() const override;
  Status next(Frame& out) override;
  std::string error() const override { return error_; }
  int64_t frames_dropped_camera() const override;

  int64_t messages_rejected() const { return rejected_.load(); }
  /// Frames missed in the stamps alone (StampGapCounter), without the rejected or overtaken.
  int64_t frames_missed() const { return frames_missed_.load(); }
  /// Times the publisher fell silent for longer than a second and came back.
  int64_t outages() const { return outages_.load(); }
  /// Depth images from another publisher on the topic while the one followed is still there:
  /// two cameras' images are no one stream, so they are dropped (counted in
  /// frames_dropped_camera, warned about once). The first publisher seen is followed; when it
  /// goes away, the next one to send is.
  int64_t images_from_other_publishers() const { return other_publishers_.load(); }

 private:
  struct Dds;
  struct TimedColor {
    int64_t stamp_ns = 0;
    ColorImage image;
    Intrinsics intrinsics;
  };
  void reject(const std::string& topic, int64_t stamp_ns, const std::string& why);
  void take_infos();
  void take_colors();
  bool attach_color(int64_t depth_stamp_ns, Frame& out);
  bool from_followed_publisher(uint64_t publication_handle);

  Ros2SourceParams params_;
  std::unique_ptr<Dds> dds_;
  SourceInfo info_;
  Intrinsics depth_intrinsics_;
  std::optional<Intrinsics> color_intrinsics_;
  std::optional<Extrinsics> depth_to_color_;
  std::deque<TimedColor> colors_;  ///< the newest few, oldest first
  int64_t last_color_wall_ns_ = 0; ///< when a colour image last arrived (wall clock), 0 never
  StampGapCounter gaps_;
  int64_t delivered_ = 0;
  std::atomic<int64_t> rejected_{0};
  std::atomic<int64_t> overtaken_{0};
  std::atomic<int64_t> other_publishers_{0};
  uint64_t followed_publisher_ = 0;  ///< DDS instance handle of the writer whose images are used; 0: none yet
  std::atomic<int64_t> frames_missed_{0};
  std::atomic<int64_t> outages_{0};
  std::string error_;
};

}  // namespace hrcsense::ros2
