// SPDX-License-Identifier: Apache-2.0
// hrcsense — the SDK's topics and messages in a bag: classification and ROS1 deserialisation.
#include "bag_messages.hpp"

#include "hrcsense/recordings/bag_writer.hpp"
#include "hrcsense/camera.hpp"
#include "hrcsense/io/io.hpp"

#include <array>
#include <cmath>

namespace hrcsense::bag {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "bag fields are read as little-endian");

/// Largest image side accepted, as for PNGs: no camera is near it, and a damaged size field
/// cannot make a frame buffer huge.
constexpr uint32_t kMaxSidePx = 16384;

}  // namespace

TopicRole classify_topic(std::string_view topic) {
  TopicRole out;
  if (topic == kJointStatesTopic) {
    out.role = Role::joint_states;
    return out;
  }
  if (topic == "/file_version") {
    out.role = Role::file_version;
    return out;
  }
  // /device_<d>/sensor_<s>/<rest>
  if (topic.rfind("/device_", 0) != 0) return out;
  const size_t sensor = topic.find("/sensor_", 1);
  if (sensor == std::string_view::npos) return out;
  const size_t rest_at = topic.find('/', sensor + 1);
  if (rest_at == std::string_view::npos) return out;
  const std::string_view rest = topic.substr(rest_at + 1);
  if (rest.rfind("option/", 0) == 0) {
    // Spaces in option names became '_' in newer SDKs; accept both.
    if (rest == "option/Depth_Units/value" || rest == "option/Depth Units/value") out.role = Role::depth_units;
    if (rest == "option/Stereo_Baseline/value" || rest == "option/Stereo Baseline/value") {
      out.role = Role::stereo_baseline;
    }
    return out;
  }
  const size_t slash = rest.find('/');
  if (slash == std::string_view::npos) return out;
  out.stream = std::string(rest.substr(0, slash));
  const std::string_view what = rest.substr(slash);
  if (what == "/image/data") out.role = Role::image;
  if (what == "/info/camera_info") out.role = Role::camera_info;
  if (what == "/info") out.role = Role::stream_info;
  if (what.rfind("/tf/", 0) == 0) out.role = Role::tf;
  if (out.role == Role::other) out.stream.clear();
  return out;
}

std::string parse_image(Cursor c, ImageView& out) {
  out.seq = c.get<uint32_t>();
  const auto sec = c.get<uint32_t>();
  const auto nsec = c.get<uint32_t>();
  out.stamp_ns = static_cast<int64_t>(sec) * 1000000000LL + nsec;
  const std::string_view frame_id = c.string();
  out.height = c.get<uint32_t>();
  out.width = c.get<uint32_t>();
  out.encoding = c.string();
  c.get<uint8_t>();  // is_bigendian: the SDK always writes 0
  out.step = c.get<uint32_t>();
  const auto bytes = c.get<uint32_t>();
  if (!c.ok || bytes > c.size - c.pos) return "image message is cut off";
  out.pixels = c.data + c.pos;
  out.pixel_bytes = bytes;
  c.pos += bytes;
  // The SDK (>= 2.49) marks images with frame_id "1" and appends the frame's depth units.
  out.depth_units_m = frame_id == "1" ? c.get<float>() : 0.0F;
  if (!c.ok) return "image message lacks its depth units field";
  if (out.width == 0 || out.height == 0 || out.width > kMaxSidePx || out.height > kMaxSidePx) {
    return "image size " + std::to_string(out.width) + "x" + std::to_string(out.height) + " is implausible";
  }
  if (static_cast<uint64_t>(out.step) * out.height != bytes) {
    return "image data holds " + std::to_string(bytes) + " bytes, step x height is " +
           std::to_string(static_cast<uint64_t>(out.step) * out.height);
  }
  return {};
}

std::string parse_camera_info(Cursor c, Intrinsics& out) {
  c.get<uint32_t>();  // header.seq
  c.get<uint64_t>();  // header.stamp
  c.string();         // header.frame_id
  const auto height = c.get<uint32_t>();
  const auto width = c.get<uint32_t>();
  const std::string_view model = c.string();
  const auto coefficients = c.get<uint32_t>();
  Intrinsics in;
  for (uint32_t i = 0; i < coefficients && c.ok; ++i) {
    const auto value = c.get<double>();
    if (i < in.coeffs.size()) in.coeffs[i] = static_cast<float>(value);
  }
  double k[9];
  for (double& value : k) value = c.get<double>();
  if (!c.ok) return "camera_info message is cut off";
  if (width == 0 || height == 0 || width > kMaxSidePx || height > kMaxSidePx) return "camera_info size is implausible";
  in.width = static_cast<int>(width);
  in.height = static_cast<int>(height);
  in.fx = static_cast<float>(k[0]);
  in.ppx = static_cast<float>(k[2]);
  in.fy = static_cast<float>(k[4]);
  in.ppy = static_cast<float>(k[5]);
  in.model = distortion_from_name(model).value_or(Distortion::none);
  // The same plausibility as a folder's intrinsics.json: a K of 1e39 or 1e-39 would put every
  // point at infinity or at the camera (R1).
  const std::string problem = intrinsics_problem(in, IntrinsicsFieldNames{"K[0]", "K[4]", "K[2]", "K[5]", "D"});
  if (!problem.empty()) return "camera_info: " + problem;
  out = in;
  return {};
}

