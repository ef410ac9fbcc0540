// SPDX-License-Identifier: Apache-2.0
// hrcsense — the RealSense SDK's messages inside a bag (../shared/specs/realsense-bag-format.md
// §3–6): which topic holds what, and the ROS1 deserialisation of the few message types used.
#pragma once

#include "hrcsense/types.hpp"

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace hrcsense::bag {

/// What a topic of the SDK's layout carries, as far as hrcsense cares.
enum class Role { other, image, camera_info, stream_info, tf, depth_units, stereo_baseline, file_version, joint_states };

/// hrcsense's own topic beside the SDK's: the robot's joints at each frame (sensor_msgs/JointState).
inline constexpr std::string_view kJointStatesTopic = "/hrcsense/joint_states";

/// A topic, classified: its role and, for stream topics, the stream ("Depth_0", "Color_0").
struct TopicRole {
  Role role = Role::other;
  std::string stream;
};

/// Classifies an SDK topic such as `/device_0/sensor_0/Depth_0/image/data`.
TopicRole classify_topic(std::string_view topic);

/// Reads ROS1-serialised fields with bounds checks; after any overrun `ok` is false and every
/// further read yields zeros, so a parser checks once at the end.
struct Cursor {
  const uint8_t* data = nullptr;
  size_t size = 0;
  size_t pos = 0;
  bool ok = true;

  bool take(void* out, size_t n) {
    if (!ok || n > size - pos) {
      ok = false;
      std::memset(out, 0, n);
      return false;
    }
    std::memcpy(out, data + pos, n);
    pos += n;
    return true;
  }
  template <typename T>
  T get() {
    T value{};
    take(&value, sizeof(T));  // little-endian host and file (checked in bag_source.cpp)
    return value;
  }
  std::string_view string() {
    const auto n = get<uint32_t>();
    if (!ok || n > size - pos) {
      ok = false;
      return {};
    }
    const std::string_view text(reinterpret_cast<const char*>(data + pos), n);
    pos += n;
    return text;
  }
};

/// sensor_msgs/Image as the SDK writes it, pointing into the message.
struct ImageView {
  uint32_t seq = 0;
  int64_t stamp_ns = 0;
  std::string_view encoding;
  uint32_t width = 0, height = 0, step = 0;
  const uint8_t* pixels = nullptr;
  size_t pixel_bytes = 0;
  float depth_units_m = 0.0F;  ///< the trailing field of SDK >= 2.49 images; 0 when absent
};

/// Parses an Image; "" or what is wrong (sizes are checked: step * height == data size).
std::string parse_image(Cursor cursor, ImageView& out);
/// Parses a CameraInfo into intrinsics (the SDK's model names; at most 5 coefficients).
std::string parse_camera_info(Cursor cursor, Intrinsics& out);
/// realsense_msgs/StreamInfo (spec §4): the rate the stream was recorded at, as the SDK states it.
struct StreamInfoMessage {
  uint32_t fps = 0;            ///< frames/s; not checked here (the caller judges the streams it plays)
  std::string_view encoding;   ///< e.g. "mono16", "rgb8"
};

/// Parses a StreamInfo; "" or what is wrong (cut off).
std::string parse_stream_info(Cursor cursor, StreamInfoMessage& out);
/// Parses a geometry_msgs/Transform: P_stream = R·P_ref + t, i.e. T_stream_ref.
std::string parse_transform(Cursor cursor, Pose& out);

/// A sensor_msgs/JointState of /hrcsense/joint_states, its joints in hrcsense's order.
struct JointStateMessage {
  int64_t stamp_ns = 0;           ///< header stamp (0: the parser's caller uses the bag time)
  JointAngles position_rad{};     ///< joint 1 (shoulder pan) first
  JointAngles velocity_rad_s{};   ///< zeros when the message has no velocities
  bool has_velocity = false;
};

/// The 0-based hrcsense joint of a JointState name, or -1 for a joint hrcsense does not know (a
/// gripper's, say). Known: UR's ROS names (`shoulder_pan_joint` ... `wrist_3_joint`) and
/// hrcsense's older `joint_0` ... `joint_5`, either after a prefix that ends in '_' or '/'
/// (`ur_shoulder_pan_joint`, `arm/elbow_joint`). Never by position in the message.
int joint_index(std::string_view name);

/// Parses a JointState, mapping each joint by name (joint_index); unknown joints are ignored.
/// "" or what is wrong: cut off, more than 64 joints, arrays of unequal length, one of the six
/// joints missing or named twice, a non-finite position or velocity (naming the field).
std::string parse_joint_state(Cursor cursor, JointStateMessage& out);

}  // namespace hrcsense::bag

namespace hrcsense {
struct RecordingSummary;
/// Reads a whole bag for summarize_recording (bag_source.cpp); damage goes into `damage`.
RecordingSummary summarize_bag(const std::string& path);
}  // namespace hrcsense
