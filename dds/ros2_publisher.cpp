// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the realsense-ros topic publisher (ros2_publisher.hpp).
#include "dds/ros2_publisher.hpp"

#include "dds/dds_entity.hpp"
#include "dds/ros2_output_messages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace hrcsense::ros2 {
namespace {

// Points an Image at caller-owned pixels: dds_write only reads them.
void point_image(sensor_msgs_msg_dds__Image_& image, const void* data, uint32_t bytes) {
  image.data._buffer = static_cast<uint8_t*>(const_cast<void*>(data));
  image.data._length = image.data._maximum = bytes;
  image.data._release = false;
}

bool same_extrinsics(const Extrinsics& a, const Extrinsics& b) {
  return a.rotation == b.rotation && a.translation_m == b.translation_m;
}

}  // namespace

struct Ros2CameraPublisher::Dds {
  DdsEntity participant;
  dds_entity_t depth = 0, depth_info = 0, color = 0, color_info = 0, extrinsics = 0;

  dds_entity_t writer(const dds_topic_descriptor_t& type, const std::string& ros_topic, const EndpointQos& qos) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic = check_dds(dds_create_topic(participant.get(), &type, name.c_str(), nullptr, nullptr),
                                         "DDS topic " + name);
    const QosHandle handle(qos);
    return check_dds(dds_create_writer(participant.get(), topic, handle.get(), nullptr), "DDS writer on " + name);
  }
};

Ros2CameraPublisher::Ros2CameraPublisher(const Ros2PublisherParams& params)
    : topics_(realsense_topics(params.node_namespace)), dds_(std::make_unique<Dds>()) {
  const std::string camera_name = camera_name_of(params.node_namespace);
  depth_frame_id_ = camera_name + "_depth_optical_frame";
  color_frame_id_ = camera_name + "_color_optical_frame";
  // Cyclone reads CYCLONEDDS_URI here; hrcsense never overrides it.
  dds_->participant = DdsEntity(check_dds(dds_create_participant(params.domain_id, nullptr, nullptr),
                                          "DDS participant on domain " + std::to_string(params.domain_id)));
  const EndpointQos stream{true, false, 2};
  dds_->depth = dds_->writer(sensor_msgs_msg_dds__Image__desc, topics_.depth_image, stream);
  dds_->depth_info = dds_->writer(sensor_msgs_msg_dds__CameraInfo__desc, topics_.depth_info, stream);
  dds_->color = dds_->writer(sensor_msgs_msg_dds__Image__desc, topics_.color_image, stream);
  dds_->color_info = dds_->writer(sensor_msgs_msg_dds__CameraInfo__desc, topics_.color_info, stream);
  dds_->extrinsics = dds_->writer(realsense2_camera_msgs_msg_dds__Extrinsics__desc, topics_.extrinsics,
                                  EndpointQos{true, true, 1});
}

Ros2CameraPublisher::~Ros2CameraPublisher() = default;

bool Ros2CameraPublisher::wait_for_subscribers(int count, double timeout_s) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    dds_publication_matched_status_t image{}, info{};
    dds_get_publication_matched_status(dds_->depth, &image);
    dds_get_publication_matched_status(dds_->depth_info, &info);
    if (static_cast<int>(image.current_count) >= count && static_cast<int>(info.current_count) >= count) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void Ros2CameraPublisher::publish(const Frame& frame) {
  const DepthImage& depth = frame.depth;
  const uint16_t* pixels = depth.pixels.data();
  // 16UC1 is millimetres by ROS convention: a source in another unit is converted.
  if (depth.depth_scale_m != 0.001F) {
    depth_mm_.resize(depth.pixels.size());
    const double to_mm = static_cast<double>(depth.depth_scale_m) / 0.001;
    std::transform(depth.pixels.begin(), depth.pixels.end(), depth_mm_.begin(), [to_mm](uint16_t raw) {
      return static_cast<uint16_t>(std::min(65535.0, std::round(raw * to_mm)));
    });
    pixels = depth_mm_.data();
  }
  sensor_msgs_msg_dds__Image_ image{};
  fill_depth_image_16uc1(pixels, depth.width, depth.height, frame.timestamp_ns, depth_frame_id_, image);
  check_dds(dds_write(dds_->depth, &image), "DDS write on " + topics_.depth_image);

  sensor_msgs_msg_dds__CameraInfo_ info{};
  fill_camera_info(frame.intrinsics, frame.timestamp_ns, depth_frame_id_, d_storage_, info);
  check_dds(dds_write(dds_->depth_info, &info), "DDS write on " + topics_.depth_info);

  if (frame.color && frame.color_intrinsics.width > 0) {
    const ColorImage& color = *frame.color;
    sensor_msgs_msg_dds__Image_ color_image{};
    color_image.header.stamp = image.header.stamp;
    color_image.header.frame_id = const_cast<char*>(color_frame_id_.c_str());
    color_image.width = static_cast<uint32_t>(color.width);
    color_image.height = static_cast<uint32_t>(color.height);
    color_image.encoding = const_cast<char*>("rgb8");
    color_image.step = 3U * color_image.width;
    point_image(color_image, color.rgb.data(), color_image.step * color_image.height);
    check_dds(dds_write(dds_->color, &color_image), "DDS write on " + topics_.color_image);
    fill_camera_info(frame.color_intrinsics, frame.timestamp_ns, color_frame_id_, d_storage_, info);
    check_dds(dds_write(dds_->color_info, &info), "DDS write on " + topics_.color_info);
  }
  if (frame.depth_to_color && !(extrinsics_sent_ && same_extrinsics(*extrinsics_sent_, *frame.depth_to_color))) {
    const realsense2_camera_msgs_msg_dds__Extrinsics_ msg = extrinsics_to_msg(*frame.depth_to_color);
    check_dds(dds_write(dds_->extrinsics, &msg), "DDS write on " + topics_.extrinsics);
    extrinsics_sent_ = frame.depth_to_color;
  }
}

}  // namespace hrcsense::ros2
