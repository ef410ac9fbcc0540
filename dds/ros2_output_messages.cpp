// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the messages `ros2.publish` writes (ros2_output_messages.hpp).
#include "dds/ros2_output_messages.hpp"

#include "dds/ros2_messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace hrcsense::ros2 {
namespace {

// DDS's C structs take char*; every string given here is only read by dds_write.
char* output_text(const std::string& text) { return const_cast<char*>(text.c_str()); }
char* output_empty_text() { return const_cast<char*>(""); }

// Edges a chain may have before it counts as a loop.
constexpr int kMaxChainEdges = 16;

// Grey of the robot's capsules, and the alpha of S_p's shell.
constexpr MarkerColor kRobotGrey{0.6F, 0.6F, 0.6F, 0.6F};
constexpr MarkerColor kTextWhite{1.0F, 1.0F, 1.0F, 1.0F};
constexpr float kShellAlpha = 0.25F;
constexpr double kContactLineWidthM = 0.01;
constexpr double kTextHeightM = 0.05;

void put_le32(uint8_t* out, float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  for (int i = 0; i < 4; ++i) out[i] = static_cast<uint8_t>(bits >> (8 * i));
}

// A capsule as markers in `ns`: a cylinder along the segment (none for a point) and a sphere
// at each end (one for a point), ids from `next_id` on.
void add_capsule_markers(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius_m, const std::string& ns,
                         const MarkerColor& color, int32_t& next_id, std::vector<MarkerSpec>& out) {
  const double diameter_m = radius_m > 0.0 ? 2.0 * radius_m : kPointMarkerDiameterM;
  const Eigen::Vector3d axis = b - a;
  const double length_m = axis.norm();
  MarkerSpec sphere;
  sphere.ns = ns;
  sphere.type = kMarkerSphere;
  sphere.scale = Eigen::Vector3d::Constant(diameter_m);
  sphere.color = color;
  if (length_m > 0.0) {
    MarkerSpec cylinder = sphere;
    cylinder.type = kMarkerCylinder;
    cylinder.id = next_id++;
    cylinder.position = 0.5 * (a + b);
    // A CYLINDER stands along its own z axis.
    cylinder.orientation = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis);
    cylinder.scale = Eigen::Vector3d(diameter_m, diameter_m, length_m);
    out.push_back(cylinder);
  }
  sphere.id = next_id++;
  sphere.position = a;
  out.push_back(sphere);
  if (length_m > 0.0) {
    sphere.id = next_id++;
    sphere.position = b;
    out.push_back(sphere);
  }
}

// S_p of the governing link: its own entry beside Measurement::links, else the verdict's.
double governing_protective_distance_m(const FrameResult& result) {
  for (size_t i = 0; i < result.links.size() && i < result.link_protective_distance_m.size(); ++i) {
    if (result.links[i].link == result.governing_link) return result.link_protective_distance_m[i];
  }
  return result.verdict.protective_distance_m;
}

}  // namespace

uint8_t verdict_number(VerdictState state) {
  switch (state) {
    case VerdictState::run: return 0;
    case VerdictState::slow: return 1;
    case VerdictState::stop: return 2;
  }
  return 2;
}

const char* base_frame_id(BaseFrame frame) { return frame == BaseFrame::base_link ? "base_link" : "base"; }

hrcsense_msgs_msg_dds__Verdict_ verdict_message(const FrameResult& result, uint32_t session, uint32_t seq,
                                                const std::string& frame_id) {
  hrcsense_msgs_msg_dds__Verdict_ msg{};
  msg.header.stamp = stamp_from_ns(result.timestamp_ns);
  msg.header.frame_id = output_text(frame_id);
  msg.session = session;
  msg.seq = seq;
  msg.verdict = verdict_number(result.verdict.state);
  msg.reason_code = static_cast<uint16_t>(result.verdict.code);
  msg.speed_scale = result.verdict.speed_scale;
  msg.distance_m = result.contact.valid ? result.contact.distance_m : std::numeric_limits<float>::quiet_NaN();
  msg.protective_distance_m = result.verdict.protective_distance_m;
  msg.governing_link = result.governing_link;
  msg.frame_age_s = static_cast<float>(result.frame_age_s);
  return msg;
}

