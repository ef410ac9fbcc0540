// SPDX-License-Identifier: Apache-2.0
// ros2.publish on loopback, in one process: a simulated cell runs through the production sinks
// (assemble_cell: the ROS 2 outputs among the links) while DDS readers listen. One Verdict per
// result with the result's values, the final stop included; seq counting up; the verdict's
// deadline offered; /tf_static and the speed scaling latched for late readers; the cloud's
// rate limit; the camera's own link → optical chain used when the camera node publishes one.
// Every wait is bounded; nothing is asserted about timing.
#include "../support/scenes.hpp"
#include "dds/dds_entity.hpp"
#include "dds/ros2_outputs.hpp"
#include "dds_test_util.hpp"

#include "common/cell.hpp"
#include "common/tee_sink.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/session.hpp"

#include "control_msgs.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <thread>
#include <vector>

namespace hrcsense::ros2 {
namespace {

using namespace std::chrono_literals;

// Every result as the sinks got it.
class CaptureSink final : public Sink {
 public:
  void header(const RunHeader& header) override { header_ = header; }
  void frame(const FrameResult& result) override { results.push_back(result); }
  void summary(const RunSummary&) override {}
  std::vector<FrameResult> results;
  RunHeader header_;
};

dds_entity_t output_reader(ParticipantScope& scope, const dds_topic_descriptor_t& type, const std::string& dds_name,
                           EndpointQos qos) {
  const dds_entity_t topic =
      scope.own(dds_create_topic(scope.participant(), &type, dds_name.c_str(), nullptr, nullptr), "topic " + dds_name);
  const QosHandle handle(qos);
  return scope.own(dds_create_reader(scope.participant(), topic, handle.get(), nullptr), "reader " + dds_name);
}

// Takes every sample `reader` holds, calling `each` on the valid ones, until `want` were seen
// or 2 s passed without them (local delivery is immediate; the wait only bounds a slow machine).
template <typename T>
size_t take_samples(dds_entity_t reader, size_t want, const std::function<void(const T&)>& each) {
  size_t seen = 0;
  const auto deadline = std::chrono::steady_clock::now() + 2s;
  for (int round = 0; round < 10000; ++round) {
    std::array<void*, 32> samples{};
    std::array<dds_sample_info_t, 32> infos{};
    const dds_return_t n = dds_take(reader, samples.data(), infos.data(), samples.size(), samples.size());
    for (dds_return_t i = 0; i < n; ++i) {
      if (!infos[static_cast<size_t>(i)].valid_data) continue;
      each(*static_cast<const T*>(samples[static_cast<size_t>(i)]));
      ++seen;
    }
    if (n > 0) dds_return_loan(reader, samples.data(), n);
    if (n > 0) continue;
    if (seen >= want || std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(10ms);
  }
  return seen;
}

// Waits (at most 2 s) until `reader` matches a writer or reports the writer's QoS incompatible;
// true when matched.
bool reader_matches(dds_entity_t reader) {
  const auto deadline = std::chrono::steady_clock::now() + 2s;
  for (;;) {
    dds_subscription_matched_status_t matched{};
    dds_requested_incompatible_qos_status_t incompatible{};
    dds_get_subscription_matched_status(reader, &matched);
    dds_get_requested_incompatible_qos_status(reader, &incompatible);
    if (matched.current_count > 0) return true;
    if (incompatible.total_count > 0 || std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(10ms);
  }
}

// The shipped UR5 cell, small and short: the background learnt in 10 frames, the person
// arriving from frame 100 on; published under /h1test in this process's test domain.
Config outputs_config(const std::string& cloud_hz, int frames) {
  return load_config(test::scene_path("cell-ur5.yaml"),
                     {"sim.width=424", "sim.height=240", "sim.color=false", "sim.frames=" + std::to_string(frames),
                      "background.frames=10", "ros2.publish=true", "ros2.namespace=/h1test",
                      "ros2.domain_id=" + std::to_string(test::test_domain()), "ros2.cloud_hz=" + cloud_hz});
}

// Runs the assembled cell with `capture` after its sinks; returns the cell (its writers live on).
std::unique_ptr<app::Cell> run_cell(const Config& config, CaptureSink& capture) {
  std::unique_ptr<app::Cell> cell = app::assemble_cell(config);
  std::vector<Sink*> sinks = cell->link_sinks();
  sinks.push_back(&capture);
  app::TeeSink tee(sinks);
  run_pipeline(cell->frames(), *cell->robot_states, *cell->pipeline, tee, cell->run_options, cell->header);
  return cell;
}

TEST(Ros2Outputs, TopicNamesUnderTheNamespaceAndTheSpeedScalingOverride) {
  const Ros2OutputTopics plain = ros2_output_topics("/hrcsense", "");
  EXPECT_EQ(plain.verdict, "/hrcsense/verdict");
  EXPECT_EQ(plain.speed_scaling, "/hrcsense/speed_scaling");
  EXPECT_EQ(plain.markers, "/hrcsense/markers");
  EXPECT_EQ(plain.foreground, "/hrcsense/foreground");
  EXPECT_EQ(plain.tf_static, "/tf_static");
  EXPECT_EQ(ros2_output_topics("/cell", "/speed_scaling_state_broadcaster/speed_scaling").speed_scaling,
            "/speed_scaling_state_broadcaster/speed_scaling");
  EXPECT_THROW(ros2_output_topics("/cell", "speed_scaling"), Ros2Error);
}

struct VerdictSample {
  hrcsense_msgs_msg_dds__Verdict_ msg{};
  std::string frame_id;
};

TEST(Ros2Outputs, EveryResultIsOneVerdictWithItsValues) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const Config config = outputs_config("100", 130);
  ParticipantScope scope(test::test_domain());
  const dds_entity_t verdicts = output_reader(scope, hrcsense_msgs_msg_dds__Verdict__desc, "rt/h1test/verdict",
                                              EndpointQos{true, false, 1000});
  const dds_entity_t markers = output_reader(scope, visualization_msgs_msg_dds__MarkerArray__desc,
                                             "rt/h1test/markers", EndpointQos{true, false, 1000});
  const dds_entity_t clouds = output_reader(scope, sensor_msgs_msg_dds__PointCloud2__desc, "rt/h1test/foreground",
                                            EndpointQos{true, false, 1000});
  CaptureSink capture;
  const std::unique_ptr<app::Cell> cell = run_cell(config, capture);
  ASSERT_TRUE(cell->ros2_outputs);
  const std::vector<FrameResult>& results = capture.results;
  ASSERT_EQ(results.size(), 131U) << "130 frames and the final stop";
  EXPECT_FALSE(results.back().source_frame);

  std::vector<VerdictSample> got;
  take_samples<hrcsense_msgs_msg_dds__Verdict_>(verdicts, results.size(), [&](const auto& msg) {
    got.push_back(VerdictSample{msg, msg.header.frame_id != nullptr ? msg.header.frame_id : ""});
  });
  ASSERT_EQ(got.size(), results.size());
  const std::string base = config.pipeline.robot.base_frame == BaseFrame::base_link ? "base_link" : "base";
  const uint8_t kNumber[] = {0, 1, 2};  // run, slow, stop as the message defines them
  int with_contact = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    const hrcsense_msgs_msg_dds__Verdict_& msg = got[i].msg;
    const FrameResult& r = results[i];
    SCOPED_TRACE("sample " + std::to_string(i));
    EXPECT_EQ(msg.seq, i + 1) << "seq starts at 1 and counts every sample";
    EXPECT_EQ(msg.session, process_session());
    EXPECT_EQ(got[i].frame_id, base);
    EXPECT_EQ(static_cast<int64_t>(msg.header.stamp.sec) * 1'000'000'000 + msg.header.stamp.nanosec, r.timestamp_ns);
    EXPECT_EQ(msg.verdict, kNumber[static_cast<int>(r.verdict.state)]);
    EXPECT_EQ(msg.reason_code, static_cast<uint16_t>(r.verdict.code));
    EXPECT_EQ(msg.speed_scale, r.verdict.speed_scale);
    EXPECT_EQ(msg.protective_distance_m, r.verdict.protective_distance_m);
    EXPECT_EQ(msg.governing_link, r.governing_link);
    EXPECT_EQ(msg.frame_age_s, static_cast<float>(r.frame_age_s));
    if (r.contact.valid) {
      ++with_contact;
      EXPECT_EQ(msg.distance_m, r.contact.distance_m);
    } else {
      EXPECT_TRUE(std::isnan(msg.distance_m));
    }
  }
  EXPECT_GT(with_contact, 0) << "the person reaches the table within the run";
  EXPECT_EQ(got.back().msg.verdict, 2) << "the final stop";
  EXPECT_EQ(got.back().msg.reason_code, 17) << "source_ended";

  // One MarkerArray per result, each starting with DELETEALL.
  size_t arrays = 0;
  take_samples<visualization_msgs_msg_dds__MarkerArray_>(markers, results.size(), [&](const auto& array) {
    ++arrays;
    ASSERT_GT(array.markers._length, 0U);
    EXPECT_EQ(array.markers._buffer[0].action, 3);
  });
  EXPECT_EQ(arrays, results.size());

  // Clouds: the first valid frame's at least; each one is a valid frame's foreground.
  size_t cloud_count = 0;
  take_samples<sensor_msgs_msg_dds__PointCloud2_>(clouds, 1, [&](const auto& cloud) {
    ++cloud_count;
    const int64_t stamp = static_cast<int64_t>(cloud.header.stamp.sec) * 1'000'000'000 + cloud.header.stamp.nanosec;
    const FrameResult* from = nullptr;
    for (const FrameResult& r : results) {
      if (r.source_frame && r.timestamp_ns == stamp) from = &r;
    }
    ASSERT_NE(from, nullptr) << "a cloud stamped as no frame: " << stamp;
    EXPECT_TRUE(from->valid);
    EXPECT_EQ(cloud.width, from->foreground_points);
    EXPECT_EQ(cloud.data._length, 12U * cloud.width);
  });
  EXPECT_GE(cloud_count, 1U);
}

TEST(Ros2Outputs, LateReadersGetTheStaticTransformsAndTheLastSpeedScale) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const Config config = outputs_config("0", 20);
  CaptureSink capture;
  const std::unique_ptr<app::Cell> cell = run_cell(config, capture);
  ASSERT_FALSE(capture.results.empty());
  ParticipantScope scope(test::test_domain());
  const dds_entity_t tf = output_reader(scope, tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static",
                                        EndpointQos{true, true, 1});
  const dds_entity_t scaling = output_reader(scope, control_msgs_msg_dds__SpeedScalingFactor__desc,
                                             "rt/h1test/speed_scaling", EndpointQos{true, true, 1});
  std::vector<std::string> names;
  Pose T_base_optical = Pose::Identity();
  const size_t tf_messages = take_samples<tf2_msgs_msg_dds__TFMessage_>(tf, 1, [&](const auto& msg) {
    ASSERT_EQ(msg.transforms._length, 2U) << "one message with both edges";
    for (uint32_t i = 0; i < msg.transforms._length; ++i) {
      const auto& t = msg.transforms._buffer[i];
      names.push_back(std::string(t.header.frame_id) + ">" + t.child_frame_id);
      EXPECT_EQ(t.header.stamp.sec, 0);
      EXPECT_EQ(t.header.stamp.nanosec, 0U);
      Pose edge = Pose::Identity();
      edge.linear() = Eigen::Quaterniond(t.transform.rotation.w, t.transform.rotation.x, t.transform.rotation.y,
                                         t.transform.rotation.z)
                          .toRotationMatrix();
      edge.translation() = Eigen::Vector3d(t.transform.translation.x, t.transform.translation.y, t.transform.translation.z);
      T_base_optical = T_base_optical * edge;
    }
  });
  EXPECT_EQ(tf_messages, 1U);
  const std::string base = config.pipeline.robot.base_frame == BaseFrame::base_link ? "base_link" : "base";
  EXPECT_EQ(names, (std::vector<std::string>{base + ">camera_link", "camera_link>camera_depth_optical_frame"}));
  EXPECT_TRUE(T_base_optical.matrix().isApprox(config.pipeline.T_base_camera.matrix(), 1e-9))
      << T_base_optical.matrix() << "\nwant\n" << config.pipeline.T_base_camera.matrix();

  std::vector<double> factors;
  take_samples<control_msgs_msg_dds__SpeedScalingFactor_>(scaling, 1,
                                                          [&](const auto& msg) { factors.push_back(msg.factor); });
  ASSERT_EQ(factors.size(), 1U) << "keep-last 1, latched";
  EXPECT_EQ(factors[0], 0.0) << "the final stop pauses the arm";
  EXPECT_EQ(capture.results.back().verdict.speed_scale, 0.0F);
}

TEST(Ros2Outputs, VerdictOffersItsDeadlineAndCloudsCanBeOff) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const Config config = outputs_config("0", 20);
  ParticipantScope scope(test::test_domain());
  const dds_entity_t clouds = output_reader(scope, sensor_msgs_msg_dds__PointCloud2__desc, "rt/h1test/foreground",
                                            EndpointQos{true, false, 100});
  CaptureSink capture;
  const std::unique_ptr<app::Cell> cell = run_cell(config, capture);
  auto* outputs = dynamic_cast<Ros2OutputSink*>(cell->ros2_outputs.get());
  ASSERT_NE(outputs, nullptr);
  // safety.max_frame_gap_periods nominal frame periods of the source.
  const double period_s = 1.0 / capture.header_.source.nominal_fps;
  const auto want_ns =
      static_cast<int64_t>(std::llround(config.pipeline.safety.max_frame_gap_periods * period_s * 1e9));
  EXPECT_EQ(outputs->verdict_deadline_ns(), want_ns);

