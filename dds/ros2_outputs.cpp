// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the ROS 2 outputs (ros2_outputs.hpp).
#include "dds/ros2_outputs.hpp"

#include "dds/dds_entity.hpp"

#include "control_msgs.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

namespace hrcsense::ros2 {
namespace {

int64_t outputs_steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// TFMessages kept by the camera chain's reader: several publishers each latch one.
constexpr int32_t kTfReaderDepth = 16;
constexpr uint32_t kTfTake = 16;

// The verdict's DEADLINE: max_frame_gap_periods nominal periods, or max_frame_age_s when the
// source's rate is unknown (not a positive finite number).
int64_t verdict_deadline_of(const Ros2OutputParams& params, double nominal_fps) {
  const bool rate_known = std::isfinite(nominal_fps) && nominal_fps > 0.0;
  return seconds_to_ns(rate_known ? params.max_frame_gap_periods / nominal_fps : params.max_frame_age_s);
}

}  // namespace

Ros2OutputTopics ros2_output_topics(const std::string& node_namespace, const std::string& speed_scaling_topic) {
  Ros2OutputTopics topics;
  topics.verdict = node_namespace + "/verdict";
  topics.speed_scaling = speed_scaling_topic.empty() ? node_namespace + "/speed_scaling" : speed_scaling_topic;
  topics.markers = node_namespace + "/markers";
  topics.foreground = node_namespace + "/foreground";
  topics.tf_static = "/tf_static";
  // Names that are not absolute are refused here, before any DDS entity exists.
  for (const std::string* name : {&topics.verdict, &topics.speed_scaling, &topics.markers, &topics.foreground}) {
    dds_topic_name(*name);
  }
  return topics;
}

// The domain's shared participant; what is made here goes with this.
struct Ros2OutputSink::Dds {
  ParticipantScope scope;
  dds_entity_t tf_topic = 0;
  dds_entity_t verdict = 0, speed_scaling = 0, markers = 0, foreground = 0, tf_static = 0;
  std::vector<geometry_msgs_msg_dds__TransformStamped_> tf_storage;
  std::array<sensor_msgs_msg_dds__PointField_, 3> cloud_fields{};

  explicit Dds(uint32_t domain_id) : scope(domain_id) {
    tf_topic = scope.own(dds_create_topic(scope.participant(), &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static",
                                          nullptr, nullptr),
                         "DDS topic rt/tf_static");
  }

  dds_entity_t writer(const dds_topic_descriptor_t& type, const std::string& ros_topic, const EndpointQos& qos) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic =
        scope.own(dds_create_topic(scope.participant(), &type, name.c_str(), nullptr, nullptr), "DDS topic " + name);
    const QosHandle handle(qos);
    return scope.own(dds_create_writer(scope.participant(), topic, handle.get(), nullptr), "DDS writer on " + name);
  }
};

Ros2OutputSink::Ros2OutputSink(Ros2OutputParams params)
    : params_(std::move(params)), topics_(ros2_output_topics(params_.node_namespace, params_.speed_scaling_topic)) {
  dds_ = std::make_unique<Dds>(params_.domain_id);
  cloud_period_ns_ = params_.cloud_hz > 0.0 ? seconds_to_ns(1.0 / params_.cloud_hz) : 0;
  if (params_.camera_publishes_optical) {
    read_camera_chain();
  } else {
    tf_edges_ = camera_tf_edges(params_.T_base_camera, params_.base_frame, params_.camera_name);
  }
}

Ros2OutputSink::~Ros2OutputSink() = default;

