// SPDX-License-Identifier: Apache-2.0
// RTDE protocol functions against the worked bytes of ../shared/specs/ur-rtde.md and against
// packages built here by hand, byte by byte.
#include "src/net/rtde_protocol.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace hrcsense::rtde {
namespace {

using Bytes = std::vector<uint8_t>;

Package only_package(const Bytes& bytes) {
  const PackageSplit split = split_package(bytes.data(), bytes.size());
  EXPECT_EQ(split.status, SplitStatus::package) << split.error;
  EXPECT_EQ(split.consumed, bytes.size());
  return split.package;
}

// Big-endian IEEE-754, written out here for the hand-built packages.
void put_double(Bytes& b, double v) {
  uint64_t u;
  std::memcpy(&u, &v, 8);
  for (int s = 56; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(u >> s));
}

TEST(RtdeEncode, ClientPackagesByteForByte) {
  EXPECT_EQ(encode_request_protocol_version(2), (Bytes{0x00, 0x05, 0x56, 0x00, 0x02}));
  EXPECT_EQ(encode_get_urcontrol_version(), (Bytes{0x00, 0x03, 0x76}));
  EXPECT_EQ(encode_start(), (Bytes{0x00, 0x03, 0x53}));
  EXPECT_EQ(encode_pause(), (Bytes{0x00, 0x03, 0x50}));
}

// 125 Hz is 0x405F400000000000; the 103 bytes of names make the size 3 + 8 + 103 = 114 (0x72).
TEST(RtdeEncode, SetupOutputsHasFrequencyThenNames) {
  const std::string names =
      "timestamp,actual_q,actual_qd,robot_mode,safety_mode,speed_scaling,target_speed_fraction,actual_TCP_pose";
  EXPECT_EQ(names, kOutputVariables);
  const Bytes out = encode_setup_outputs(125.0, names);
  ASSERT_EQ(out.size(), 114U);
  EXPECT_EQ(Bytes(out.begin(), out.begin() + 11), (Bytes{0x00, 0x72, 0x4F, 0x40, 0x5F, 0x40, 0, 0, 0, 0, 0}));
  EXPECT_EQ(std::string(out.begin() + 11, out.end()), names);
  EXPECT_THROW(encode_setup_outputs(125.0, std::string(2049, 'a')), std::invalid_argument);
}

TEST(RtdeParse, SpecRepliesAccepted) {
  bool accepted = false;
  std::string error;
  EXPECT_TRUE(parse_accepted(only_package({0x00, 0x04, 0x56, 0x01}), PackageType::request_protocol_version, accepted,
                             error));
  EXPECT_TRUE(accepted);
  accepted = false;
  EXPECT_TRUE(parse_accepted(only_package({0x00, 0x04, 0x53, 0x01}), PackageType::start, accepted, error));
  EXPECT_TRUE(accepted);
  accepted = false;
  EXPECT_TRUE(parse_accepted(only_package({0x00, 0x04, 0x50, 0x01}), PackageType::pause, accepted, error));
  EXPECT_TRUE(accepted);
  EXPECT_TRUE(parse_accepted(only_package({0x00, 0x04, 0x56, 0x00}), PackageType::request_protocol_version, accepted,
                             error));
  EXPECT_FALSE(accepted);
}

TEST(RtdeParse, SpecControllerVersion) {
  ControllerVersion v;
  std::string error;
  ASSERT_TRUE(parse_controller_version(
      only_package({0x00, 0x13, 0x76, 0, 0, 0, 5, 0, 0, 0, 8, 0, 0, 0, 0, 0, 0, 0, 0}), v, error))
      << error;
  EXPECT_EQ(v.major, 5U);
  EXPECT_EQ(v.minor, 8U);
  EXPECT_EQ(v.bugfix, 0U);
  EXPECT_EQ(v.build, 0U);
}

TEST(RtdeParse, SpecInputSetupReply) {
  SetupReply reply;
  std::string error;
  ASSERT_TRUE(parse_setup_reply(only_package({0x00, 0x11, 0x49, 0x01, 0x55, 0x49, 0x4E, 0x54, 0x33, 0x32, 0x2C, 0x44,
                                            0x4F, 0x55, 0x42, 0x4C, 0x45}),
                                PackageType::setup_inputs, reply, error))
      << error;
  EXPECT_EQ(reply.recipe_id, 1);
  EXPECT_EQ(reply.types, (std::vector<std::string>{"UINT32", "DOUBLE"}));
}

// The spec's data package for `timestamp,target_speed_fraction`: the recipe skips the second
// variable by its size, and the timestamp is ≈ 16412.206 s.
TEST(RtdeParse, SpecDataPackage) {
  SetupReply reply;
  reply.recipe_id = 1;
  reply.types = {"DOUBLE", "DOUBLE"};
  OutputRecipe recipe;
  std::string error;
  ASSERT_TRUE(make_output_recipe(reply, "timestamp,target_speed_fraction", recipe, error)) << error;
  DataSample sample;
  ASSERT_TRUE(parse_data_package(only_package({0x00, 0x14, 0x55, 0x01, 0x40, 0xD0, 0x07, 0x0D, 0x2F, 0x1A, 0x9F, 0xBE,
                                             0x3F, 0xF0, 0, 0, 0, 0, 0, 0}),
                                 recipe, sample, error))
      << error;
  EXPECT_EQ(sample.recipe_id, 1);
  EXPECT_NEAR(sample.timestamp_s, 16412.206, 1e-3);
  EXPECT_EQ(sample.target_speed_fraction, 1.0);  // 3F F0 00 .. 00
}

// hrcsense's own recipe, a package built by hand: timestamp 12.5, q_j = 0.25 j − 1, qd_j = 0.5 j,
// robot_mode 7, safety_mode 3 (protective stop), speed_scaling 0.75, slider 0.5, TCP pose 0.1 j.
TEST(RtdeParse, OwnRecipeDataPackage) {
  SetupReply reply;
  reply.recipe_id = 4;
  reply.types = {"DOUBLE", "VECTOR6D", "VECTOR6D", "INT32", "INT32", "DOUBLE", "DOUBLE", "VECTOR6D"};
  OutputRecipe recipe;
  std::string error;
  ASSERT_TRUE(make_output_recipe(reply, kOutputVariables, recipe, error)) << error;
  EXPECT_EQ(recipe.payload_size, 1U + 8 + 48 + 48 + 4 + 4 + 8 + 8 + 48);
  Bytes b{0x00, 0x00, 0x55, 0x04};
  put_double(b, 12.5);
  for (int j = 0; j < 6; ++j) put_double(b, 0.25 * j - 1.0);
  for (int j = 0; j < 6; ++j) put_double(b, 0.5 * j);
  for (uint8_t v : {0, 0, 0, 7, 0, 0, 0, 3}) b.push_back(v);
  put_double(b, 0.75);
  put_double(b, 0.5);
  for (int j = 0; j < 6; ++j) put_double(b, 0.1 * j);
  b[0] = static_cast<uint8_t>(b.size() >> 8);
  b[1] = static_cast<uint8_t>(b.size() & 0xFF);
  DataSample s;
  ASSERT_TRUE(parse_data_package(only_package(b), recipe, s, error)) << error;
  EXPECT_EQ(s.timestamp_s, 12.5);
  for (int j = 0; j < 6; ++j) {
    EXPECT_EQ(s.q[j], 0.25 * j - 1.0);
    EXPECT_EQ(s.qd[j], 0.5 * j);
    EXPECT_EQ(s.tcp_pose[j], 0.1 * j);
  }
  EXPECT_EQ(s.robot_mode, 7);
  EXPECT_EQ(s.safety_mode, 3);
  EXPECT_EQ(s.speed_scaling, 0.75);
  EXPECT_EQ(s.target_speed_fraction, 0.5);

  // Another recipe id, or 8 bytes the recipe does not explain: rejected, naming the package.
  Bytes wrong_id = b;
  wrong_id[3] = 7;
  EXPECT_FALSE(parse_data_package(only_package(wrong_id), recipe, s, error));
  EXPECT_NE(error.find("DATA_PACKAGE: recipe id 7, expected 4"), std::string::npos) << error;
  Bytes oversized = b;
  oversized.insert(oversized.end(), 8, 0);
  oversized[1] = static_cast<uint8_t>(oversized[1] + 8);
  EXPECT_FALSE(parse_data_package(only_package(oversized), recipe, s, error));
  EXPECT_NE(error.find("DATA_PACKAGE: payload of 185 bytes, expected 177"), std::string::npos) << error;
}

TEST(RtdeParse, RecipeProblemsNameTheVariable) {
  OutputRecipe recipe;
  std::string error;
  SetupReply reply{1, {"DOUBLE", "VECTOR6D", "VECTOR6D", "INT32", "INT32", "DOUBLE", "DOUBLE", "NOT_FOUND"}};
  EXPECT_FALSE(make_output_recipe(reply, kOutputVariables, recipe, error));
  EXPECT_NE(error.find("'actual_TCP_pose' NOT_FOUND"), std::string::npos) << error;
  reply.types[7] = "VECTOR6D";
  reply.types[1] = "DOUBLE";
  EXPECT_FALSE(make_output_recipe(reply, kOutputVariables, recipe, error));
  EXPECT_NE(error.find("'actual_q' is DOUBLE, expected VECTOR6D"), std::string::npos) << error;
  reply.types.pop_back();
  EXPECT_FALSE(make_output_recipe(reply, kOutputVariables, recipe, error));
  EXPECT_NE(error.find("7 types for 8 requested variables"), std::string::npos) << error;
}

TEST(RtdeSplit, TruncatedWaitsShortSizeIsMalformedUnknownIsSkippedBySize) {
  const Bytes two{0x00, 0x04, 0x56, 0x01, 0x00, 0x08, 0x58, 1, 2, 3, 4, 5};  // V, then type 'X' (unknown)
  PackageSplit split = split_package(two.data(), two.size());
  ASSERT_EQ(split.status, SplitStatus::package);
  EXPECT_EQ(split.consumed, 4U);
  split = split_package(two.data() + 4, two.size() - 4);
  ASSERT_EQ(split.status, SplitStatus::package);
  EXPECT_EQ(split.package.type, 0x58);
  EXPECT_EQ(split.package.payload_size, 5U);
  EXPECT_STREQ(package_type_name(split.package.type), "unknown package type");
  EXPECT_EQ(split_package(two.data(), 2).status, SplitStatus::need_more);         // less than a header
  EXPECT_EQ(split_package(two.data() + 4, 7).status, SplitStatus::need_more);     // 7 of 8 bytes
  const Bytes short_size{0x00, 0x02, 0x55};
  split = split_package(short_size.data(), short_size.size());
  EXPECT_EQ(split.status, SplitStatus::malformed);
  EXPECT_NE(split.error.find("package size 2"), std::string::npos) << split.error;
}

TEST(RtdeParse, PayloadsTheTypeDoesNotExplainAreErrorsNamingThePackage) {
  bool accepted = false;
  ControllerVersion v;
  TextMessage text;
  std::string error;
  EXPECT_FALSE(parse_accepted(only_package({0x00, 0x05, 0x56, 0x01, 0x00}), PackageType::request_protocol_version,
                              accepted, error));
  EXPECT_NE(error.find("REQUEST_PROTOCOL_VERSION: payload of 2 bytes, expected 1"), std::string::npos) << error;
  EXPECT_FALSE(parse_accepted(only_package({0x00, 0x04, 0x53, 0x01}), PackageType::pause, accepted, error));
  EXPECT_NE(error.find("CONTROL_PACKAGE_PAUSE: got a CONTROL_PACKAGE_START"), std::string::npos) << error;
  EXPECT_FALSE(parse_controller_version(only_package({0x00, 0x07, 0x76, 0, 0, 0, 5}), v, error));
  EXPECT_NE(error.find("GET_URCONTROL_VERSION: payload of 4 bytes, expected 16"), std::string::npos) << error;
  // Text: message "abc", source "fake", level 3 (info); then a message length past the end.
  ASSERT_TRUE(parse_text_message(only_package({0x00, 0x0D, 0x4D, 3, 'a', 'b', 'c', 4, 'f', 'a', 'k', 'e', 3}), text,
                                 error))
      << error;
  EXPECT_EQ(text.message, "abc");
  EXPECT_EQ(text.source, "fake");
  EXPECT_EQ(text.level, 3);
  EXPECT_FALSE(parse_text_message(only_package({0x00, 0x06, 0x4D, 9, 'a', 'b'}), text, error));
  EXPECT_NE(error.find("TEXT_MESSAGE: message runs past"), std::string::npos) << error;
  EXPECT_FALSE(parse_text_message(only_package({0x00, 0x08, 0x4D, 1, 'a', 0, 3, 9}), text, error));
  EXPECT_NE(error.find("TEXT_MESSAGE: payload of 5 bytes, expected 4"), std::string::npos) << error;
}

}  // namespace
}  // namespace hrcsense::rtde
