// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — hrcsense_msgs/Measurement to and from CameraMeasurement (measurement_messages.hpp).
#include "dds/measurement_messages.hpp"

#include "dds/ros2_messages.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <limits>

namespace hrcsense::ros2 {
namespace {

constexpr uint32_t kMaxMessageLinks = 64;  // the IDL's bound

geometry_msgs_msg_dds__Point_ point_msg(const Eigen::Vector3f& p) {
  return {static_cast<double>(p.x()), static_cast<double>(p.y()), static_cast<double>(p.z())};
}

Eigen::Vector3f point_of(const geometry_msgs_msg_dds__Point_& p) {
  return {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
}

hrcsense_msgs_msg_dds__LinkContact_ link_msg(int link, const Contact& c, float speed_towards_mps,
                                             float distance_uncertainty_m) {
  hrcsense_msgs_msg_dds__LinkContact_ out{};
  out.link = link;
  out.distance_m = c.distance_m;
  out.inside = c.inside;
  out.closest_base = point_msg(c.closest_base);
  out.closest_robot_base = point_msg(c.closest_robot_base);
  out.closest_camera = point_msg(c.closest_camera);
  out.speed_towards_mps = speed_towards_mps;
  out.distance_uncertainty_m = distance_uncertainty_m;
  return out;
}

Contact contact_of(const hrcsense_msgs_msg_dds__LinkContact_& msg) {
  Contact c;
  c.valid = true;
  c.distance_m = msg.distance_m;
  c.inside = msg.inside;
  c.closest_base = point_of(msg.closest_base);
  c.closest_robot_base = point_of(msg.closest_robot_base);
  c.closest_camera = point_of(msg.closest_camera);
  c.robot_link = msg.link;
  return c;
}

template <typename Seq, typename T>
void point_at(Seq& seq, std::vector<T>& storage) {
  seq._maximum = static_cast<uint32_t>(storage.size());
  seq._length = static_cast<uint32_t>(storage.size());
  seq._buffer = storage.empty() ? nullptr : storage.data();
  seq._release = false;
}

}  // namespace

std::string measurement_topic(const std::string& node_namespace, const std::string& camera_name) {
  if (!is_camera_name(camera_name)) {
    throw Ros2Error("camera name '" + camera_name + "': expected a ROS name token (a letter, then letters, digits, '_')");
  }
  const std::string topic =
      (node_namespace.size() > 1 && node_namespace.back() == '/' ? node_namespace.substr(0, node_namespace.size() - 1)
                                                                 : node_namespace) +
      "/measurement/" + camera_name;
  (void)dds_topic_name(topic);  // throws for a namespace that is not absolute
  return topic;
}

hrcsense_msgs_msg_dds__Measurement_ measurement_message(const CameraMeasurement& m, const std::string& base_frame,
                                                        MeasurementBuffers& buffers) {
  hrcsense_msgs_msg_dds__Measurement_ msg{};
  buffers.frame_id = base_frame;
  msg.header.stamp = stamp_from_ns(m.capture_ns);
  msg.header.frame_id = buffers.frame_id.data();
  // The strings are only read by dds_write.
  msg.camera_name = const_cast<char*>(m.camera_name.c_str());
  msg.session = m.session;
  msg.seq = m.sequence;
  msg.frame = m.frame;
  msg.nominal_fps = m.nominal_fps;
  msg.width = static_cast<uint32_t>(std::max(0, m.intrinsics.width));
  msg.height = static_cast<uint32_t>(std::max(0, m.intrinsics.height));
  msg.fx = m.intrinsics.fx;
  msg.fy = m.intrinsics.fy;
  msg.ppx = m.intrinsics.ppx;
  msg.ppy = m.intrinsics.ppy;
  const Eigen::Quaterniond q(m.T_base_camera.linear());
  const Eigen::Vector3d t = m.T_base_camera.translation();
  msg.camera_pose.position = {t.x(), t.y(), t.z()};
  msg.camera_pose.orientation = {q.x(), q.y(), q.z(), q.w()};
  msg.valid = m.valid;
  msg.reason_code = static_cast<uint16_t>(m.reason_code);
  msg.reason = const_cast<char*>(m.reason.c_str());
  msg.has_contact = m.contact.valid;
  if (m.contact.valid) msg.contact = link_msg(m.contact.robot_link, m.contact, std::numeric_limits<float>::quiet_NaN(),
                                              std::numeric_limits<float>::quiet_NaN());
  buffers.links.clear();
  for (const LinkContact& link : m.links) {
    if (buffers.links.size() == kMaxMessageLinks) break;
    buffers.links.push_back(link_msg(link.link, link.contact, link.speed_towards_mps, link.distance_uncertainty_m));
  }
  point_at(msg.links, buffers.links);
  msg.unknown_distance_m = m.unknown_distance_m;
  msg.seen_free_cells = static_cast<uint32_t>(m.seen_free.cells);
  buffers.seen_free = m.seen_free.bytes;
  point_at(msg.seen_free, buffers.seen_free);
  msg.foreground_points = m.foreground_points;
  msg.self_filtered_pixels = m.self_filtered_pixels;
  msg.invalid_pixels = m.invalid_pixels;
  msg.valid_share = m.valid_share;
  const RobotState& s = m.robot_state;
  msg.robot_state_valid = s.valid;
  buffers.joints_rad.assign(s.q_rad.begin(), s.q_rad.end());
  buffers.joint_velocities_rad_s.assign(s.qd_rad_s.begin(), s.qd_rad_s.end());
  point_at(msg.joints_rad, buffers.joints_rad);
  point_at(msg.joint_velocities_rad_s, buffers.joint_velocities_rad_s);
  msg.robot_state_sample_ns = s.sample_time_ns;
  msg.robot_state_extrapolated_ns = s.extrapolated_ns;
  msg.robot_state_age_ms = m.robot_state_age_ms;
  msg.robot_speed_fraction = s.speed_fraction;
  msg.latency_us = m.latency_us;
  msg.has_truth = m.truth.has_value();
  if (m.truth && m.truth->valid) {
    msg.truth = link_msg(m.truth->robot_link, *m.truth, std::numeric_limits<float>::quiet_NaN(),
                         std::numeric_limits<float>::quiet_NaN());
  } else if (m.truth) {
    msg.truth.distance_m = std::numeric_limits<float>::quiet_NaN();  // a truth without a contact
    msg.truth.link = -1;
  }
  buffers.truth_links.clear();
  for (const LinkTruth& lt : m.truth_links) {
    if (buffers.truth_links.size() == kMaxMessageLinks) break;
    buffers.truth_links.push_back({lt.link, lt.distance_m, lt.speed_towards_mps});
  }
  point_at(msg.truth_links, buffers.truth_links);
  return msg;
}

std::string camera_measurement_from(const hrcsense_msgs_msg_dds__Measurement_& msg, CameraMeasurement& out) {
  if (msg.camera_name == nullptr) return "camera_name: null";
  if (msg.reason == nullptr) return "reason: null";
  if (msg.links._length > kMaxMessageLinks || msg.truth_links._length > kMaxMessageLinks) return "links: more than 64";
  if ((msg.links._length > 0 && msg.links._buffer == nullptr) ||
      (msg.truth_links._length > 0 && msg.truth_links._buffer == nullptr) ||
      (msg.seen_free._length > 0 && msg.seen_free._buffer == nullptr)) {
    return "a sequence without its values";
  }
  if (msg.seen_free._length != (static_cast<uint64_t>(msg.seen_free_cells) + 7) / 8) {
    return "seen_free: " + std::to_string(msg.seen_free._length) + " bytes for " + std::to_string(msg.seen_free_cells) +
           " cells";
  }
  const auto joints = static_cast<uint32_t>(kJointCount);
  if (msg.joints_rad._length > joints || msg.joint_velocities_rad_s._length > joints ||
      (msg.joints_rad._length > 0 && msg.joints_rad._buffer == nullptr) ||
      (msg.joint_velocities_rad_s._length > 0 && msg.joint_velocities_rad_s._buffer == nullptr)) {
    return "joints_rad: more than six values, or none where a count is given";
  }
  if (msg.robot_state_valid && (msg.joints_rad._length != joints || msg.joint_velocities_rad_s._length != joints)) {
    return "joints_rad: a valid robot state needs six positions and six velocities";
  }
  out.camera_name.assign(msg.camera_name);
  out.session = msg.session;
  out.sequence = msg.seq;
  out.frame = msg.frame;
  out.capture_ns = stamp_ns(msg.header.stamp);
  out.nominal_fps = msg.nominal_fps;
  out.intrinsics = Intrinsics{};
  out.intrinsics.width = static_cast<int>(std::min<uint32_t>(msg.width, 1U << 20));
  out.intrinsics.height = static_cast<int>(std::min<uint32_t>(msg.height, 1U << 20));
  out.intrinsics.fx = msg.fx;
  out.intrinsics.fy = msg.fy;
  out.intrinsics.ppx = msg.ppx;
  out.intrinsics.ppy = msg.ppy;
  const auto& o = msg.camera_pose.orientation;
  Eigen::Quaterniond q(o.w, o.x, o.y, o.z);
  if (!(q.norm() > 1e-9) || !std::isfinite(q.norm())) q = Eigen::Quaterniond::Identity();
  out.T_base_camera = Pose::Identity();
  out.T_base_camera.linear() = q.normalized().toRotationMatrix();
  out.T_base_camera.translation() = Eigen::Vector3d(msg.camera_pose.position.x, msg.camera_pose.position.y,
                                                    msg.camera_pose.position.z);
  out.valid = msg.valid;
  out.reason_code = static_cast<ReasonCode>(msg.reason_code);
  out.reason.assign(msg.reason);
  out.contact = Contact{};
  if (msg.has_contact) out.contact = contact_of(msg.contact);
  out.links.clear();
  for (uint32_t i = 0; i < msg.links._length; ++i) {
    const hrcsense_msgs_msg_dds__LinkContact_& l = msg.links._buffer[i];
    LinkContact link;
    link.link = l.link;
    link.contact = contact_of(l);
    link.speed_towards_mps = l.speed_towards_mps;
    link.distance_uncertainty_m = l.distance_uncertainty_m;
    out.links.push_back(link);
  }
  out.unknown_distance_m = msg.unknown_distance_m;
  out.seen_free.cells = msg.seen_free_cells;
  out.seen_free.bytes.assign(msg.seen_free._buffer, msg.seen_free._buffer + msg.seen_free._length);
  out.foreground_points = msg.foreground_points;
  out.self_filtered_pixels = msg.self_filtered_pixels;
  out.invalid_pixels = msg.invalid_pixels;
  out.valid_share = msg.valid_share;
  RobotState& s = out.robot_state;
  s = RobotState{};
  s.valid = msg.robot_state_valid;
  for (uint32_t j = 0; j < msg.joints_rad._length; ++j) s.q_rad[j] = msg.joints_rad._buffer[j];
  for (uint32_t j = 0; j < msg.joint_velocities_rad_s._length; ++j) s.qd_rad_s[j] = msg.joint_velocities_rad_s._buffer[j];
  s.sample_time_ns = msg.robot_state_sample_ns;
  s.host_time_ns = out.capture_ns;
  s.extrapolated_ns = msg.robot_state_extrapolated_ns;
  s.speed_fraction = msg.robot_speed_fraction;
  out.robot_state_age_ms = msg.robot_state_age_ms;
  out.latency_us = msg.latency_us;
  out.truth.reset();
  if (msg.has_truth) {
    out.truth = std::isnan(msg.truth.distance_m) ? Contact{} : contact_of(msg.truth);
  }
  out.truth_links.clear();
  for (uint32_t i = 0; i < msg.truth_links._length; ++i) {
    const auto& lt = msg.truth_links._buffer[i];
    out.truth_links.push_back({lt.link, lt.distance_m, lt.speed_towards_mps});
  }
  return {};
}

}  // namespace hrcsense::ros2
