// SPDX-License-Identifier: Apache-2.0
// Tests of the ROS 2 names and message conversions (dds/ros2_messages.hpp), against the
// realsense-ros layout and ROS 2 rules of ../shared/specs/ros2-interop.md, by hand.
#include "dds/ros2_messages.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace hrcsense::ros2 {
namespace {

TEST(Ros2Names, RealsenseRosTopicsUnderTheNodeNamespace) {
  const CameraTopics topics = realsense_topics("/camera/camera");
  EXPECT_EQ(topics.depth_image, "/camera/camera/depth/image_rect_raw");
  EXPECT_EQ(topics.depth_info, "/camera/camera/depth/camera_info");
  EXPECT_EQ(topics.color_image, "/camera/camera/color/image_raw");
  EXPECT_EQ(topics.color_info, "/camera/camera/color/camera_info");
  EXPECT_EQ(topics.extrinsics, "/camera/camera/extrinsics/depth_to_color");
  EXPECT_EQ(camera_info_topic("/cell/d435/aligned_depth_to_color/image_raw"),
            "/cell/d435/aligned_depth_to_color/camera_info");
  EXPECT_EQ(camera_name_of("/cell/d435"), "d435");
}

TEST(Ros2Names, DdsTopicIsRtPrefixed) {
  EXPECT_EQ(dds_topic_name("/camera/camera/depth/image_rect_raw"), "rt/camera/camera/depth/image_rect_raw");
  EXPECT_THROW(dds_topic_name("camera/depth"), Ros2Error);
}

TEST(Ros2Names, TypeNamesAreRos2Mangled) {
  // pkg/msg/T → pkg::msg::dds_::T_, nested types alike (the spec's "Names" table).
  EXPECT_STREQ(sensor_msgs_msg_dds__Image__desc.m_typename, "sensor_msgs::msg::dds_::Image_");
  EXPECT_STREQ(sensor_msgs_msg_dds__CameraInfo__desc.m_typename, "sensor_msgs::msg::dds_::CameraInfo_");
  EXPECT_STREQ(sensor_msgs_msg_dds__RegionOfInterest__desc.m_typename, "sensor_msgs::msg::dds_::RegionOfInterest_");
  EXPECT_STREQ(std_msgs_msg_dds__Header__desc.m_typename, "std_msgs::msg::dds_::Header_");
  EXPECT_STREQ(builtin_interfaces_msg_dds__Time__desc.m_typename, "builtin_interfaces::msg::dds_::Time_");
  EXPECT_STREQ(realsense2_camera_msgs_msg_dds__Extrinsics__desc.m_typename,
               "realsense2_camera_msgs::msg::dds_::Extrinsics_");
}

TEST(Ros2Stamp, NanosecondsRoundTripAndNanosecStaysPositive) {
  builtin_interfaces_msg_dds__Time_ stamp{};
  stamp.sec = 1'700'000'000;
  stamp.nanosec = 123'456'789;
  EXPECT_EQ(stamp_ns(stamp), 1'700'000'000'123'456'789);
  const builtin_interfaces_msg_dds__Time_ back = stamp_from_ns(1'700'000'000'123'456'789);
  EXPECT_EQ(back.sec, 1'700'000'000);
  EXPECT_EQ(back.nanosec, 123'456'789U);
  const builtin_interfaces_msg_dds__Time_ before_epoch = stamp_from_ns(-1);  // 1 ns before: sec -1, nanosec 999999999
  EXPECT_EQ(before_epoch.sec, -1);
  EXPECT_EQ(before_epoch.nanosec, 999'999'999U);
}

// A CameraInfo as realsense-ros fills it for a D435 depth stream at 848x480.
struct InfoFixture {
  std::vector<double> d{0.0, 0.0, 0.0, 0.0, 0.0};
  std::string model = "plumb_bob";
  sensor_msgs_msg_dds__CameraInfo_ info{};

  InfoFixture() {
    info.width = 848;
    info.height = 480;
    const double k[9] = {418.25, 0.0, 424.5, 0.0, 418.75, 238.25, 0.0, 0.0, 1.0};
    std::memcpy(info.k, k, sizeof k);
  }
  const sensor_msgs_msg_dds__CameraInfo_& get() {
    info.distortion_model = model.data();
    info.d._buffer = d.data();
    info.d._length = info.d._maximum = static_cast<uint32_t>(d.size());
    return info;
  }
};

TEST(Ros2CameraInfo, PlumbBobIsBrownConradyWithKsPinhole) {
  InfoFixture f;
  f.d = {0.125, -0.25, 0.001, -0.002, 0.0625};
  const Intrinsics in = intrinsics_from_camera_info(f.get(), "/cam/depth/camera_info");
  EXPECT_EQ(in.width, 848);
  EXPECT_EQ(in.height, 480);
  EXPECT_EQ(in.fx, 418.25F);
  EXPECT_EQ(in.fy, 418.75F);
  EXPECT_EQ(in.ppx, 424.5F);
  EXPECT_EQ(in.ppy, 238.25F);
  EXPECT_EQ(in.model, Distortion::brown_conrady);
  EXPECT_EQ(in.coeffs[0], 0.125F);
  EXPECT_EQ(in.coeffs[1], -0.25F);
  EXPECT_EQ(in.coeffs[2], 0.001F);
  EXPECT_EQ(in.coeffs[3], -0.002F);
  EXPECT_EQ(in.coeffs[4], 0.0625F);
}

TEST(Ros2CameraInfo, EquidistantIsKannalaBrandtAndNoneNeedsZeros) {
  InfoFixture f;
  f.model = "equidistant";
  f.d = {0.5, -0.25, 0.125, -0.0625};
  Intrinsics in = intrinsics_from_camera_info(f.get(), "t");
  EXPECT_EQ(in.model, Distortion::kannala_brandt4);
  EXPECT_EQ(in.coeffs[3], -0.0625F);
  EXPECT_EQ(in.coeffs[4], 0.0F);

  f.model = "";
  f.d = {};
  EXPECT_EQ(intrinsics_from_camera_info(f.get(), "t").model, Distortion::none);
  f.model = "none";
  f.d = {0.1, 0.0, 0.0, 0.0, 0.0};  // "none" with a coefficient is not none
  EXPECT_THROW(intrinsics_from_camera_info(f.get(), "t"), Ros2Error);
}

TEST(Ros2CameraInfo, RationalPolynomialOnlyWithoutItsRationalTerms) {
  InfoFixture f;
  f.model = "rational_polynomial";
  f.d = {0.1, 0.2, 0.0, 0.0, 0.3, 0.0, 0.0, 0.0};
  const Intrinsics in = intrinsics_from_camera_info(f.get(), "t");
  EXPECT_EQ(in.model, Distortion::brown_conrady);
  EXPECT_EQ(in.coeffs[4], 0.3F);
  f.d[6] = 0.01;  // k5: a term the SDK's models do not have
  EXPECT_THROW(intrinsics_from_camera_info(f.get(), "t"), Ros2Error);
}

TEST(Ros2CameraInfo, UnknownModelIsAnErrorNamingItAndTheTopic) {
  InfoFixture f;
  f.model = "fisheye_fov";
  f.d = {0.9};
  try {
    intrinsics_from_camera_info(f.get(), "/cam/depth/camera_info");
    FAIL() << "no error";
  } catch (const Ros2Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("fisheye_fov"), std::string::npos) << what;
    EXPECT_NE(what.find("/cam/depth/camera_info"), std::string::npos) << what;
  }
}

TEST(Ros2CameraInfo, NotAPinholeOrWrongCountIsAnError) {
  InfoFixture f;
  f.d = {0.0, 0.0, 0.0};  // plumb_bob wants 5 (zeros may be short)
  EXPECT_NO_THROW(intrinsics_from_camera_info(f.get(), "t"));
  f.d = {0.1, 0.0, 0.0};
  EXPECT_THROW(intrinsics_from_camera_info(f.get(), "t"), Ros2Error);
  InfoFixture g;
  g.info.k[8] = 0.0;
  EXPECT_THROW(intrinsics_from_camera_info(g.get(), "t"), Ros2Error);
  InfoFixture h;
  h.info.width = 0;
  EXPECT_THROW(intrinsics_from_camera_info(h.get(), "t"), Ros2Error);
}

// CameraInfo holds doubles, Intrinsics float32 (as the SDK's): a focal length that is positive
// as a double but 0 or inf as a float, or a coefficient beyond float's range, is refused
// (found by fuzz_ros2).
TEST(Ros2CameraInfo, ValuesOutsideFloatRangeAreAnError) {
  for (double fx : {1e-300, 1e300}) {
    InfoFixture f;
    f.info.k[0] = fx;
    EXPECT_THROW(intrinsics_from_camera_info(f.get(), "t"), Ros2Error) << fx;
  }
  InfoFixture g;
  g.info.k[2] = -1e39;  // cx
  EXPECT_THROW(intrinsics_from_camera_info(g.get(), "t"), Ros2Error);
  InfoFixture h;
  h.d = {1e39, 0.0, 0.0, 0.0, 0.0};
  EXPECT_THROW(intrinsics_from_camera_info(h.get(), "t"), Ros2Error);
  InfoFixture ok;
  ok.info.k[0] = 1e-3;  // small but a float: accepted
  EXPECT_FLOAT_EQ(intrinsics_from_camera_info(ok.get(), "t").fx, 1e-3F);
}

TEST(Ros2CameraInfo, FillWritesWhatRealsenseRosWrites) {
  Intrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = 380.5F;
  in.fy = 381.25F;
  in.ppx = 320.75F;
  in.ppy = 240.5F;
  in.model = Distortion::inverse_brown_conrady;
  in.coeffs = {0.5F, 0.25F, 0.0F, 0.0F, 0.125F};
  std::vector<double> d;
  sensor_msgs_msg_dds__CameraInfo_ info{};
  const std::string frame_id = "camera_depth_optical_frame";  // the info points at it
  fill_camera_info(in, 5'000'000'007, frame_id, d, info);
  EXPECT_EQ(info.header.stamp.sec, 5);
  EXPECT_EQ(info.header.stamp.nanosec, 7U);
  EXPECT_STREQ(info.header.frame_id, "camera_depth_optical_frame");
  EXPECT_STREQ(info.distortion_model, "plumb_bob");
  ASSERT_EQ(info.d._length, 5U);
  EXPECT_EQ(info.d._buffer[4], 0.125);
  const double k[9] = {380.5, 0.0, 320.75, 0.0, 381.25, 240.5, 0.0, 0.0, 1.0};
  const double p[12] = {380.5, 0.0, 320.75, 0.0, 0.0, 381.25, 240.5, 0.0, 0.0, 0.0, 1.0, 0.0};
  for (int i = 0; i < 9; ++i) EXPECT_EQ(info.k[i], k[i]) << i;
  for (int i = 0; i < 12; ++i) EXPECT_EQ(info.p[i], p[i]) << i;
  EXPECT_EQ(info.r[0], 1.0);
  EXPECT_EQ(info.r[1], 0.0);
  EXPECT_EQ(info.r[8], 1.0);
  // Read back: the same pinhole; inverse Brown-Conrady comes back as Brown-Conrady, as
  // realsense-ros's plumb_bob says no more (docs/CAMERAS.md).
  const Intrinsics back = intrinsics_from_camera_info(info, "t");
  EXPECT_EQ(back.fx, in.fx);
  EXPECT_EQ(back.ppy, in.ppy);
  EXPECT_EQ(back.model, Distortion::brown_conrady);
  EXPECT_EQ(back.coeffs, in.coeffs);
}

// A 3x2 16UC1 image with rows padded to 8 bytes.
struct DepthFixture {
  std::string encoding = "16UC1";
  std::vector<uint8_t> bytes{0xE8, 0x03, 0xD0, 0x07, 0x00, 0x00, 0xAA, 0xBB,   // 1000 2000 0 | pad
                             0x01, 0x00, 0xFF, 0xFF, 0x34, 0x12, 0xCC, 0xDD};  // 1 65535 0x1234 | pad
  sensor_msgs_msg_dds__Image_ image{};
  DepthFixture() {
    image.width = 3;
    image.height = 2;
    image.step = 8;
  }
  const sensor_msgs_msg_dds__Image_& get() {
    image.encoding = encoding.data();
    image.data._buffer = bytes.data();
    image.data._length = image.data._maximum = static_cast<uint32_t>(bytes.size());
    return image;
  }
};

TEST(Ros2DepthImage, PaddedRowsAreCopiedInMillimetres) {
  DepthFixture f;
  ASSERT_EQ(depth_image_problem(f.get(), 3, 2), "");
  DepthImage depth;
  copy_depth_image(f.get(), depth);
  EXPECT_EQ(depth.width, 3);
  EXPECT_EQ(depth.height, 2);
  EXPECT_EQ(depth.depth_scale_m, 0.001F);
  EXPECT_EQ(depth.pixels, (std::vector<uint16_t>{1000, 2000, 0, 1, 65535, 0x1234}));
}

TEST(Ros2DepthImage, BigEndianIsSwapped) {
  DepthFixture f;
  f.image.is_bigendian = 1;
  DepthImage depth;
  copy_depth_image(f.get(), depth);
  EXPECT_EQ(depth.at(0, 0), 0xE803);
  EXPECT_EQ(depth.at(2, 1), 0x3412);
}

TEST(Ros2DepthImage, WrongEncodingSizeStepOrLengthIsNamed) {
  DepthFixture f;
  f.encoding = "32FC1";
  EXPECT_NE(depth_image_problem(f.get(), 3, 2).find("encoding '32FC1'"), std::string::npos);
  DepthFixture g;
  EXPECT_NE(depth_image_problem(g.get(), 4, 2).find("size 3x2"), std::string::npos);
  DepthFixture h;
  h.image.step = 5;  // less than 2 bytes x 3 pixels
  EXPECT_NE(depth_image_problem(h.get(), 3, 2).find("step 5"), std::string::npos);
  DepthFixture i;
  i.bytes.pop_back();
  EXPECT_NE(depth_image_problem(i.get(), 3, 2).find("data 15 bytes"), std::string::npos);
  DepthFixture empty;  // 0 columns with no data: refused even when 0 was expected (found by fuzz_ros2)
  empty.image.width = 0;
  empty.image.step = 0;
  empty.bytes.clear();
  EXPECT_NE(depth_image_problem(empty.get(), 0, 2).find("size 0x2: empty"), std::string::npos);
}

TEST(Ros2ColorImage, Bgr8IsSwappedToRgb) {
  std::vector<uint8_t> bytes{10, 20, 30, 40, 50, 60};
  std::string encoding = "bgr8";
  sensor_msgs_msg_dds__Image_ image{};
  image.width = 2;
  image.height = 1;
  image.step = 6;
  image.encoding = encoding.data();
  image.data._buffer = bytes.data();
  image.data._length = 6;
  ASSERT_EQ(color_image_problem(image), "");
  ColorImage color;
  copy_color_image(image, color);
  EXPECT_EQ(color.rgb, (std::vector<uint8_t>{30, 20, 10, 60, 50, 40}));
  encoding = "yuv422";
  image.encoding = encoding.data();
  EXPECT_NE(color_image_problem(image).find("yuv422"), std::string::npos);
}

TEST(Ros2Extrinsics, ColumnMajorBothWays) {
  realsense2_camera_msgs_msg_dds__Extrinsics_ msg{};
  for (int i = 0; i < 9; ++i) msg.rotation[i] = 0.125 * i;
  msg.translation[0] = 0.015;
  const Extrinsics e = extrinsics_from_msg(msg);
  EXPECT_EQ(e.rotation[3], 0.375F);  // element (row 0, column 1), as in the SDK's layout
  EXPECT_EQ(e.translation_m[0], 0.015F);
  const realsense2_camera_msgs_msg_dds__Extrinsics_ back = extrinsics_to_msg(e);
  EXPECT_EQ(back.rotation[8], 1.0);
}

TEST(Ros2StampGaps, CountsMissingFramesAndTellsOutagesApart) {
  StampGapCounter gaps;
  const int64_t p = 33'333'333;  // 30 frames/s
  EXPECT_EQ(gaps.add(0), 0);
  EXPECT_EQ(gaps.add(p), 0);
  EXPECT_EQ(gaps.add(2 * p + 3'000'000), 0);  // 3 ms of jitter loses nothing
  EXPECT_EQ(gaps.add(5 * p), 2);              // frames 3 and 4 missing
  EXPECT_EQ(gaps.add(6 * p), 0);
  EXPECT_EQ(gaps.frames_missed, 2);
  EXPECT_EQ(gaps.add(6 * p + 3'000'000'000), 0);  // three seconds away: a silence, not 90 lost frames
  EXPECT_EQ(gaps.outages, 1);
  EXPECT_EQ(gaps.add(0), 0);  // a restarted publisher starts over
  EXPECT_EQ(gaps.add(p), 0);
  EXPECT_EQ(gaps.add(3 * p), 1);
  EXPECT_EQ(gaps.frames_missed, 3);
}

TEST(Ros2StampGaps, StepsShorterThanAMillisecondAreNoPeriod) {
  // Stamps 1 ns apart (a publisher counting frames, not time) must not turn the next real
  // step into millions of lost frames.
  StampGapCounter gaps;
  for (int64_t t = 0; t < 5; ++t) EXPECT_EQ(gaps.add(t), 0);
  EXPECT_EQ(gaps.add(500'000'000), 0);
  EXPECT_EQ(gaps.add(533'333'333), 0);  // 33 ms: the shortest believable step so far, the period
  EXPECT_EQ(gaps.add(600'000'000), 1);
  EXPECT_EQ(gaps.frames_missed, 1);
}

TEST(Ros2HostTime, WallClockStampsMapToMonotonicOthersToArrival) {
  const int64_t wall = 1'800'000'000'000'000'000;
  const int64_t mono = 5'000'000'000;
  // Taken 12 ms ago on the wall clock: 12 ms before now on the monotonic clock.
  EXPECT_EQ(host_time_of_stamp(wall - 12'000'000, wall, mono), mono - 12'000'000);
  // Slightly ahead (a camera clock a little fast): never later than now.
  EXPECT_EQ(host_time_of_stamp(wall + 2'000'000, wall, mono), mono);
  // A replayed recording of 2020, or a simulator at t = 0: the arrival time stands in.
  EXPECT_EQ(host_time_of_stamp(1'600'000'000'000'000'000, wall, mono), mono);
  EXPECT_EQ(host_time_of_stamp(33'000'000, wall, mono), mono);
}

}  // namespace
}  // namespace hrcsense::ros2
