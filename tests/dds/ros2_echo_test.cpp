// SPDX-License-Identifier: Apache-2.0
// `hrcsense echo`: each message type as one JSON line with the values of the message (made by
// hand here), the type found from the topic's name, and the command printing what a writer in
// this process publishes.
#include "../support/child_process.hpp"
#include "dds/dds_entity.hpp"
#include "dds/ros2_echo.hpp"
#include "dds_test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <signal.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>

namespace hrcsense::ros2 {
namespace {

using nlohmann::json;

TEST(Ros2Echo, TheTypeComesFromTheTopicsLastName) {
  EXPECT_EQ(echo_type_of_topic("/hrcsense/verdict"), EchoType::verdict);
  EXPECT_EQ(echo_type_of_topic("/cell_a/speed_scaling"), EchoType::speed_scaling);
  EXPECT_EQ(echo_type_of_topic("/hrcsense/markers"), EchoType::markers);
  EXPECT_EQ(echo_type_of_topic("/hrcsense/foreground"), EchoType::point_cloud);
  EXPECT_EQ(echo_type_of_topic("/tf_static"), EchoType::tf);
  EXPECT_EQ(echo_type_of_topic("/joint_states"), EchoType::joint_state);
  EXPECT_FALSE(echo_type_of_topic("/speed_scaling_state_broadcaster/speed_scaling_x").has_value());
  EXPECT_EQ(echo_type_named("float64"), EchoType::float64);
  EXPECT_FALSE(echo_type_named("Float64").has_value());
  for (EchoType t : {EchoType::verdict, EchoType::speed_scaling, EchoType::markers, EchoType::point_cloud, EchoType::tf,
                     EchoType::joint_state, EchoType::float64}) {
    EXPECT_EQ(echo_type_named(echo_type_name(t)), t);
  }
}

TEST(Ros2Echo, AVerdictLineHasEveryFieldAndNaNIsNull) {
  hrcsense_msgs_msg_dds__Verdict_ v{};
  v.header.stamp.sec = 3;
  v.header.stamp.nanosec = 250'000'000;
  v.header.frame_id = const_cast<char*>("base");
  v.session = 77;
  v.seq = 12;
  v.verdict = 1;
  v.reason_code = 29;
  v.speed_scale = 0.5F;
  v.distance_m = std::nanf("");
  v.protective_distance_m = 1.25F;
  v.governing_link = -1;
  v.frame_age_s = 0.0625F;
  const json line = json::parse(echo_line(v));
  EXPECT_EQ(line["stamp_ns"], 3'250'000'000LL);
  EXPECT_EQ(line["frame_id"], "base");
  EXPECT_EQ(line["session"], 77);
  EXPECT_EQ(line["seq"], 12);
  EXPECT_EQ(line["verdict"], "slow");
  EXPECT_EQ(line["reason_code"], 29);
  EXPECT_EQ(line["speed_scale"], 0.5);
  EXPECT_TRUE(line["distance_m"].is_null());
  EXPECT_EQ(line["protective_distance_m"], 1.25);
  EXPECT_EQ(line["governing_link"], -1);
  EXPECT_EQ(line["frame_age_s"], 0.0625);
}

TEST(Ros2Echo, JointStatesAndTransformsAreListed) {
  char* names[] = {const_cast<char*>("elbow_joint"), const_cast<char*>("wrist_1_joint")};
  double position[] = {1.5, -0.25};
  sensor_msgs_msg_dds__JointState_ js{};
  js.header.frame_id = const_cast<char*>("");
  js.name._buffer = names;
  js.name._length = js.name._maximum = 2;
  js.position._buffer = position;
  js.position._length = js.position._maximum = 2;
  const json joints = json::parse(echo_line(js));
  EXPECT_EQ(joints["name"], json({"elbow_joint", "wrist_1_joint"}));
  EXPECT_EQ(joints["position"], json({1.5, -0.25}));
  EXPECT_EQ(joints["velocity"], json::array());

  geometry_msgs_msg_dds__TransformStamped_ t{};
  t.header.frame_id = const_cast<char*>("base");
  t.child_frame_id = const_cast<char*>("camera_link");
  t.transform.translation = {2.0, 0.0, 1.6};
  t.transform.rotation = {0.0, 0.0, 0.0, 1.0};
  tf2_msgs_msg_dds__TFMessage_ tf{};
  tf.transforms._buffer = &t;
  tf.transforms._length = tf.transforms._maximum = 1;
  const json line = json::parse(echo_line(tf));
  ASSERT_EQ(line["transforms"].size(), 1U);
  EXPECT_EQ(line["transforms"][0]["parent"], "base");
  EXPECT_EQ(line["transforms"][0]["child"], "camera_link");
  EXPECT_EQ(line["transforms"][0]["translation_m"], json({2.0, 0.0, 1.6}));
  EXPECT_EQ(line["transforms"][0]["rotation_xyzw"], json({0.0, 0.0, 0.0, 1.0}));
}

TEST(Ros2EchoCli, PrintsWhatAWriterPublishes) {
  if (!test::loopback_configured()) GTEST_SKIP() << test::kNoLoopback;
  const uint32_t domain = test::test_domain();
  ParticipantScope scope(domain);
  const dds_entity_t topic = scope.own(dds_create_topic(scope.participant(), &control_msgs_msg_dds__SpeedScalingFactor__desc,
                                                        "rt/echo_test/speed_scaling", nullptr, nullptr),
                                       "topic");
  const QosHandle qos(EndpointQos{true, true, 1});
  const dds_entity_t writer = scope.own(dds_create_writer(scope.participant(), topic, qos.get(), nullptr), "writer");
  test::ChildProcess child({HRCSENSE_CLI, "echo", "/echo_test/speed_scaling", "--domain", std::to_string(domain),
                            "--count", "3", "--timeout-s", "30"});
  // Latched: the echo gets the last value even if it matched late; then two more.
  std::vector<double> printed;
  std::string line;
  double factor = 0.25;
  for (int round = 0; round < 600 && printed.size() < 3; ++round) {
    control_msgs_msg_dds__SpeedScalingFactor_ msg{factor};
    dds_write(writer, &msg);
    if (child.read_line(line, 0.05)) {
      printed.push_back(json::parse(line)["factor"].get<double>());
      factor += 0.25;
    }
  }
  EXPECT_EQ(child.wait(10.0), 0);
  ASSERT_EQ(printed.size(), 3U);
  // Each printed value is one that was written, in order.
  EXPECT_LT(printed[0], printed[1]);
  EXPECT_LT(printed[1], printed[2]);
  for (double p : printed) EXPECT_EQ(std::fmod(p, 0.25), 0.0) << p;
}

TEST(Ros2EchoCli, AnUnknownTopicWithoutTypeIsAUsageError) {
  test::ChildProcess child({HRCSENSE_CLI, "echo", "/some/topic", "--timeout-s", "1"});
  const int status = child.wait(20.0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
}

}  // namespace
}  // namespace hrcsense::ros2