geometry_msgs_msg_dds__Quaternion_ quaternion_msg(const Eigen::Matrix3d& rotation) {
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // q and -q are the same rotation: one of them
  return geometry_msgs_msg_dds__Quaternion_{q.x(), q.y(), q.z(), q.w()};
}

Pose T_link_optical_fixed() {
  // Columns: the optical axes in the link frame. Optical x (right) is link -y, optical y
  // (down) is link -z, optical z (forward) is link x.
  Eigen::Matrix3d R_link_optical;
  R_link_optical << 0.0, 0.0, 1.0,  //
      -1.0, 0.0, 0.0,               //
      0.0, -1.0, 0.0;
  Pose T = Pose::Identity();
  T.linear() = R_link_optical;
  return T;
}

std::string camera_link_frame(const std::string& camera_name) { return camera_name + "_link"; }
std::string camera_optical_frame(const std::string& camera_name) { return camera_name + "_depth_optical_frame"; }

TfEdge camera_link_edge(const Pose& T_base_camera, const Pose& T_link_optical, const std::string& base_frame,
                        const std::string& camera_name) {
  return TfEdge{base_frame, camera_link_frame(camera_name), T_base_camera * T_link_optical.inverse()};
}

std::vector<TfEdge> camera_tf_edges(const Pose& T_base_camera, const std::string& base_frame,
                                    const std::string& camera_name) {
  const Pose T_link_optical = T_link_optical_fixed();
  return {camera_link_edge(T_base_camera, T_link_optical, base_frame, camera_name),
          TfEdge{camera_link_frame(camera_name), camera_optical_frame(camera_name), T_link_optical}};
}

std::optional<Pose> chain_transform(const std::vector<TfEdge>& edges, const std::string& ancestor,
                                    const std::string& descendant) {
  Pose T_frame_descendant = Pose::Identity();
  std::string frame = descendant;
  for (int step = 0; step <= kMaxChainEdges; ++step) {
    if (frame == ancestor) {
      // Edges far apart in size can still add up to no number.
      if (!T_frame_descendant.matrix().allFinite()) return std::nullopt;
      return T_frame_descendant;
    }
    const TfEdge* up = nullptr;
    for (const TfEdge& edge : edges) {
      if (edge.child_frame == frame) up = &edge;  // the newest edge of a frame wins
    }
    if (up == nullptr) return std::nullopt;
    T_frame_descendant = up->T_parent_child * T_frame_descendant;
    frame = up->parent_frame;
  }
  return std::nullopt;
}

std::vector<TfEdge> tf_edges_from_msg(const tf2_msgs_msg_dds__TFMessage_& message) {
  std::vector<TfEdge> edges;
  for (uint32_t i = 0; i < message.transforms._length; ++i) {
    const geometry_msgs_msg_dds__TransformStamped_& t = message.transforms._buffer[i];
    const geometry_msgs_msg_dds__Quaternion_& r = t.transform.rotation;
    const geometry_msgs_msg_dds__Vector3_& p = t.transform.translation;
    Eigen::Quaterniond q(r.w, r.x, r.y, r.z);
    const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && q.coeffs().allFinite();
    // |q| must be about 1; far from it the sender computed garbage (and 1e-3 keeps the
    // normalisation away from dividing by nothing).
    if (!finite || !(q.norm() > 1e-3)) continue;
    q.normalize();
    TfEdge edge;
    edge.parent_frame = t.header.frame_id != nullptr ? t.header.frame_id : "";
    edge.child_frame = t.child_frame_id != nullptr ? t.child_frame_id : "";
    edge.T_parent_child = Pose::Identity();
    edge.T_parent_child.linear() = q.toRotationMatrix();
    edge.T_parent_child.translation() = Eigen::Vector3d(p.x, p.y, p.z);
    edges.push_back(std::move(edge));
  }
  return edges;
}