std::string parse_stream_info(Cursor c, StreamInfoMessage& out) {
  const auto fps = c.get<uint32_t>();
  const std::string_view encoding = c.string();
  c.get<uint8_t>();  // is_recommended: not used
  if (!c.ok) return "stream info message is cut off";
  out.fps = fps;
  out.encoding = encoding;
  return {};
}

std::string parse_transform(Cursor c, Pose& out) {
  double v[7];  // translation x y z, rotation x y z w
  for (double& value : v) value = c.get<double>();
  if (!c.ok) return "transform message is cut off";
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (!(std::abs(q.norm() - 1.0) < 1e-3)) return "transform rotation is not a unit quaternion";
  if (!(std::abs(v[0]) <= 1000.0 && std::abs(v[1]) <= 1000.0 && std::abs(v[2]) <= 1000.0)) {
    return "transform translation is not finite or beyond 1000 m";
  }
  out = Pose::Identity();
  out.linear() = q.normalized().toRotationMatrix();
  out.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return {};
}

namespace {

/// True when `name` is `base`, or ends with it after a prefix whose last character is '_' or '/'.
bool names_joint(std::string_view name, std::string_view base) {
  if (name.size() < base.size() || name.substr(name.size() - base.size()) != base) return false;
  if (name.size() == base.size()) return true;
  const char before = name[name.size() - base.size() - 1];
  return before == '_' || before == '/';
}

/// More joints than any arm with a gripper has; a damaged count cannot make the parser loop long.
constexpr uint32_t kMaxJointStateJoints = 64;

}  // namespace

int joint_index(std::string_view name) {
  for (int j = 0; j < kJointCount; ++j) {
    if (names_joint(name, kUrJointNames[static_cast<size_t>(j)])) return j;
    if (names_joint(name, "joint_" + std::to_string(j))) return j;
  }
  return -1;
}

std::string parse_joint_state(Cursor c, JointStateMessage& out) {
  c.get<uint32_t>();  // header.seq
  const auto sec = c.get<uint32_t>();
  const auto nsec = c.get<uint32_t>();
  c.string();  // header.frame_id
  const auto count = c.get<uint32_t>();
  if (!c.ok) return "joint_states message is cut off";
  if (count > kMaxJointStateJoints) {
    return "joint_states name[] has " + std::to_string(count) + " entries (at most " +
           std::to_string(kMaxJointStateJoints) + ")";
  }
  std::array<int, kMaxJointStateJoints> joint_of{};  // message entry -> hrcsense joint, or -1
  std::array<bool, kJointCount> named{};
  for (uint32_t i = 0; i < count; ++i) {
    const std::string_view name = c.string();
    if (!c.ok) return "joint_states message is cut off in name[" + std::to_string(i) + "]";
    const int j = joint_index(name);
    joint_of[i] = j;
    if (j < 0) continue;
    if (named[static_cast<size_t>(j)]) {
      return "joint_states name[" + std::to_string(i) + "] '" + std::string(name) + "' names joint " +
             kUrJointNames[static_cast<size_t>(j)] + " again";
    }
    named[static_cast<size_t>(j)] = true;
  }
  for (int j = 0; j < kJointCount; ++j) {
    if (!named[static_cast<size_t>(j)]) {
      return std::string("joint_states has no joint ") + kUrJointNames[static_cast<size_t>(j)] + " (or joint_" +
             std::to_string(j) + ")";
    }
  }
  // position[] must match name[]; velocity[] and effort[] may also be empty (not measured).
  const char* const arrays[] = {"position", "velocity", "effort"};
  JointStateMessage message;
  for (int a = 0; a < 3; ++a) {
    const auto n = c.get<uint32_t>();
    if (!c.ok) return std::string("joint_states message is cut off before ") + arrays[a] + "[]";
    if (n != count && (a == 0 || n != 0)) {
      return std::string("joint_states ") + arrays[a] + "[] has " + std::to_string(n) + " entries, name[] " +
             std::to_string(count);
    }
    if (a == 1) message.has_velocity = n != 0;
    for (uint32_t i = 0; i < n; ++i) {
      const auto value = c.get<double>();
      if (!c.ok) return std::string("joint_states message is cut off in ") + arrays[a] + "[]";
      const int j = joint_of[i];
      if (j < 0 || a == 2) continue;  // efforts are not used
      if (!std::isfinite(value)) {
        return std::string("joint_states ") + arrays[a] + "[" + std::to_string(i) + "] (" +
               kUrJointNames[static_cast<size_t>(j)] + ") is not finite";
      }
      (a == 0 ? message.position_rad : message.velocity_rad_s)[static_cast<size_t>(j)] = value;
    }
  }
  message.stamp_ns = static_cast<int64_t>(sec) * 1000000000LL + nsec;
  out = message;
  return {};
}

}  // namespace hrcsense::bag
