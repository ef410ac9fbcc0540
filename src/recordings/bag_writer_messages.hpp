// SPDX-License-Identifier: Apache-2.0
// hrcsense — the ROS1 serialisation of what the .bag writer (bag_writer.cpp) puts into a bag:
// little-endian fields and the SDK's messages (../shared/specs/realsense-bag-format.md §3).
#pragma once

#include "hrcsense/camera.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::bag_write {

/// Little-endian ROS1 fields appended to `b`; a string is its uint32 length and its bytes.
void put32(std::vector<uint8_t>& b, uint32_t v);
void put64(std::vector<uint8_t>& b, uint64_t v);
void put_f32(std::vector<uint8_t>& b, float v);
void put_f64(std::vector<uint8_t>& b, double v);
void put_string(std::vector<uint8_t>& b, const std::string& s);
/// ROS time: uint32 sec, uint32 nsec (times before 1970 cannot be written: clamped to 0).
void put_time(std::vector<uint8_t>& b, int64_t ns);

/// sensor_msgs/CameraInfo of a stream's intrinsics (R and P zero, as the SDK writes them).
std::vector<uint8_t> camera_info_message(const Intrinsics& in);
/// geometry_msgs/Transform of a pose.
std::vector<uint8_t> transform_message(const Pose& T);
/// realsense_msgs/StreamInfo.
std::vector<uint8_t> stream_info_message(uint32_t fps, const std::string& encoding);
/// diagnostic_msgs/KeyValue.
std::vector<uint8_t> key_value_message(const std::string& key, const std::string& value);
/// std_msgs/String.
std::vector<uint8_t> string_message(const std::string& text);
/// std_msgs/UInt32.
std::vector<uint8_t> u32_message(uint32_t v);
/// std_msgs/Float32.
std::vector<uint8_t> f32_message(float v);
/// Frame::depth_to_color (the SDK's column-major rs2_extrinsics) as a pose.
Pose extrinsics_pose(const Extrinsics& e);

}  // namespace hrcsense::bag_write