void fill_tf_message(const std::vector<TfEdge>& edges, int64_t stamp_ns,
                     std::vector<geometry_msgs_msg_dds__TransformStamped_>& storage, tf2_msgs_msg_dds__TFMessage_& out) {
  storage.assign(edges.size(), geometry_msgs_msg_dds__TransformStamped_{});
  for (size_t i = 0; i < edges.size(); ++i) {
    const TfEdge& edge = edges[i];
    geometry_msgs_msg_dds__TransformStamped_& t = storage[i];
    t.header.stamp = stamp_from_ns(stamp_ns);
    t.header.frame_id = output_text(edge.parent_frame);
    t.child_frame_id = output_text(edge.child_frame);
    const Eigen::Vector3d translation = edge.T_parent_child.translation();
    t.transform.translation = geometry_msgs_msg_dds__Vector3_{translation.x(), translation.y(), translation.z()};
    t.transform.rotation = quaternion_msg(edge.T_parent_child.linear());
  }
  out = tf2_msgs_msg_dds__TFMessage_{};
  out.transforms._buffer = storage.data();
  out.transforms._length = out.transforms._maximum = static_cast<uint32_t>(storage.size());
  out.transforms._release = false;
}

void pack_xyz(const PointCloud& points, std::vector<uint8_t>& bytes) {
  bytes.resize(points.size() * kCloudPointStep);
  uint8_t* out = bytes.data();
  for (size_t i = 0; i < points.size(); ++i, out += kCloudPointStep) {
    put_le32(out, points.x[i]);
    put_le32(out + 4, points.y[i]);
    put_le32(out + 8, points.z[i]);
  }
}

void fill_point_cloud(const std::vector<uint8_t>& bytes, int64_t stamp_ns, const std::string& frame_id,
                      std::array<sensor_msgs_msg_dds__PointField_, 3>& fields, sensor_msgs_msg_dds__PointCloud2_& out) {
  constexpr uint8_t kFloat32 = 7;  // sensor_msgs/PointField FLOAT32
  static const char* const kNames[3] = {"x", "y", "z"};
  for (uint32_t i = 0; i < 3; ++i) {
    fields[i] = sensor_msgs_msg_dds__PointField_{const_cast<char*>(kNames[i]), 4U * i, kFloat32, 1U};
  }
  const auto count = static_cast<uint32_t>(bytes.size() / kCloudPointStep);
  out = sensor_msgs_msg_dds__PointCloud2_{};
  out.header.stamp = stamp_from_ns(stamp_ns);
  out.header.frame_id = output_text(frame_id);
  out.height = 1;
  out.width = count;
  out.fields._buffer = fields.data();
  out.fields._length = out.fields._maximum = 3;
  out.fields._release = false;
  out.is_bigendian = false;
  out.point_step = kCloudPointStep;
  out.row_step = kCloudPointStep * count;
  out.data._buffer = const_cast<uint8_t*>(bytes.data());
  out.data._length = out.data._maximum = static_cast<uint32_t>(count * kCloudPointStep);
  out.data._release = false;
  out.is_dense = true;  // pack_xyz's points are measured ones: no NaN
}

void fill_depth_image_16uc1(const uint16_t* pixels_mm, int width, int height, int64_t stamp_ns,
                            const std::string& frame_id, sensor_msgs_msg_dds__Image_& out) {
  out = sensor_msgs_msg_dds__Image_{};
  out.header.stamp = stamp_from_ns(stamp_ns);
  out.header.frame_id = output_text(frame_id);
  out.width = static_cast<uint32_t>(std::max(width, 0));
  out.height = static_cast<uint32_t>(std::max(height, 0));
  out.encoding = const_cast<char*>("16UC1");
  out.is_bigendian = 0;
  out.step = 2U * out.width;
  // dds_write only reads the pixels.
  out.data._buffer = reinterpret_cast<uint8_t*>(const_cast<uint16_t*>(pixels_mm));
  out.data._length = out.data._maximum = out.step * out.height;
  out.data._release = false;
}

MarkerColor verdict_color(VerdictState state, float alpha) {
  switch (state) {
    case VerdictState::run: return {0.0F, 0.8F, 0.0F, alpha};
    case VerdictState::slow: return {1.0F, 0.75F, 0.0F, alpha};
    case VerdictState::stop: return {0.9F, 0.0F, 0.0F, alpha};
  }
  return {0.9F, 0.0F, 0.0F, alpha};
}

std::vector<MarkerSpec> safety_markers(const FrameResult& result, const RobotModel& robot) {
  std::vector<MarkerSpec> markers;
  safety_markers(result, robot, markers);
  return markers;
}