void Ros2OutputSink::read_camera_chain() {
  const std::string link = camera_link_frame(params_.camera_name);
  const std::string optical = camera_optical_frame(params_.camera_name);
  // The camera node's domain may differ from the outputs' (source.ros2.domain_id): its transforms
  // are read where it publishes them.
  std::unique_ptr<ParticipantScope> camera_scope;
  dds_entity_t participant = dds_->scope.participant();
  dds_entity_t topic = dds_->tf_topic;
  if (params_.camera_domain_id != params_.domain_id) {
    camera_scope = std::make_unique<ParticipantScope>(params_.camera_domain_id);
    participant = camera_scope->participant();
    topic = camera_scope->own(
        dds_create_topic(participant, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", nullptr, nullptr),
        "DDS topic rt/tf_static");
  }
  // A reader of its own, deleted when the chain is read (the writer comes later, in header()).
  const QosHandle qos(EndpointQos{true, true, kTfReaderDepth});
  const DdsEntity reader(
      check_dds(dds_create_reader(participant, topic, qos.get(), nullptr), "DDS reader on rt/tf_static"));
  std::vector<TfEdge> seen;
  std::optional<Pose> T_link_optical;
  const dds_time_t deadline = dds_time() + seconds_to_ns(params_.camera_tf_wait_s);
  // Polls every 20 ms until the chain is complete or the wait is over (bounded by the deadline).
  while (!T_link_optical) {
    std::array<void*, kTfTake> samples{};
    std::array<dds_sample_info_t, kTfTake> infos{};
    const dds_return_t count = dds_take(reader.get(), samples.data(), infos.data(), kTfTake, kTfTake);
    for (dds_return_t i = 0; i < count; ++i) {
      if (!infos[static_cast<size_t>(i)].valid_data) continue;
      for (TfEdge& edge : tf_edges_from_msg(*static_cast<const tf2_msgs_msg_dds__TFMessage_*>(samples[static_cast<size_t>(i)]))) {
        seen.push_back(std::move(edge));
      }
    }
    if (count > 0) dds_return_loan(reader.get(), samples.data(), count);
    T_link_optical = chain_transform(seen, link, optical);
    if (T_link_optical || dds_time() >= deadline) break;
    dds_sleepfor(DDS_MSECS(20));
  }
  if (!T_link_optical) {
    char wait_text[32];
    std::snprintf(wait_text, sizeof wait_text, "%g", params_.camera_tf_wait_s);
    camera_tf_note_ = "no " + link + " → " + optical + " on /tf_static within " + wait_text +
                      " s (is the camera node running in domain " + std::to_string(params_.camera_domain_id) +
                      "?): " + params_.base_frame + " → " + link + " uses the D435's fixed link → optical rotation instead";
    T_link_optical = T_link_optical_fixed();
  }
  // A frame never gets a second parent: when someone already places the camera's link (a
  // static_transform_publisher of the cell's calibration), hrcsense publishes nothing.
  for (const TfEdge& edge : seen) {
    if (edge.child_frame != link) continue;
    camera_tf_note_ = link + " already has the parent " + edge.parent_frame +
                      " on /tf_static: hrcsense publishes no " + params_.base_frame + " → " + link +
                      " (check that it agrees with camera.T_base_camera)";
    tf_edges_.clear();
    return;
  }
  // The camera node is the parent of its optical frames: only base → link is hrcsense's.
  tf_edges_ = {camera_link_edge(params_.T_base_camera, *T_link_optical, params_.base_frame, params_.camera_name)};
}

void Ros2OutputSink::header(const RunHeader& header) {
  session_ = header.session;
  verdict_deadline_ns_ = verdict_deadline_of(params_, header.source.nominal_fps);
  try {
    EndpointQos verdict_qos{true, false, 1};
    verdict_qos.deadline_ns = verdict_deadline_ns_;
    verdict_qos.liveliness_lease_ns = verdict_deadline_ns_;
    dds_->verdict = dds_->writer(hrcsense_msgs_msg_dds__Verdict__desc, topics_.verdict, verdict_qos);
    dds_->speed_scaling =
        dds_->writer(control_msgs_msg_dds__SpeedScalingFactor__desc, topics_.speed_scaling, EndpointQos{true, true, 1});
    dds_->markers = dds_->writer(visualization_msgs_msg_dds__MarkerArray__desc, topics_.markers, EndpointQos{true, false, 1});
    dds_->foreground = dds_->writer(sensor_msgs_msg_dds__PointCloud2__desc, topics_.foreground, EndpointQos{true, false, 1});
    const QosHandle latched(EndpointQos{true, true, 1});
    dds_->tf_static = dds_->scope.own(dds_create_writer(dds_->scope.participant(), dds_->tf_topic, latched.get(), nullptr),
                                      "DDS writer on rt/tf_static");
  } catch (const Ros2Error& e) {
    failure_ = std::string("ROS 2 outputs: ") + e.what();
    return;
  }
  if (tf_edges_.empty()) return;  // the camera's link has a parent already (camera_tf_note())
  tf2_msgs_msg_dds__TFMessage_ tf{};
  fill_tf_message(tf_edges_, 0, dds_->tf_storage, tf);
  write(dds_->tf_static, &tf, topics_.tf_static);
}

bool Ros2OutputSink::write(int32_t writer, const void* sample, const std::string& topic) {
  const dds_return_t ret = writer > 0 ? dds_write(writer, sample) : DDS_RETCODE_PRECONDITION_NOT_MET;
  if (ret >= 0) return true;
  ++counters_.failed_writes;
  counters_.last_error = "DDS write on " + topic + ": " + dds_strretcode(ret);
  return false;
}

void Ros2OutputSink::frame(const FrameResult& result) {
  if (failed()) return;
  const hrcsense_msgs_msg_dds__Verdict_ verdict = verdict_message(result, session_, ++seq_, params_.base_frame);
  if (write(dds_->verdict, &verdict, topics_.verdict)) {
    ++counters_.verdicts;
    verdicts_failed_in_a_row_ = 0;
  } else if (++verdicts_failed_in_a_row_ >= kFailedVerdictsInARow) {
    failure_ = "ROS 2 outputs: " + std::to_string(kFailedVerdictsInARow) + " verdicts in a row not written (" +
               counters_.last_error + ")";
  }

  const control_msgs_msg_dds__SpeedScalingFactor_ scaling{static_cast<double>(result.verdict.speed_scale)};
  write(dds_->speed_scaling, &scaling, topics_.speed_scaling);

  // A joint state without a valid reading would put the arm somewhere it is not: no capsules.
  robot_.capsules.clear();
  if (!params_.robot.arm || result.robot_state.valid) robot_model_at(params_.robot, result.robot_state.q_rad, robot_);
  safety_markers(result, robot_, marker_specs_);
  visualization_msgs_msg_dds__MarkerArray_ markers{};
  fill_marker_array(marker_specs_, result.timestamp_ns, params_.base_frame, marker_buffers_, markers);
  if (write(dds_->markers, &markers, topics_.markers)) ++counters_.marker_arrays;

  write_pending_cloud();
}

void Ros2OutputSink::on_processed(const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
  if (cloud_period_ns_ <= 0 || !result.valid) return;
  const int64_t now_ns = outputs_steady_now_ns();
  if (last_cloud_copy_ns_ >= 0 && now_ns - last_cloud_copy_ns_ < cloud_period_ns_) return;
  last_cloud_copy_ns_ = now_ns;
  const PointCloud& points = pipeline.foreground().points_base;
  tap_cloud_.points.x.assign(points.x.begin(), points.x.end());
  tap_cloud_.points.y.assign(points.y.begin(), points.y.end());
  tap_cloud_.points.z.assign(points.z.begin(), points.z.end());
  tap_cloud_.timestamp_ns = frame.timestamp_ns;
  const std::lock_guard<std::mutex> lock(cloud_mutex_);
  std::swap(tap_cloud_, shared_cloud_);
  cloud_pending_ = true;
}

void Ros2OutputSink::write_pending_cloud() {
  {
    const std::lock_guard<std::mutex> lock(cloud_mutex_);
    if (!cloud_pending_) return;
    std::swap(out_cloud_, shared_cloud_);
    cloud_pending_ = false;
  }
  pack_xyz(out_cloud_.points, cloud_bytes_);
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  fill_point_cloud(cloud_bytes_, out_cloud_.timestamp_ns, params_.base_frame, dds_->cloud_fields, cloud);
  if (write(dds_->foreground, &cloud, topics_.foreground)) ++counters_.clouds;
}

}  // namespace hrcsense::ros2
