// SPDX-License-Identifier: Apache-2.0
// The fused view's DDS side (dds/camera_previews.hpp, dds/fused_view_reader.hpp) on loopback:
// the preview encoders and decoders against hand values, and two fake cameras publishing in
// this process (their measurement, cloud and depth preview, as `run --camera` does) read back
// by the viewer's reader: both cameras, their ages in the order of their hand-set capture
// stamps, the fused closest pair the hand-set smaller one, and an unconfigured camera unheard.
#if HRCSENSE_HAVE_DDS

#include "dds/camera_previews.hpp"
#include "dds/dds_entity.hpp"
#include "dds/fused_view_reader.hpp"
#include "dds/measurement_messages.hpp"
#include "dds/ros2_output_messages.hpp"
#include "tests/dds/dds_test_util.hpp"
#include "viewer/fused_view.hpp"

#include "hrcsense/clock.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

namespace hrcsense::fused_view_dds_test {
namespace {

TEST(CameraPreviews, DecimationKeepsEachBlocksNearestDepthInMillimetres) {
  DepthImage depth;
  depth.resize(9, 4);  // factor 4: 2 × 1, the ninth column and nothing else dropped
  depth.depth_scale_m = 0.0001F;  // 0.1 mm units
  std::fill(depth.pixels.begin(), depth.pixels.end(), 0);
  depth.pixels[1 * 9 + 2] = 20000;  // 2.0 m
  depth.pixels[3 * 9 + 0] = 15004;  // 1.5004 m: the block's nearest, 1500 mm
  depth.pixels[0 * 9 + 8] = 100;    // in the dropped column
  ros2::DepthPreview preview;
  ros2::decimate_depth_preview(depth, 4, 77, preview);
  EXPECT_EQ(preview.width, 2);
  EXPECT_EQ(preview.height, 1);
  EXPECT_EQ(preview.timestamp_ns, 77);
  ASSERT_EQ(preview.depth_mm.size(), 2U);
  EXPECT_EQ(preview.depth_mm[0], 1500);
  EXPECT_EQ(preview.depth_mm[1], 0);  // nothing valid in the second block
  // 848 × 480 by 4: the stated 212 × 120, 50 880 bytes a frame.
  EXPECT_EQ(ros2::depth_preview_bytes(848 / 4, 480 / 4), 50880);
}

TEST(CameraPreviews, TopicsBelowTheCamerasNameAndBadNamesRefused) {
  const ros2::CameraPreviewTopics topics = ros2::camera_preview_topics("/hrcsense", "left");
  EXPECT_EQ(topics.foreground, "/hrcsense/left/foreground");
  EXPECT_EQ(topics.depth_preview, "/hrcsense/left/depth_preview");
  EXPECT_THROW(ros2::camera_preview_topics("/hrcsense", "1st"), ros2::Ros2Error);
  EXPECT_THROW(ros2::camera_preview_topics("hrcsense", "left"), ros2::Ros2Error);
}

TEST(CameraPreviews, CloudAndPreviewDecodeWhatTheEncodersMake) {
  PointCloud points;
  points.x = {0.5F, -1.25F};
  points.y = {2.0F, 0.0F};
  points.z = {1.0F, 0.75F};
  std::vector<uint8_t> bytes;
  ros2::pack_xyz(points, bytes);
  std::array<sensor_msgs_msg_dds__PointField_, 3> fields{};
  const std::string frame = "base";
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  ros2::fill_point_cloud(bytes, 5, frame, fields, cloud);
  PointCloud back;
  EXPECT_EQ(ros2::points_from_cloud(cloud, back), "");
  EXPECT_EQ(back.x, points.x);
  EXPECT_EQ(back.y, points.y);
  EXPECT_EQ(back.z, points.z);
  // A cloud without z is refused, naming the field; one whose data is short too.
  cloud.fields._length = 2;
  EXPECT_NE(ros2::points_from_cloud(cloud, back).find("'z'"), std::string::npos);
  cloud.fields._length = 3;
  cloud.data._length = 12;
  EXPECT_NE(ros2::points_from_cloud(cloud, back).find("data"), std::string::npos);
  // No columns and 4e9 rows of 0 bytes: an empty cloud at once (the fuzz target once timed out
  // here, walking the empty rows).
  cloud.width = 0;
  cloud.height = 4'000'000'000U;
  cloud.row_step = 0;
  EXPECT_EQ(ros2::points_from_cloud(cloud, back), "");
  EXPECT_TRUE(back.x.empty());

  const std::vector<uint16_t> mm = {0, 1000, 2000, 65535, 7, 8};
  sensor_msgs_msg_dds__Image_ image{};
  ros2::fill_depth_image_16uc1(mm.data(), 3, 2, 9, frame, image);
  EXPECT_STREQ(image.encoding, "16UC1");
  EXPECT_EQ(image.step, 6U);
  ros2::DepthPreview preview;
  EXPECT_EQ(ros2::depth_preview_from(image, preview), "");
  EXPECT_EQ(preview.width, 3);
  EXPECT_EQ(preview.height, 2);
  EXPECT_EQ(preview.depth_mm, mm);
  EXPECT_EQ(preview.timestamp_ns, 9);
  image.step = 4;  // shorter than a row
  EXPECT_NE(ros2::depth_preview_from(image, preview), "");
}

// A fake camera process of a cell: its measurement writer (as MeasurementSink writes: reliable,
// keep-last 1) and its preview writers (as `run --camera` with ros2.publish).
class FakeCamera {
 public:
  FakeCamera(uint32_t domain, const std::string& name)
      : name_(name), scope_(domain), previews_(preview_params(domain, name)) {
    const std::string topic = ros2::dds_topic_name(ros2::measurement_topic("/hrcsense", name));
    const dds_entity_t t = scope_.own(dds_create_topic(scope_.participant(), &hrcsense_msgs_msg_dds__Measurement__desc,
                                                       topic.c_str(), nullptr, nullptr),
                                      "topic");
    const ros2::QosHandle qos(ros2::EndpointQos{true, false, 1});
    writer_ = scope_.own(dds_create_writer(scope_.participant(), t, qos.get(), nullptr), "writer");
  }
  void publish(const CameraMeasurement& m, const PointCloud& cloud, const ros2::DepthPreview& preview) {
    const hrcsense_msgs_msg_dds__Measurement_ msg = ros2::measurement_message(m, "base", buffers_);
    ASSERT_GE(dds_write(writer_, &msg), 0);
    ASSERT_TRUE(previews_.write_cloud(cloud, m.capture_ns));
    ASSERT_TRUE(previews_.write_depth_preview(preview));
  }

