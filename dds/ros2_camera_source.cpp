// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the ROS 2 camera source (ros2_camera_source.hpp).
#include "dds/ros2_camera_source.hpp"

#include "dds/dds_entity.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>

namespace hrcsense::ros2 {
namespace {

int64_t wall_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int64_t monotonic_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Samples taken per call: the newest is used, older ones were overtaken (a slow pipeline).
constexpr uint32_t kMaxTake = 4;
// Colour images kept for pairing, and how long a depth image waits for its colour.
constexpr size_t kColorsKept = 4;
constexpr int64_t kColorWaitNs = 20'000'000;
// Stamps within this of each other pair a colour image with a depth image, when the rate is
// not known yet (half a period at 30 frames/s).
constexpr int64_t kDefaultPairingNs = 16'000'000;

// Loaned samples of one take, returned to the reader when this goes out of scope.
template <typename T>
class Taken {
 public:
  explicit Taken(dds_entity_t reader) : reader_(reader) {
    count_ = dds_take(reader_, samples_.data(), infos_.data(), kMaxTake, kMaxTake);
    if (count_ < 0) count_ = 0;  // a reader that failed reads as empty; the next call tries again
  }
  Taken(const Taken&) = delete;
  Taken& operator=(const Taken&) = delete;
  ~Taken() {
    if (count_ > 0) dds_return_loan(reader_, samples_.data(), count_);
  }
  int32_t size() const { return count_; }
  bool valid(int32_t i) const { return infos_[static_cast<size_t>(i)].valid_data; }
  const T& operator[](int32_t i) const { return *static_cast<const T*>(samples_[static_cast<size_t>(i)]); }
  dds_instance_handle_t publisher(int32_t i) const { return infos_[static_cast<size_t>(i)].publication_handle; }

 private:
  dds_entity_t reader_;
  std::array<void*, kMaxTake> samples_{};
  std::array<dds_sample_info_t, kMaxTake> infos_{};
  int32_t count_ = 0;
};

}  // namespace

// The domain's shared participant; the topics, readers and waitsets made here go with this.
struct Ros2CameraSource::Dds {
  std::unique_ptr<ParticipantScope> scope;
  dds_entity_t depth_reader = 0, depth_info_reader = 0, color_reader = 0, color_info_reader = 0;
  dds_entity_t extrinsics_reader = 0;
  dds_entity_t depth_waitset = 0, color_waitset = 0, info_waitset = 0;

  dds_entity_t reader(const dds_topic_descriptor_t& type, const std::string& ros_topic, const EndpointQos& qos) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic =
        scope->own(dds_create_topic(scope->participant(), &type, name.c_str(), nullptr, nullptr), "DDS topic " + name);
    const QosHandle handle(qos);
    return scope->own(dds_create_reader(scope->participant(), topic, handle.get(), nullptr), "DDS reader on " + name);
  }

  dds_entity_t waitset_on(dds_entity_t reader) {
    const dds_entity_t waitset = scope->own(dds_create_waitset(scope->participant()), "DDS waitset");
    const dds_entity_t condition = check_dds(dds_create_readcondition(reader, DDS_ANY_STATE), "DDS read condition");
    check_dds(dds_waitset_attach(waitset, condition, condition), "DDS waitset attach");
    return waitset;
  }

  // The participant in params.domain_id, the readers of the configured topics (colour ones only
  // with params.color) and a waitset on each reader waited on.
  void open(const Ros2SourceParams& params) {
    const CameraTopics& topics = params.topics;
    scope = std::make_unique<ParticipantScope>(params.domain_id);
    const EndpointQos images{false, false, static_cast<int32_t>(kMaxTake)};
    const EndpointQos infos{false, false, 1};
    depth_reader = reader(sensor_msgs_msg_dds__Image__desc, topics.depth_image, images);
    depth_info_reader = reader(sensor_msgs_msg_dds__CameraInfo__desc, topics.depth_info, infos);
    if (params.color) {
      color_reader = reader(sensor_msgs_msg_dds__Image__desc, topics.color_image, images);
      color_info_reader = reader(sensor_msgs_msg_dds__CameraInfo__desc, topics.color_info, infos);
      extrinsics_reader =
          reader(realsense2_camera_msgs_msg_dds__Extrinsics__desc, topics.extrinsics, EndpointQos{true, true, 1});
      color_waitset = waitset_on(color_reader);
    }
    depth_waitset = waitset_on(depth_reader);
    info_waitset = waitset_on(depth_info_reader);
  }

