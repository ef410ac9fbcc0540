// SPDX-License-Identifier: Apache-2.0
// The bytes on the wire: one small sensor_msgs/Image as Cyclone serialises it from the
// idlc-generated type equals the XCDR1 encoding worked out by hand below from the rules of
// ../shared/specs/ros2-interop.md ("Wire format"), independent of idlc; and the DDS names a
// ROS 2 node would see.
#include "dds/dds_entity.hpp"
#include "dds_test_util.hpp"

#include <dds/ddsi/ddsi_serdata.h>
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::ros2 {
namespace {

TEST(Ros2Wire, SmallImageIsPlainLittleEndianCdr) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  DdsEntity participant(dds_create_participant(test::test_domain(), nullptr, nullptr));
  ASSERT_GT(participant.get(), 0);
  const dds_entity_t topic =
      dds_create_topic(participant.get(), &sensor_msgs_msg_dds__Image__desc, "rt/wire/image", nullptr, nullptr);
  ASSERT_GT(topic, 0);
  const QosHandle qos(EndpointQos{true, false, 1});
  const dds_entity_t writer = dds_create_writer(participant.get(), topic, qos.get(), nullptr);
  const dds_entity_t reader = dds_create_reader(participant.get(), topic, qos.get(), nullptr);
  ASSERT_GT(writer, 0);
  ASSERT_GT(reader, 0);

  // The DDS names a ROS 2 node matches on.
  char name[128];
  ASSERT_GE(dds_get_type_name(topic, name, sizeof name), 0);  // the length on success
  EXPECT_STREQ(name, "sensor_msgs::msg::dds_::Image_");
  ASSERT_GE(dds_get_name(topic, name, sizeof name), 0);
  EXPECT_STREQ(name, "rt/wire/image");

  // A 2x1 16UC1 image: 1000 mm and 2000 mm, stamped 1 s + 2 ns, frame "f".
  std::vector<uint8_t> pixels{0xE8, 0x03, 0xD0, 0x07};
  std::string frame_id = "f", encoding = "16UC1";
  sensor_msgs_msg_dds__Image_ image{};
  image.header.stamp.sec = 1;
  image.header.stamp.nanosec = 2;
  image.header.frame_id = frame_id.data();
  image.height = 1;
  image.width = 2;
  image.encoding = encoding.data();
  image.is_bigendian = 0;
  image.step = 4;
  image.data._buffer = pixels.data();
  image.data._length = image.data._maximum = 4;
  ASSERT_EQ(dds_write(writer, &image), DDS_RETCODE_OK);

  struct ddsi_serdata* serdata = nullptr;
  dds_sample_info_t info;
  int32_t taken = 0;
  for (int i = 0; i < 200 && taken <= 0; ++i) {  // local delivery is immediate; 2 s at most
    taken = dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE);
    if (taken <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(taken, 1);
  std::vector<uint8_t> bytes(ddsi_serdata_size(serdata));
  ddsi_serdata_to_ser(serdata, 0, bytes.size(), bytes.data());
  ddsi_serdata_unref(serdata);

  // Offsets count from the payload, after the 4-byte encapsulation header.
  const std::vector<uint8_t> expected{
      0x00, 0x01, 0x00, 0x00,                          // encapsulation: CDR little-endian (XCDR1)
      0x01, 0x00, 0x00, 0x00,                          //  0 header.stamp.sec = 1 (int32)
      0x02, 0x00, 0x00, 0x00,                          //  4 header.stamp.nanosec = 2 (uint32)
      0x02, 0x00, 0x00, 0x00, 'f', 0x00, 0x00, 0x00,   //  8 frame_id: length 2 with NUL, "f\0", pad to 16
      0x01, 0x00, 0x00, 0x00,                          // 16 height = 1
      0x02, 0x00, 0x00, 0x00,                          // 20 width = 2
      0x06, 0x00, 0x00, 0x00, '1', '6', 'U', 'C', '1', 0x00,  // 24 encoding: length 6, "16UC1\0"
      0x00,                                            // 34 is_bigendian = 0 (uint8)
      0x00,                                            // 35 pad: step is a uint32 at 36
      0x04, 0x00, 0x00, 0x00,                          // 36 step = 4
      0x04, 0x00, 0x00, 0x00,                          // 40 data: 4 elements
      0xE8, 0x03, 0xD0, 0x07,                          // 44 the pixels' bytes
  };
  EXPECT_EQ(bytes, expected);
}

}  // namespace
}  // namespace hrcsense::ros2
