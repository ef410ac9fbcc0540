// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — `hrcsense publish`: frames of any source as a realsense-ros camera's topics,
// so a recording or the simulator can stand in for a camera in a ROS 2 system.
#pragma once

#include "dds/ros2_messages.hpp"
#include "hrcsense/types.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense::ros2 {

struct Ros2PublisherParams {
  std::string node_namespace = "/camera/camera";  ///< realsense-ros's node: topics below it
  uint32_t domain_id = 0;
};

/// Writes, per frame, the depth Image (16UC1, millimetres) and its CameraInfo, the colour
/// Image (rgb8) and its CameraInfo when the frame has colour, and the depth→colour Extrinsics
/// once they are known (again when they change). Frame ids follow realsense-ros
/// (`<camera_name>_depth_optical_frame`); stamps are the frames' own timestamps. Writers are
/// reliable (so RViz and `ros2 topic echo`, reliable by default, receive them) and volatile,
/// the extrinsics transient-local, as realsense-ros latches them.
class Ros2CameraPublisher {
 public:
  explicit Ros2CameraPublisher(const Ros2PublisherParams& params);  ///< throws Ros2Error
  ~Ros2CameraPublisher();
  Ros2CameraPublisher(const Ros2CameraPublisher&) = delete;
  Ros2CameraPublisher& operator=(const Ros2CameraPublisher&) = delete;

  /// Throws Ros2Error naming the topic when a write fails.
  void publish(const Frame& frame);
  /// Waits until at least `count` readers match both the depth image and its CameraInfo;
  /// false at `timeout_s`.
  bool wait_for_subscribers(int count, double timeout_s) const;
  const CameraTopics& topics() const { return topics_; }

 private:
  struct Dds;
  CameraTopics topics_;
  std::string depth_frame_id_, color_frame_id_;
  std::unique_ptr<Dds> dds_;
  std::vector<uint16_t> depth_mm_;  ///< the depth in millimetres when the source's unit differs
  std::vector<double> d_storage_;
  std::optional<Extrinsics> extrinsics_sent_;
};

}  // namespace hrcsense::ros2