  // Waits for the first depth CameraInfo, which sets `depth_intrinsics`, and a second one when it
  // comes within 500 ms (realsense-ros publishes one per image), whose stamp gives the rate.
  // Returns their stamps (ns); throws Ros2StartupError when none came within
  // params.startup_timeout_s, when a stop was requested first, or when the message is invalid.
  std::vector<int64_t> first_depth_infos(const Ros2SourceParams& params, const std::string& domain,
                                         Intrinsics& depth_intrinsics) {
    const CameraTopics& topics = params.topics;
    const auto timeout = static_cast<dds_duration_t>(params.startup_timeout_s * 1e9);
    const dds_time_t deadline = dds_time() + timeout;
    const dds_time_t second_info_deadline_ns = DDS_MSECS(500);
    const auto stopping = [&params] { return params.stop_requested != nullptr && params.stop_requested->load(); };
    std::vector<int64_t> stamps;
    dds_time_t second_deadline = deadline;
    while (stamps.size() < 2 && !stopping() && dds_time() < std::min(deadline, second_deadline)) {
      // Slices of 100 ms, so that a stop request (a signal) ends the wait promptly.
      const dds_time_t slice = std::min({deadline, second_deadline, dds_time() + DDS_MSECS(100)});
      if (dds_waitset_wait_until(info_waitset, nullptr, 0, slice) <= 0) continue;
      Taken<sensor_msgs_msg_dds__CameraInfo_> taken(depth_info_reader);
      for (int32_t i = 0; i < taken.size(); ++i) {
        if (!taken.valid(i)) continue;
        try {
          depth_intrinsics = intrinsics_from_camera_info(taken[i], topics.depth_info);
        } catch (const Ros2Error& e) {
          throw Ros2StartupError(e.what());  // the camera's message, not the configuration, is wrong
        }
        stamps.push_back(stamp_ns(taken[i].header.stamp));
        if (stamps.size() == 1) second_deadline = dds_time() + second_info_deadline_ns;
      }
    }
    if (stamps.empty() && stopping()) {
      throw Ros2StartupError("stopped while waiting for the first CameraInfo on " + topics.depth_info + " (" + domain +
                             ")");
    }
    if (stamps.empty()) {
      throw Ros2StartupError("no CameraInfo on " + topics.depth_info + " (DDS " + dds_topic_name(topics.depth_info) +
                             ", " + domain + ") within " + std::to_string(params.startup_timeout_s) +
                             " s (source.ros2.startup_timeout_s): is the camera node running, in this domain "
                             "(ROS_DOMAIN_ID), reachable under CYCLONEDDS_URI's network settings?");
    }
    return stamps;
  }
};

Ros2CameraSource::Ros2CameraSource(Ros2SourceParams params) : params_(std::move(params)), dds_(std::make_unique<Dds>()) {
  const std::string domain = "domain " + std::to_string(params_.domain_id);
  dds_->open(params_);
  // The first depth CameraInfo gives the intrinsics the run starts with; a second one, when it
  // comes soon, gives the rate.
  const std::vector<int64_t> stamps = dds_->first_depth_infos(params_, domain, depth_intrinsics_);
  info_.type = "ros2";
  info_.live = true;
  info_.description = "ROS 2 " + params_.topics.depth_image + " (" + domain + ")";
  info_.intrinsics = depth_intrinsics_;
  info_.stereo_baseline_mm = params_.stereo_baseline_mm;
  info_.frame_count = -1;
  const int64_t step_ns = stamps.size() >= 2 ? stamps.back() - stamps.front() : 0;
  // A rate between 1 and 1000 frames/s is believed; else the D435's default 30.
  info_.nominal_fps = step_ns >= 1'000'000 && step_ns <= 1'000'000'000 ? 1e9 / static_cast<double>(step_ns) : 30.0;
}

