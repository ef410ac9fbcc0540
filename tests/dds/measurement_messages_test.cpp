// SPDX-License-Identifier: Apache-2.0
// hrcsense_msgs/Measurement: a camera's measurement into the message and back, what makes a
// message unreadable, and one measurement over loopback DDS from the camera's writer to the
// fuser's reader (docs/MULTICAMERA.md).
#include "dds/measurement_endpoints.hpp"
#include "dds/measurement_messages.hpp"
#include "dds/ros2_messages.hpp"
#include "dds_test_util.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

namespace hrcsense::ros2 {
namespace {

CameraMeasurement sample_measurement() {
  CameraMeasurement m;
  m.camera_name = "left";
  m.session = 0xC0FFEEU;
  m.sequence = 42;
  m.frame = 1234;
  m.capture_ns = 1'800'000'000'123'456'789;
  m.nominal_fps = 30.0;
  m.intrinsics.width = 848;
  m.intrinsics.height = 480;
  m.intrinsics.fx = 421.5F;
  m.intrinsics.fy = 421.0F;
  m.intrinsics.ppx = 424.25F;
  m.intrinsics.ppy = 240.75F;
  m.T_base_camera = Pose::Identity();
  m.T_base_camera.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d(0, 0, 1)).toRotationMatrix();
  m.T_base_camera.translation() = Eigen::Vector3d(2.0, -0.5, 1.6);
  m.valid = true;
  m.reason_code = ReasonCode::clear;
  LinkContact l;
  l.link = 3;
  l.contact.valid = true;
  l.contact.distance_m = 0.625F;
  l.contact.robot_link = 3;
  l.contact.closest_base = {0.5F, 0.25F, 1.0F};
  l.contact.closest_robot_base = {0.25F, 0.25F, 0.5F};
  l.contact.closest_camera = {0.0F, -0.125F, 2.0F};
  l.speed_towards_mps = 0.75F;
  l.distance_uncertainty_m = 0.03125F;
  m.links = {l};
  m.contact = l.contact;
  m.unknown_distance_m = 0.875F;
  m.seen_free.reset(20);
  m.seen_free.set(0);
  m.seen_free.set(19);
  m.foreground_points = 1500;
  m.self_filtered_pixels = 900;
  m.invalid_pixels = 12;
  m.valid_share = 0.95F;
  m.robot_state.valid = true;
  m.robot_state.q_rad = {0.1, -1.0, 1.5, -2.0, -1.5, 0.25};
  m.robot_state.qd_rad_s = {0.5, 0.0, 0.0, 0.0, 0.0, -0.5};
  m.robot_state.sample_time_ns = m.capture_ns - 8'000'000;
  m.robot_state.extrapolated_ns = 3'000'000;
  m.robot_state.speed_fraction = 0.5;
  m.robot_state_age_ms = 8.0;
  m.latency_us = 2500.0;
  Contact truth = l.contact;
  truth.distance_m = 0.6F;
  m.truth = truth;
  m.truth_links = {{3, 0.6F, 0.7F}};
  return m;
}

TEST(MeasurementMessage, TheTopicIsUnderTheNamespaceAndTheNameMustBeAToken) {
  EXPECT_EQ(measurement_topic("/hrcsense", "front"), "/hrcsense/measurement/front");
  EXPECT_EQ(measurement_topic("/cell_a/", "cam_2"), "/cell_a/measurement/cam_2");
  EXPECT_THROW(measurement_topic("/hrcsense", "2front"), Ros2Error);
  EXPECT_THROW(measurement_topic("/hrcsense", "front/left"), Ros2Error);
  EXPECT_THROW(measurement_topic("hrcsense", "front"), Ros2Error);
}

TEST(MeasurementMessage, EveryFieldComesBackAsItWasSent) {
  const CameraMeasurement sent = sample_measurement();
  MeasurementBuffers buffers;
  const hrcsense_msgs_msg_dds__Measurement_ msg = measurement_message(sent, "base_link", buffers);
  EXPECT_STREQ(msg.header.frame_id, "base_link");
  EXPECT_EQ(msg.header.stamp.sec, 1'800'000'000);
  EXPECT_EQ(msg.header.stamp.nanosec, 123'456'789U);
  EXPECT_EQ(msg.seen_free_cells, 20U);
  EXPECT_EQ(msg.seen_free._length, 3U);  // 20 bits in 3 bytes
  CameraMeasurement got;
  ASSERT_EQ(camera_measurement_from(msg, got), "");
  EXPECT_EQ(got.camera_name, "left");
  EXPECT_EQ(got.session, 0xC0FFEEU);
  EXPECT_EQ(got.sequence, 42U);
  EXPECT_EQ(got.frame, 1234);
  EXPECT_EQ(got.capture_ns, sent.capture_ns);
  EXPECT_EQ(got.nominal_fps, 30.0);
  EXPECT_EQ(got.intrinsics.width, 848);
  EXPECT_EQ(got.intrinsics.ppy, 240.75F);
  EXPECT_TRUE(got.T_base_camera.isApprox(sent.T_base_camera, 1e-12));
  EXPECT_TRUE(got.valid);
  ASSERT_EQ(got.links.size(), 1U);
  EXPECT_EQ(got.links[0].link, 3);
  EXPECT_EQ(got.links[0].contact.distance_m, 0.625F);
  EXPECT_EQ(got.links[0].contact.closest_camera, Eigen::Vector3f(0.0F, -0.125F, 2.0F));
  EXPECT_EQ(got.links[0].speed_towards_mps, 0.75F);
  EXPECT_EQ(got.links[0].distance_uncertainty_m, 0.03125F);
  EXPECT_TRUE(got.contact.valid);
  EXPECT_EQ(got.contact.closest_robot_base, Eigen::Vector3f(0.25F, 0.25F, 0.5F));
  EXPECT_EQ(got.unknown_distance_m, 0.875F);
  EXPECT_EQ(got.seen_free.cells, 20U);
  EXPECT_TRUE(got.seen_free.test(0));
  EXPECT_TRUE(got.seen_free.test(19));
  EXPECT_FALSE(got.seen_free.test(10));
  EXPECT_EQ(got.foreground_points, 1500U);
  EXPECT_EQ(got.self_filtered_pixels, 900U);
  EXPECT_TRUE(got.robot_state.valid);
  EXPECT_EQ(got.robot_state.q_rad[5], 0.25);
  EXPECT_EQ(got.robot_state.qd_rad_s[0], 0.5);
  EXPECT_EQ(got.robot_state.sample_time_ns, sent.capture_ns - 8'000'000);
  EXPECT_EQ(got.robot_state.extrapolated_ns, 3'000'000);
  EXPECT_EQ(got.robot_state.speed_fraction, 0.5);
  EXPECT_EQ(got.robot_state_age_ms, 8.0);
  EXPECT_EQ(got.latency_us, 2500.0);
  ASSERT_TRUE(got.truth);
  EXPECT_EQ(got.truth->distance_m, 0.6F);
  ASSERT_EQ(got.truth_links.size(), 1U);
  EXPECT_EQ(got.truth_links[0].speed_towards_mps, 0.7F);
  EXPECT_EQ(measurement_problem(got), "");
}

TEST(MeasurementMessage, UnreadableMessagesSayWhy) {
  const CameraMeasurement sent = sample_measurement();
  MeasurementBuffers buffers;
  hrcsense_msgs_msg_dds__Measurement_ msg = measurement_message(sent, "base", buffers);
  CameraMeasurement got;
  msg.seen_free_cells = 25;  // needs 4 bytes, 3 came
  EXPECT_NE(camera_measurement_from(msg, got).find("seen_free: 3 bytes for 25 cells"), std::string::npos);
  msg.seen_free_cells = 20;
  msg.joints_rad._length = 5;  // a valid state with five joints
  EXPECT_NE(camera_measurement_from(msg, got).find("joints_rad"), std::string::npos);
  msg.joints_rad._length = 6;
  msg.camera_name = nullptr;
  EXPECT_EQ(camera_measurement_from(msg, got), "camera_name: null");
}

TEST(MeasurementMessage, OneMeasurementCrossesLoopbackFromTheCameraToTheFuser) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint32_t domain = test::test_domain();
  MeasurementReader reader(domain, "/cell_test", {"front", "left"});
  MeasurementWriterParams params;
  params.domain_id = domain;
  params.node_namespace = "/cell_test";
  params.camera_name = "left";
  params.nominal_fps = 30.0;
  MeasurementSink sink(params);
  EXPECT_EQ(sink.topic(), "/cell_test/measurement/left");
  RunHeader header;
  header.session = 0xABCDU;
  header.filters.intrinsics.width = 424;
  sink.header(header);

  FrameResult result;
  result.frame = 7;
  result.valid = true;
  result.clocked = true;
  result.seen_ns = 1'000'000'000;  // a run-clock time: 1 s after the steady clock's origin
  result.foreground_points = 0;
  // Wait for discovery, bounded: write until the reader has the sample (at most 5 s).
  size_t taken = 0;
  CameraMeasurement got;
  size_t topic = 99;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (taken == 0 && std::chrono::steady_clock::now() < deadline) {
    if (reader.writers(1) > 0) sink.frame(result);
    reader.wait(50'000'000);
    taken = reader.take([&](size_t t, const CameraMeasurement& m, const std::string& problem) {
      EXPECT_EQ(problem, "");
      topic = t;
      got = m;
    });
  }
  ASSERT_GT(taken, 0U) << "no measurement within 5 s";
  EXPECT_EQ(topic, 1U);
  EXPECT_EQ(got.camera_name, "left");
  EXPECT_EQ(got.session, 0xABCDU);
  EXPECT_EQ(got.frame, 7);
  EXPECT_EQ(got.intrinsics.width, 424);
  EXPECT_GE(got.sequence, 1U);
  // The capture moved onto the shared clock: 1 s after the steady origin plus the offset.
  EXPECT_NEAR(static_cast<double>(got.capture_ns - 1'000'000'000 - realtime_minus_steady_ns()), 0.0, 1e6);
  EXPECT_EQ(reader.writers(0), 0);
}

}  // namespace
}  // namespace hrcsense::ros2