void safety_markers(const FrameResult& result, const RobotModel& robot, std::vector<MarkerSpec>& markers) {
  markers.clear();
  MarkerSpec delete_all;
  delete_all.action = kMarkerDeleteAll;
  markers.push_back(delete_all);

  int32_t robot_id = 0;
  for (const Capsule& capsule : robot.capsules) {
    add_capsule_markers(capsule.a.cast<double>(), capsule.b.cast<double>(), capsule.radius_m, "robot", kRobotGrey,
                        robot_id, markers);
  }
  if (result.governing_link >= 0) {
    const double s_p_m = governing_protective_distance_m(result);
    const MarkerColor shell = verdict_color(result.verdict.state, kShellAlpha);
    int32_t shell_id = 0;
    for (const Capsule& capsule : robot.capsules) {
      if (capsule.link != result.governing_link) continue;
      add_capsule_markers(capsule.a.cast<double>(), capsule.b.cast<double>(), capsule.radius_m + s_p_m,
                          "protective_distance", shell, shell_id, markers);
    }
  }
  if (result.contact.valid) {
    const Eigen::Vector3d person = result.contact.closest_base.cast<double>();
    const Eigen::Vector3d robot_point = result.contact.closest_robot_base.cast<double>();
    MarkerSpec line;
    line.ns = "contact";
    line.id = 0;
    line.type = kMarkerLineList;
    line.scale = Eigen::Vector3d(kContactLineWidthM, 0.0, 0.0);
    line.color = verdict_color(result.verdict.state, 1.0F);
    line.points = {person, robot_point};
    markers.push_back(line);
    MarkerSpec text;
    text.ns = "contact";
    text.id = 1;
    text.type = kMarkerText;
    text.position = 0.5 * (person + robot_point) + Eigen::Vector3d(0.0, 0.0, kTextHeightM);
    text.scale = Eigen::Vector3d(0.0, 0.0, kTextHeightM);
    text.color = kTextWhite;
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3f m", static_cast<double>(result.contact.distance_m));
    text.text = buffer;
    markers.push_back(text);
  }
}

void fill_marker_array(const std::vector<MarkerSpec>& specs, int64_t stamp_ns, const std::string& frame_id,
                       MarkerArrayBuffers& buffers, visualization_msgs_msg_dds__MarkerArray_& out) {
  buffers.markers.assign(specs.size(), visualization_msgs_msg_dds__Marker_{});
  if (buffers.points.size() < specs.size()) buffers.points.resize(specs.size());
  for (size_t i = 0; i < specs.size(); ++i) {
    const MarkerSpec& spec = specs[i];
    visualization_msgs_msg_dds__Marker_& m = buffers.markers[i];
    m.header.stamp = stamp_from_ns(stamp_ns);
    m.header.frame_id = output_text(frame_id);
    m.ns = output_text(spec.ns);
    m.id = spec.id;
    m.type = spec.type;
    m.action = spec.action;
    m.pose.position = geometry_msgs_msg_dds__Point_{spec.position.x(), spec.position.y(), spec.position.z()};
    const Eigen::Quaterniond q = spec.orientation.normalized();
    m.pose.orientation = geometry_msgs_msg_dds__Quaternion_{q.x(), q.y(), q.z(), q.w()};
    m.scale = geometry_msgs_msg_dds__Vector3_{spec.scale.x(), spec.scale.y(), spec.scale.z()};
    m.color = std_msgs_msg_dds__ColorRGBA_{spec.color.r, spec.color.g, spec.color.b, spec.color.a};
    // lifetime 0: until replaced (the next array's DELETEALL)
    m.frame_locked = false;
    std::vector<geometry_msgs_msg_dds__Point_>& points = buffers.points[i];
    points.clear();
    for (const Eigen::Vector3d& p : spec.points) points.push_back(geometry_msgs_msg_dds__Point_{p.x(), p.y(), p.z()});
    m.points._buffer = points.data();
    m.points._length = m.points._maximum = static_cast<uint32_t>(points.size());
    m.points._release = false;
    m.texture_resource = output_empty_text();
    m.texture.header.frame_id = output_empty_text();
    m.texture.format = output_empty_text();
    m.text = output_text(spec.text);
    m.mesh_resource = output_empty_text();
    m.mesh_file.filename = output_empty_text();
  }
  out = visualization_msgs_msg_dds__MarkerArray_{};
  out.markers._buffer = buffers.markers.data();
  out.markers._length = out.markers._maximum = static_cast<uint32_t>(buffers.markers.size());
  out.markers._release = false;
}

}  // namespace hrcsense::ros2