Ros2CameraSource::~Ros2CameraSource() = default;

SourceInfo Ros2CameraSource::info() const { return info_; }

int64_t Ros2CameraSource::frames_dropped_camera() const {
  return frames_missed_.load() + rejected_.load() + overtaken_.load() + other_publishers_.load();
}

void Ros2CameraSource::reject(const std::string& topic, int64_t stamp_ns, const std::string& why) {
  const int64_t count = ++rejected_;
  // The first few, then one in a hundred: a camera configured wrongly would flood the log.
  if (count <= 3 || count % 100 == 0) {
    spdlog::warn("{}: message stamped {} ns rejected: {} ({} rejected so far)", topic, stamp_ns, why, count);
  }
}

bool Ros2CameraSource::from_followed_publisher(uint64_t publication_handle) {
  if (publication_handle == followed_publisher_) return true;
  if (followed_publisher_ != 0) {
    std::array<dds_instance_handle_t, 16> matched{};
    const dds_return_t count = dds_get_matched_publications(dds_->depth_reader, matched.data(), matched.size());
    const auto end = matched.begin() + std::clamp<dds_return_t>(count, 0, static_cast<dds_return_t>(matched.size()));
    if (std::find(matched.begin(), end, followed_publisher_) != end) {
      if (++other_publishers_ == 1) {
        spdlog::warn("{}: a second publisher sends images on this topic; only the first one's are used, the "
                     "other's are dropped and counted in frames_dropped_camera",
                     params_.topics.depth_image);
      }
      return false;
    }
    spdlog::info("{}: the publisher followed has gone; following the one now sending", params_.topics.depth_image);
  }
  followed_publisher_ = publication_handle;
  return true;
}

void Ros2CameraSource::take_infos() {
  {
    Taken<sensor_msgs_msg_dds__CameraInfo_> taken(dds_->depth_info_reader);
    for (int32_t i = 0; i < taken.size(); ++i) {
      if (!taken.valid(i)) continue;
      try {
        const Intrinsics intrinsics = intrinsics_from_camera_info(taken[i], params_.topics.depth_info);
        // The image size is fixed for the run (the background, the filters); a new calibration
        // of the same size is taken.
        if (intrinsics.width == depth_intrinsics_.width && intrinsics.height == depth_intrinsics_.height) {
          depth_intrinsics_ = intrinsics;
        }
      } catch (const Ros2Error& e) {
        reject(params_.topics.depth_info, stamp_ns(taken[i].header.stamp), e.what());
      }
    }
  }
  if (!params_.color) return;
  {
    Taken<sensor_msgs_msg_dds__CameraInfo_> taken(dds_->color_info_reader);
    for (int32_t i = 0; i < taken.size(); ++i) {
      if (!taken.valid(i)) continue;
      try {
        color_intrinsics_ = intrinsics_from_camera_info(taken[i], params_.topics.color_info);
      } catch (const Ros2Error& e) {
        reject(params_.topics.color_info, stamp_ns(taken[i].header.stamp), e.what());
      }
    }
  }
  Taken<realsense2_camera_msgs_msg_dds__Extrinsics_> taken(dds_->extrinsics_reader);
  for (int32_t i = 0; i < taken.size(); ++i) {
    if (taken.valid(i)) depth_to_color_ = extrinsics_from_msg(taken[i]);
  }
}

