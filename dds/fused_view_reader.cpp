// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the fused view's reader (fused_view_reader.hpp).
#include "dds/fused_view_reader.hpp"

#include "dds/camera_previews.hpp"
#include "dds/dds_entity.hpp"
#include "dds/measurement_endpoints.hpp"
#include "dds/ros2_messages.hpp"

#include "hrcsense_msgs.h"
#include "sensor_msgs.h"

#include <array>
#include <cmath>
#include <functional>

namespace hrcsense::ros2 {
namespace {

constexpr uint32_t kFusedViewTake = 4;

// Every valid sample waiting on `reader`, oldest first, handed to `received` while on loan.
template <typename Message>
void take_all_of(dds_entity_t reader, const std::function<void(const Message&)>& received) {
  for (;;) {
    std::array<void*, kFusedViewTake> samples{};
    std::array<dds_sample_info_t, kFusedViewTake> infos{};
    const dds_return_t n = dds_take(reader, samples.data(), infos.data(), kFusedViewTake, kFusedViewTake);
    if (n <= 0) return;
    for (int32_t i = 0; i < n; ++i) {
      if (infos[static_cast<size_t>(i)].valid_data) received(*static_cast<const Message*>(samples[static_cast<size_t>(i)]));
    }
    dds_return_loan(reader, samples.data(), n);
    if (n < static_cast<int32_t>(kFusedViewTake)) return;
  }
}

VerdictState fused_verdict_state(uint8_t number) {
  switch (number) {
    case 0: return VerdictState::run;
    case 1: return VerdictState::slow;
    default: return VerdictState::stop;  // 2, or a number no verdict has: shown as the safe one
  }
}

void note_rejected(FusedCameraView& camera, const std::string& topic, const std::string& problem) {
  ++camera.rejected;
  camera.last_problem = topic + ": " + problem;
}

}  // namespace

struct FusedViewReader::Dds {
  ParticipantScope scope;
  MeasurementReader measurements;
  std::vector<CameraPreviewTopics> topics;
  std::vector<dds_entity_t> clouds, previews;
  dds_entity_t verdict = 0, waitset = 0;
  PointCloud cloud_scratch;
  DepthPreview preview_scratch;

  Dds(uint32_t domain_id, const std::string& node_namespace, const std::vector<std::string>& names)
      : scope(domain_id), measurements(domain_id, node_namespace, names) {
    waitset = scope.own(dds_create_waitset(scope.participant()), "DDS waitset");
  }

  dds_entity_t reader(const dds_topic_descriptor_t& type, const std::string& ros_topic, int32_t depth) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic =
        scope.own(dds_create_topic(scope.participant(), &type, name.c_str(), nullptr, nullptr), "DDS topic " + name);
    const QosHandle qos(EndpointQos{false, false, depth});
    const dds_entity_t made =
        scope.own(dds_create_reader(scope.participant(), topic, qos.get(), nullptr), "DDS reader on " + name);
    const dds_entity_t condition = check_dds(dds_create_readcondition(made, DDS_ANY_STATE), "DDS read condition");
    check_dds(dds_waitset_attach(waitset, condition, condition), "DDS waitset attach");
    return made;
  }
};

namespace {
std::vector<std::string> fused_view_names(const FusedViewParams& params) {
  std::vector<std::string> names;
  for (const FusedViewCamera& camera : params.cameras) names.push_back(camera.name);
  return names;
}
}  // namespace

FusedViewReader::FusedViewReader(const FusedViewParams& params) {
  dds_ = std::make_unique<Dds>(params.domain_id, params.node_namespace, fused_view_names(params));
  for (const FusedViewCamera& camera : params.cameras) {
    FusedCameraView view;
    view.name = camera.name;
    view.T_base_camera = camera.T_base_camera;
    view.intrinsics = camera.intrinsics;
    view_.cameras.push_back(std::move(view));
    const CameraPreviewTopics topics = camera_preview_topics(params.node_namespace, camera.name);
    dds_->topics.push_back(topics);
    dds_->clouds.push_back(dds_->reader(sensor_msgs_msg_dds__PointCloud2__desc, topics.foreground, 1));
    dds_->previews.push_back(dds_->reader(sensor_msgs_msg_dds__Image__desc, topics.depth_preview, 1));
  }
  const std::string prefix = params.node_namespace == "/" ? "" : params.node_namespace;
  dds_->verdict = dds_->reader(hrcsense_msgs_msg_dds__Verdict__desc, prefix + "/verdict", 1);
}

FusedViewReader::~FusedViewReader() = default;

int32_t FusedViewReader::measurement_writers(size_t camera) const { return dds_->measurements.writers(camera); }

const FusedView& FusedViewReader::poll(int64_t timeout_ns, int64_t steady_now_ns) {
  if (timeout_ns > 0) dds_waitset_wait(dds_->waitset, nullptr, 0, timeout_ns);
  dds_->measurements.take([this](size_t topic, const CameraMeasurement& m, const std::string& problem) {
    FusedCameraView& camera = view_.cameras[topic];
    if (!problem.empty()) return note_rejected(camera, dds_->measurements.topics()[topic], problem);
    // The fuser's own rule for what can be fused: a point that is not finite is never drawn.
    const std::string unusable = measurement_problem(m);
    if (!unusable.empty()) return note_rejected(camera, dds_->measurements.topics()[topic], unusable);
    if (m.camera_name != camera.name) {
      return note_rejected(camera, dds_->measurements.topics()[topic], "camera_name '" + m.camera_name + "'");
    }
    // Arrival order is the writer's order; a restarted camera's first measurement replaces the old.
    camera.measurement = m;
    camera.T_base_camera = m.T_base_camera;
    if (m.intrinsics.width > 0) camera.intrinsics = m.intrinsics;
    ++camera.measurements;
  });
  for (size_t i = 0; i < view_.cameras.size(); ++i) {
    FusedCameraView& camera = view_.cameras[i];
    take_all_of<sensor_msgs_msg_dds__PointCloud2_>(dds_->clouds[i], [&](const sensor_msgs_msg_dds__PointCloud2_& msg) {
      const std::string problem = points_from_cloud(msg, dds_->cloud_scratch);
      if (!problem.empty()) return note_rejected(camera, dds_->topics[i].foreground, problem);
      std::swap(camera.cloud_base, dds_->cloud_scratch);
      camera.cloud_stamp_ns = stamp_ns(msg.header.stamp);
    });
    take_all_of<sensor_msgs_msg_dds__Image_>(dds_->previews[i], [&](const sensor_msgs_msg_dds__Image_& msg) {
      const std::string problem = depth_preview_from(msg, dds_->preview_scratch);
      if (!problem.empty()) return note_rejected(camera, dds_->topics[i].depth_preview, problem);
      std::swap(camera.preview, dds_->preview_scratch);
    });
  }
  take_all_of<hrcsense_msgs_msg_dds__Verdict_>(dds_->verdict, [&](const hrcsense_msgs_msg_dds__Verdict_& msg) {
    FusedVerdictView& v = view_.verdict;
    v.received = true;
    v.verdict = fused_verdict_state(msg.verdict);
    v.reason_code = msg.reason_code;
    v.distance_m = msg.distance_m;
    v.governing_link = msg.governing_link;
    v.stamp_ns = stamp_ns(msg.header.stamp);
    v.received_steady_ns = steady_now_ns;
  });
  return view_;
}

}  // namespace hrcsense::ros2
