// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — `hrcsense echo` (ros2_echo.hpp).
#include "dds/ros2_echo.hpp"

#include "dds/dds_entity.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cmath>

namespace hrcsense::ros2 {
namespace {

using nlohmann::json;

json number_or_null(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

json header_json(const std_msgs_msg_dds__Header_& header) {
  return {{"stamp_ns", stamp_ns(header.stamp)}, {"frame_id", header.frame_id != nullptr ? header.frame_id : ""}};
}

template <typename Sequence>
json doubles_json(const Sequence& values) {
  json out = json::array();
  for (uint32_t i = 0; i < values._length; ++i) out.push_back(number_or_null(values._buffer[i]));
  return out;
}

const char* verdict_word(uint8_t verdict) {
  switch (verdict) {
    case 0: return "run";
    case 1: return "slow";
    case 2: return "stop";
    default: return "unknown";
  }
}

constexpr std::array<const char*, 7> kEchoTypeNames = {"verdict", "speed_scaling", "markers", "point_cloud",
                                                       "tf",      "joint_state",   "float64"};

}  // namespace

const char* echo_type_name(EchoType type) { return kEchoTypeNames[static_cast<size_t>(type)]; }

std::optional<EchoType> echo_type_named(const std::string& name) {
  for (size_t i = 0; i < kEchoTypeNames.size(); ++i) {
    if (name == kEchoTypeNames[i]) return static_cast<EchoType>(i);
  }
  return std::nullopt;
}

std::optional<EchoType> echo_type_of_topic(const std::string& ros_topic) {
  const std::string last = ros_topic.substr(ros_topic.rfind('/') + 1);
  if (last == "verdict") return EchoType::verdict;
  if (last == "speed_scaling") return EchoType::speed_scaling;
  if (last == "markers") return EchoType::markers;
  if (last == "foreground") return EchoType::point_cloud;
  if (last == "tf_static" || last == "tf") return EchoType::tf;
  if (last == "joint_states") return EchoType::joint_state;
  return std::nullopt;
}

std::string echo_line(const hrcsense_msgs_msg_dds__Verdict_& msg) {
  json line = header_json(msg.header);
  line["session"] = msg.session;
  line["seq"] = msg.seq;
  line["verdict"] = verdict_word(msg.verdict);
  line["reason_code"] = msg.reason_code;
  line["speed_scale"] = number_or_null(msg.speed_scale);
  line["distance_m"] = number_or_null(msg.distance_m);
  line["protective_distance_m"] = number_or_null(msg.protective_distance_m);
  line["governing_link"] = msg.governing_link;
  line["frame_age_s"] = number_or_null(msg.frame_age_s);
  return line.dump();
}

std::string echo_line(const control_msgs_msg_dds__SpeedScalingFactor_& msg) {
  return json{{"factor", number_or_null(msg.factor)}}.dump();
}

std::string echo_line(const visualization_msgs_msg_dds__MarkerArray_& msg) {
  json markers = json::array();
  for (uint32_t i = 0; i < msg.markers._length; ++i) {
    const visualization_msgs_msg_dds__Marker_& m = msg.markers._buffer[i];
    json marker = {{"ns", m.ns != nullptr ? m.ns : ""}, {"id", m.id}, {"type", m.type}, {"action", m.action},
                   {"frame_id", m.header.frame_id != nullptr ? m.header.frame_id : ""},
                   {"color_rgba", {m.color.r, m.color.g, m.color.b, m.color.a}}, {"points", m.points._length}};
    if (m.text != nullptr && m.text[0] != '\0') marker["text"] = m.text;
    markers.push_back(std::move(marker));
  }
  return json{{"markers", std::move(markers)}}.dump();
}

std::string echo_line(const sensor_msgs_msg_dds__PointCloud2_& msg) {
  json line = header_json(msg.header);
  json fields = json::array();
  for (uint32_t i = 0; i < msg.fields._length; ++i) {
    const sensor_msgs_msg_dds__PointField_& f = msg.fields._buffer[i];
    fields.push_back({{"name", f.name != nullptr ? f.name : ""}, {"offset", f.offset}, {"datatype", f.datatype}});
  }
  line["width"] = msg.width;
  line["height"] = msg.height;
  line["fields"] = std::move(fields);
  line["point_step"] = msg.point_step;
  line["points"] = uint64_t{msg.width} * msg.height;
  line["bytes"] = msg.data._length;
  return line.dump();
}

std::string echo_line(const tf2_msgs_msg_dds__TFMessage_& msg) {
  json transforms = json::array();
  for (uint32_t i = 0; i < msg.transforms._length; ++i) {
    const geometry_msgs_msg_dds__TransformStamped_& t = msg.transforms._buffer[i];
    const geometry_msgs_msg_dds__Vector3_& p = t.transform.translation;
    const geometry_msgs_msg_dds__Quaternion_& q = t.transform.rotation;
    transforms.push_back({{"parent", t.header.frame_id != nullptr ? t.header.frame_id : ""},
                          {"child", t.child_frame_id != nullptr ? t.child_frame_id : ""},
                          {"stamp_ns", stamp_ns(t.header.stamp)},
                          {"translation_m", {p.x, p.y, p.z}},
                          {"rotation_xyzw", {q.x, q.y, q.z, q.w}}});
  }
  return json{{"transforms", std::move(transforms)}}.dump();
}

std::string echo_line(const sensor_msgs_msg_dds__JointState_& msg) {
  json line = header_json(msg.header);
  json names = json::array();
  for (uint32_t i = 0; i < msg.name._length; ++i) names.push_back(msg.name._buffer[i] != nullptr ? msg.name._buffer[i] : "");
  line["name"] = std::move(names);
  line["position"] = doubles_json(msg.position);
  line["velocity"] = doubles_json(msg.velocity);
  line["effort"] = doubles_json(msg.effort);
  return line.dump();
}

std::string echo_line(const std_msgs_msg_dds__Float64_& msg) { return json{{"data", number_or_null(msg.data)}}.dump(); }

namespace {

template <typename T>
int64_t print_taken(dds_entity_t reader, int64_t room, std::ostream& out) {
  constexpr int32_t kBatch = 8;
  std::array<void*, kBatch> samples{};
  std::array<dds_sample_info_t, kBatch> infos{};
  const int32_t n = dds_take(reader, samples.data(), infos.data(), kBatch, kBatch);
  int64_t printed = 0;
  for (int32_t i = 0; i < n && (room < 0 || printed < room); ++i) {
    if (!infos[static_cast<size_t>(i)].valid_data) continue;
    out << echo_line(*static_cast<const T*>(samples[static_cast<size_t>(i)])) << '\n';
    ++printed;
  }
  if (n > 0) dds_return_loan(reader, samples.data(), n);
  out.flush();
  return printed;
}

const dds_topic_descriptor_t& descriptor_of(EchoType type) {
  switch (type) {
    case EchoType::verdict: return hrcsense_msgs_msg_dds__Verdict__desc;
    case EchoType::speed_scaling: return control_msgs_msg_dds__SpeedScalingFactor__desc;
    case EchoType::markers: return visualization_msgs_msg_dds__MarkerArray__desc;
    case EchoType::point_cloud: return sensor_msgs_msg_dds__PointCloud2__desc;
    case EchoType::tf: return tf2_msgs_msg_dds__TFMessage__desc;
    case EchoType::joint_state: return sensor_msgs_msg_dds__JointState__desc;
    case EchoType::float64: return std_msgs_msg_dds__Float64__desc;
  }
  return std_msgs_msg_dds__Float64__desc;
}

int64_t print_samples(EchoType type, dds_entity_t reader, int64_t room, std::ostream& out) {
  switch (type) {
    case EchoType::verdict: return print_taken<hrcsense_msgs_msg_dds__Verdict_>(reader, room, out);
    case EchoType::speed_scaling: return print_taken<control_msgs_msg_dds__SpeedScalingFactor_>(reader, room, out);
    case EchoType::markers: return print_taken<visualization_msgs_msg_dds__MarkerArray_>(reader, room, out);
    case EchoType::point_cloud: return print_taken<sensor_msgs_msg_dds__PointCloud2_>(reader, room, out);
    case EchoType::tf: return print_taken<tf2_msgs_msg_dds__TFMessage_>(reader, room, out);
    case EchoType::joint_state: return print_taken<sensor_msgs_msg_dds__JointState_>(reader, room, out);
    case EchoType::float64: return print_taken<std_msgs_msg_dds__Float64_>(reader, room, out);
  }
  return 0;
}

}  // namespace

int64_t echo_topic(const EchoParams& params, std::ostream& out) {
  ParticipantScope scope(params.domain_id);
  const std::string name = dds_topic_name(params.topic);
  const dds_entity_t topic = scope.own(
      dds_create_topic(scope.participant(), &descriptor_of(params.type), name.c_str(), nullptr, nullptr),
      "DDS topic " + name);
  const bool latched = params.type == EchoType::tf || params.type == EchoType::speed_scaling;
  const QosHandle qos(EndpointQos{latched, latched, latched ? 1 : 64});
  const dds_entity_t reader =
      scope.own(dds_create_reader(scope.participant(), topic, qos.get(), nullptr), "DDS reader on " + name);
  const dds_entity_t waitset = scope.own(dds_create_waitset(scope.participant()), "DDS waitset");
  const dds_entity_t condition = scope.own(dds_create_readcondition(reader, DDS_ANY_STATE), "DDS read condition");
  check_dds(dds_waitset_attach(waitset, condition, condition), "DDS waitset attach");

  const auto started = std::chrono::steady_clock::now();
  int64_t printed = 0;
  for (;;) {
    if (params.count >= 0 && printed >= params.count) break;
    if (params.stop_requested != nullptr && params.stop_requested->load()) break;
    const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (params.timeout_s >= 0.0 && elapsed_s >= params.timeout_s) break;
    // Slices of 100 ms, so that a signal or the timeout ends the wait soon.
    dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(100));
    printed += print_samples(params.type, reader, params.count < 0 ? -1 : params.count - printed, out);
  }
  return printed;
}

}  // namespace hrcsense::ros2