  EndpointQos same{true, false, 1};
  same.deadline_ns = want_ns;
  EXPECT_TRUE(reader_matches(output_reader(scope, hrcsense_msgs_msg_dds__Verdict__desc, "rt/h1test/verdict", same)));
  EndpointQos shorter = same;
  shorter.deadline_ns = want_ns / 2;
  EXPECT_FALSE(reader_matches(output_reader(scope, hrcsense_msgs_msg_dds__Verdict__desc, "rt/h1test/verdict", shorter)))
      << "a reader asking for verdicts more often than offered is refused";

  EXPECT_EQ(take_samples<sensor_msgs_msg_dds__PointCloud2_>(clouds, 0, [](const auto&) {}), 0U) << "cloud_hz 0";
  EXPECT_EQ(outputs->counters().clouds, 0);
  EXPECT_EQ(outputs->counters().verdicts, static_cast<int64_t>(capture.results.size()));
  EXPECT_EQ(outputs->counters().failed_writes, 0);
}

// camera 1 m above the base looking along base +x (optical z = base +x, x = -y, y = -z).
Pose camera_looking_along_base_x() {
  Pose T = Pose::Identity();
  Eigen::Matrix3d R;
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  T.linear() = R;
  T.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  return T;
}

Ros2OutputParams chain_params() {
  Ros2OutputParams params;
  params.domain_id = test::test_domain();
  params.camera_domain_id = test::test_domain();
  params.node_namespace = "/h1chain";
  params.T_base_camera = camera_looking_along_base_x();
  params.camera_publishes_optical = true;
  params.cloud_hz = 0.0;
  return params;
}

// Writes one /tf_static message of the edges (parent, child, translation, quaternion x y z w)
// from a latched writer made on `scope`, as a camera node or a static_transform_publisher does.
struct TfEdgeText {
  const char* parent;
  const char* child;
  geometry_msgs_msg_dds__Vector3_ translation;
  geometry_msgs_msg_dds__Quaternion_ rotation;
};
void write_tf_static(ParticipantScope& scope, std::vector<TfEdgeText> edges) {
  const dds_entity_t topic = scope.own(
      dds_create_topic(scope.participant(), &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", nullptr, nullptr),
      "topic");
  const QosHandle latched(EndpointQos{true, true, 1});
  const dds_entity_t writer = scope.own(dds_create_writer(scope.participant(), topic, latched.get(), nullptr), "writer");
  std::vector<geometry_msgs_msg_dds__TransformStamped_> t(edges.size());
  for (size_t i = 0; i < edges.size(); ++i) {
    t[i].header.frame_id = const_cast<char*>(edges[i].parent);
    t[i].child_frame_id = const_cast<char*>(edges[i].child);
    t[i].transform.translation = edges[i].translation;
    t[i].transform.rotation = edges[i].rotation;
  }
  tf2_msgs_msg_dds__TFMessage_ msg{};
  msg.transforms._buffer = t.data();
  msg.transforms._length = msg.transforms._maximum = static_cast<uint32_t>(t.size());
  ASSERT_EQ(dds_write(writer, &msg), DDS_RETCODE_OK);
}

TEST(Ros2Outputs, CameraNodesOwnChainIsUsedUnderTheLinkOnly) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  ParticipantScope scope(test::test_domain());
  // realsense-ros's chain: camera_link → camera_depth_frame (15 mm to the left) →
  // camera_depth_optical_frame (the optical rotation, written as its quaternion).
  write_tf_static(scope, {{"camera_link", "camera_depth_frame", {0.0, 0.015, 0.0}, {0.0, 0.0, 0.0, 1.0}},
                          {"camera_depth_frame", "camera_depth_optical_frame", {0.0, 0.0, 0.0}, {-0.5, 0.5, -0.5, 0.5}}});

  Ros2OutputParams params = chain_params();
  params.camera_tf_wait_s = 10.0;  // a bound: the chain is latched and arrives at once
  Ros2OutputSink outputs(params);
  EXPECT_EQ(outputs.camera_tf_note(), "");
  ASSERT_EQ(outputs.tf_static_edges().size(), 1U) << "the camera node owns link → optical";
  const TfEdge& edge = outputs.tf_static_edges()[0];
  EXPECT_EQ(edge.parent_frame, "base");
  EXPECT_EQ(edge.child_frame, "camera_link");
  // By hand: the optical frame is the link rotated as the D435's, so the link has the base's
  // axes; the optical origin (0, 0, 1) is 15 mm left (+y) of the link's, so the link is at
  // (0, -0.015, 1).
  EXPECT_TRUE(edge.T_parent_child.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_NEAR(edge.T_parent_child.translation().x(), 0.0, 1e-12);
  EXPECT_NEAR(edge.T_parent_child.translation().y(), -0.015, 1e-12);
  EXPECT_NEAR(edge.T_parent_child.translation().z(), 1.0, 1e-12);
}

TEST(Ros2Outputs, ALinkThatHasAParentAlreadyGetsNoSecond) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  ParticipantScope scope(test::test_domain());
  // Someone's static_transform_publisher already places the link; the camera node its optics.
  write_tf_static(scope, {{"world", "placed_cam_link", {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0}},
                          {"placed_cam_link", "placed_cam_depth_optical_frame", {0.0, 0.0, 0.0}, {-0.5, 0.5, -0.5, 0.5}}});

  Ros2OutputParams params = chain_params();
  params.camera_name = "placed_cam";
  params.camera_tf_wait_s = 10.0;
  Ros2OutputSink outputs(params);
  EXPECT_TRUE(outputs.tf_static_edges().empty());
  EXPECT_NE(outputs.camera_tf_note().find("already has the parent world"), std::string::npos) << outputs.camera_tf_note();
}

TEST(Ros2Outputs, WithoutTheCameraNodesChainTheFixedRotationStandsIn) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  Ros2OutputParams params = chain_params();
  params.camera_name = "absent_cam";  // nobody publishes its frames
  params.camera_tf_wait_s = 0.2;
  Ros2OutputSink outputs(params);
  EXPECT_NE(outputs.camera_tf_note().find("fixed"), std::string::npos) << outputs.camera_tf_note();
  ASSERT_EQ(outputs.tf_static_edges().size(), 1U);
  const TfEdge& edge = outputs.tf_static_edges()[0];
  EXPECT_EQ(edge.child_frame, "absent_cam_link");
  EXPECT_TRUE(edge.T_parent_child.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_NEAR(edge.T_parent_child.translation().z(), 1.0, 1e-12);
}

TEST(Ros2Outputs, RefusedVerdictsAreCountedThenAPersistentFailure) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  Ros2OutputParams params = chain_params();
  params.camera_publishes_optical = false;
  Ros2OutputSink outputs(params);
  // Without header() there are no writers: every write is refused, and frame() never throws.
  FrameResult result;
  for (int i = 1; i < Ros2OutputSink::kFailedVerdictsInARow; ++i) {
    EXPECT_NO_THROW(outputs.frame(result));
    EXPECT_FALSE(outputs.failed()) << "a refused write alone is counted, not a failure";
  }
  EXPECT_GT(outputs.counters().failed_writes, 0);
  EXPECT_NE(outputs.counters().last_error.find("DDS write on /h1chain/"), std::string::npos) << outputs.counters().last_error;
  outputs.frame(result);
  EXPECT_TRUE(outputs.failed());
  EXPECT_NE(outputs.failure().find("in a row"), std::string::npos) << outputs.failure();
  EXPECT_NE(outputs.failure().find("/h1chain/verdict"), std::string::npos) << outputs.failure();
  EXPECT_EQ(outputs.counters().verdicts, 0);
}

}  // namespace
}  // namespace hrcsense::ros2