 private:
  static ros2::CameraPreviewParams preview_params(uint32_t domain, const std::string& name) {
    ros2::CameraPreviewParams params;
    params.domain_id = domain;
    params.camera_name = name;
    return params;
  }
  std::string name_;
  ros2::ParticipantScope scope_;
  ros2::CameraPreviewWriter previews_;
  dds_entity_t writer_ = 0;
  ros2::MeasurementBuffers buffers_;
};

CameraMeasurement fake_measurement(const std::string& name, int64_t capture_ns, float distance_m, int link) {
  CameraMeasurement m;
  m.camera_name = name;
  m.session = 7;
  m.sequence = 1;
  m.nominal_fps = 30.0;
  m.capture_ns = capture_ns;
  m.valid = true;
  m.reason_code = ReasonCode::clear;
  LinkContact contact;
  contact.link = link;
  contact.contact.valid = true;
  contact.contact.distance_m = distance_m;
  contact.contact.closest_base = Eigen::Vector3f(1.0F, 0.0F, 1.0F + distance_m);
  contact.contact.closest_robot_base = Eigen::Vector3f(1.0F, 0.0F, 1.0F);
  contact.contact.robot_link = link;
  m.links = {contact};
  m.contact = contact.contact;
  return m;
}

TEST(FusedViewReader, TwoCamerasOnLoopbackTheirAgesAndTheSmallerPair) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint32_t domain = test::test_domain();
  ros2::FusedViewParams params;
  params.domain_id = domain;
  Pose T_left = Pose::Identity();
  T_left.translation() = Eigen::Vector3d(2.0, 1.0, 2.0);
  params.cameras = {{"left", T_left, Intrinsics{}}, {"right", Pose::Identity(), Intrinsics{}}};
  ros2::FusedViewReader reader(params);