void Ros2CameraSource::take_colors() {
  Taken<sensor_msgs_msg_dds__Image_> taken(dds_->color_reader);
  for (int32_t i = 0; i < taken.size(); ++i) {
    if (!taken.valid(i)) continue;
    const sensor_msgs_msg_dds__Image_& image = taken[i];
    const int64_t stamp = stamp_ns(image.header.stamp);
    const std::string problem = color_image_problem(image);
    if (!problem.empty()) {
      reject(params_.topics.color_image, stamp, problem);
      continue;
    }
    last_color_wall_ns_ = wall_now_ns();
    TimedColor slot;
    if (colors_.size() >= kColorsKept) {  // reuse the oldest buffer
      slot = std::move(colors_.front());
      colors_.pop_front();
    }
    slot.stamp_ns = stamp;
    copy_color_image(image, slot.image);
    colors_.push_back(std::move(slot));
  }
}

bool Ros2CameraSource::attach_color(int64_t depth_stamp_ns, Frame& out) {
  const int64_t tolerance_ns = gaps_.period_ns > 0 ? gaps_.period_ns / 2 : kDefaultPairingNs;
  auto find = [&] {
    return std::find_if(colors_.begin(), colors_.end(), [&](const TimedColor& color) {
      return std::llabs(color.stamp_ns - depth_stamp_ns) <= tolerance_ns;
    });
  };
  take_colors();
  auto match = find();
  // Colour that streams but has not come yet for this image: wait a little for it.
  if (match == colors_.end() && last_color_wall_ns_ != 0 && wall_now_ns() - last_color_wall_ns_ < 1'000'000'000) {
    if (dds_waitset_wait(dds_->color_waitset, nullptr, 0, kColorWaitNs) > 0) take_colors();
    match = find();
  }
  if (match == colors_.end() || !color_intrinsics_ || color_intrinsics_->width != match->image.width ||
      color_intrinsics_->height != match->image.height) {
    return false;
  }
  out.color = match->image;
  out.color_intrinsics = *color_intrinsics_;
  out.depth_to_color = depth_to_color_;
  return true;
}

Source::Status Ros2CameraSource::next(Frame& out) {
  const dds_time_t deadline = dds_time() + params_.idle_after_ns;
  for (;;) {
    take_infos();
    bool got = false;
    int64_t stamp = 0;
    {
      Taken<sensor_msgs_msg_dds__Image_> taken(dds_->depth_reader);
      int32_t newest = -1;
      int32_t good = 0;
      for (int32_t i = 0; i < taken.size(); ++i) {
        if (!taken.valid(i) || !from_followed_publisher(taken.publisher(i))) continue;
        const int64_t sample_stamp = stamp_ns(taken[i].header.stamp);
        const int64_t outages_before = gaps_.outages;
        const int64_t previous_stamp = gaps_.previous_ns;
        gaps_.add(sample_stamp);
        if (gaps_.outages != outages_before) {
          spdlog::warn("{}: images again after {:.3f} s of silence", params_.topics.depth_image,
                       static_cast<double>(sample_stamp - previous_stamp) * 1e-9);
        }
        const std::string problem = depth_image_problem(taken[i], depth_intrinsics_.width, depth_intrinsics_.height);
        if (!problem.empty()) {
          reject(params_.topics.depth_image, sample_stamp, problem);
          continue;
        }
        newest = i;
        ++good;
      }
      frames_missed_.store(gaps_.frames_missed);
      outages_.store(gaps_.outages);
      if (newest >= 0) {
        overtaken_ += good - 1;
        copy_depth_image(taken[newest], out.depth);
        stamp = stamp_ns(taken[newest].header.stamp);
        got = true;
      }
    }
    if (got) {
      out.index = delivered_++;
      out.timestamp_ns = stamp;
      out.host_time_ns = host_time_of_stamp(stamp, wall_now_ns(), monotonic_now_ns());
      out.intrinsics = depth_intrinsics_;
      out.stereo_baseline_mm = params_.stereo_baseline_mm;
      out.truth.reset();
      out.color.reset();
      out.color_intrinsics = Intrinsics{};
      out.depth_to_color.reset();
      if (params_.color) attach_color(stamp, out);
      return Status::frame;
    }
    if (dds_time() >= deadline) return Status::idle;
    dds_waitset_wait_until(dds_->depth_waitset, nullptr, 0, deadline);
  }
}

}  // namespace hrcsense::ros2