  // Hand-set: left captured 80 ms before `now`, right 300 ms; right's contact (0.35 m, link 2)
  // is the smaller; an unconfigured camera nearer still is never read.
  const int64_t now_ns = shared_clock_ns();
  const CameraMeasurement left = fake_measurement("left", now_ns - 80'000'000, 0.90F, 1);
  const CameraMeasurement right = fake_measurement("right", now_ns - 300'000'000, 0.35F, 2);
  const CameraMeasurement intruder = fake_measurement("intruder", now_ns, 0.01F, 0);
  PointCloud left_cloud, right_cloud;
  left_cloud.x = {1.0F, 1.1F};
  left_cloud.y = {0.0F, 0.1F};
  left_cloud.z = {1.9F, 1.8F};
  right_cloud.x = {1.0F};
  right_cloud.y = {0.0F};
  right_cloud.z = {1.35F};
  ros2::DepthPreview preview;
  preview.width = 4;
  preview.height = 2;
  preview.depth_mm = {0, 1, 2, 3, 4, 5, 6, 7};
  preview.timestamp_ns = now_ns;
  FakeCamera left_camera(domain, "left"), right_camera(domain, "right"), intruder_camera(domain, "intruder");

  // Volatile topics: samples written before the readers matched are lost, so the cameras write
  // until the reader has all of them (bounded: 200 turns of at most 20 ms).
  auto heard_all = [](const ros2::FusedView& view) {
    for (const ros2::FusedCameraView& camera : view.cameras) {
      if (!camera.measurement || camera.cloud_stamp_ns == 0 || camera.preview.width == 0) return false;
    }
    return true;
  };
  for (int turn = 0; turn < 200 && !heard_all(reader.view()); ++turn) {
    left_camera.publish(left, left_cloud, preview);
    right_camera.publish(right, right_cloud, preview);
    intruder_camera.publish(intruder, right_cloud, preview);
    reader.poll(20'000'000, 0);
  }
  const ros2::FusedView& view = reader.view();
  ASSERT_TRUE(heard_all(view));
  ASSERT_EQ(view.cameras.size(), 2U);
  EXPECT_EQ(view.cameras[0].name, "left");
  EXPECT_EQ(view.cameras[1].name, "right");
  EXPECT_EQ(view.cameras[0].cloud_base.x, left_cloud.x);
  EXPECT_EQ(view.cameras[1].cloud_base.z, right_cloud.z);
  EXPECT_EQ(view.cameras[0].preview.depth_mm, preview.depth_mm);
  EXPECT_EQ(view.cameras[0].rejected, 0);
  EXPECT_EQ(view.cameras[1].rejected, 0);
  EXPECT_FALSE(view.verdict.received);  // no fuser here: the view shows NO DATA, never its own verdict

  const std::vector<view::FusedCameraRow> rows = view::fused_camera_rows(view, now_ns);
  ASSERT_TRUE(rows[0].age_ms && rows[1].age_ms);
  EXPECT_DOUBLE_EQ(*rows[0].age_ms, 80.0);
  EXPECT_DOUBLE_EQ(*rows[1].age_ms, 300.0);
  EXPECT_LT(*rows[0].age_ms, *rows[1].age_ms);

  const view::FusedPair pair = view::fused_closest_pair(view);
  ASSERT_TRUE(pair.valid);
  EXPECT_EQ(pair.camera, "right");
  EXPECT_EQ(pair.link, 2);
  EXPECT_FLOAT_EQ(pair.distance_m, 0.35F);
  EXPECT_EQ(pair.closest_robot_base, Eigen::Vector3f(1.0F, 0.0F, 1.0F));
}

}  // namespace
}  // namespace hrcsense::fused_view_dds_test

#endif  // HRCSENSE_HAVE_DDS
