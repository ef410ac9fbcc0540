// SPDX-License-Identifier: Apache-2.0
// ros2/hrcsense_msgs/msg/*.msg (what a ROS 2 workspace builds) and dds/idl/hrcsense_msgs.idl
// (what hrcsense writes on the wire) must list the same fields, in the same order, of the same
// types: the wire is positional, so a field out of place there would be read as another one.
// Verdict, and the multi-camera Measurement with its LinkContact and LinkTruth.
// The ROS → IDL type names are the spec's table (../shared/specs/ros2-interop.md, "Wire format").
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using Field = std::pair<std::string, std::string>;  // (IDL type, name)

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The .msg's fields (constants, "TYPE NAME=VALUE", are not on the wire), their types as IDL.
std::vector<Field> msg_fields(const std::string& text) {
  const std::map<std::string, std::string> idl_of = {
      {"bool", "boolean"}, {"byte", "octet"}, {"uint8", "uint8"}, {"int8", "int8"}, {"uint16", "uint16"},
      {"int16", "int16"}, {"uint32", "uint32"}, {"int32", "int32"}, {"uint64", "uint64"}, {"int64", "int64"},
      {"float32", "float"}, {"float64", "double"}, {"string", "string"},
      {"std_msgs/Header", "std_msgs::msg::dds_::Header_"},
      {"geometry_msgs/Point", "geometry_msgs::msg::dds_::Point_"},
      {"geometry_msgs/Pose", "geometry_msgs::msg::dds_::Pose_"},
      {"LinkContact", "LinkContact_"},
      {"LinkTruth", "LinkTruth_"}};
  std::vector<Field> fields;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string type, name;
    if (!(words >> type >> name)) continue;
    if (name.find('=') != std::string::npos) continue;
    // T[] is sequence<T>, T[<=N] is sequence<T, N> (the spec's "Wire format").
    std::string bound;
    const size_t bracket = type.find('[');
    const bool sequence = bracket != std::string::npos;
    if (sequence) {
      bound = type.substr(bracket + 1, type.size() - bracket - 2);
      if (bound.rfind("<=", 0) == 0) bound = bound.substr(2);
      type = type.substr(0, bracket);
    }
    const auto idl = idl_of.find(type);
    EXPECT_NE(idl, idl_of.end()) << "no IDL type known for " << type;
    std::string idl_type = idl == idl_of.end() ? type : idl->second;
    if (sequence) idl_type = "sequence<" + idl_type + (bound.empty() ? "" : ", " + bound) + ">";
    fields.emplace_back(idl_type, name);
  }
  return fields;
}

// The members of `@final struct NAME { ... };` in the IDL.
std::vector<Field> idl_fields(const std::string& text, const std::string& name) {
  const size_t start = text.find("struct " + name + " {");
  EXPECT_NE(start, std::string::npos) << "no struct " << name;
  if (start == std::string::npos) return {};
  EXPECT_EQ(text.rfind("@final", start), start - 7) << name << " must be @final (XCDR1, rmw_cyclonedds)";
  const size_t open = text.find('{', start) + 1;
  const std::string body = text.substr(open, text.find("};", open) - open);
  std::vector<Field> fields;
  std::istringstream members(body);
  for (std::string member; std::getline(members, member, ';');) {
    // "TYPE NAME", where TYPE may be "sequence<T, N>": the name is the last word.
    const size_t end = member.find_last_not_of(" \n\t");
    if (end == std::string::npos) continue;
    const size_t name_start = member.find_last_of(" \n\t", end) + 1;
    const size_t type_start = member.find_first_not_of(" \n\t");
    const size_t type_end = member.find_last_not_of(" \n\t", name_start - 1);
    fields.emplace_back(member.substr(type_start, type_end - type_start + 1), member.substr(name_start, end - name_start + 1));
  }
  return fields;
}

TEST(VerdictMessage, TheRosMessageAndTheIdlListTheSameFields) {
  const std::string source = HRCSENSE_SOURCE_DIR;
  const std::vector<Field> msg = msg_fields(read_text(source + "/ros2/hrcsense_msgs/msg/Verdict.msg"));
  const std::vector<Field> idl = idl_fields(read_text(source + "/dds/idl/hrcsense_msgs.idl"), "Verdict_");
  EXPECT_EQ(msg, idl);
  // The order, written out here independently of both files.
  const std::vector<Field> expected = {{"std_msgs::msg::dds_::Header_", "header"},
                                       {"uint32", "session"},
                                       {"uint32", "seq"},
                                       {"uint8", "verdict"},
                                       {"uint16", "reason_code"},
                                       {"float", "speed_scale"},
                                       {"float", "distance_m"},
                                       {"float", "protective_distance_m"},
                                       {"int32", "governing_link"},
                                       {"float", "frame_age_s"}};
  EXPECT_EQ(idl, expected);
}

TEST(MeasurementMessage, TheRosMessagesAndTheIdlListTheSameFields) {
  const std::string source = HRCSENSE_SOURCE_DIR;
  const std::string idl = read_text(source + "/dds/idl/hrcsense_msgs.idl");
  for (const std::string name : {"Measurement", "LinkContact", "LinkTruth"}) {
    const std::vector<Field> msg = msg_fields(read_text(source + "/ros2/hrcsense_msgs/msg/" + name + ".msg"));
    EXPECT_EQ(msg, idl_fields(idl, name + "_")) << name;
  }
  // A few members written out here, independently of both files: the nested and bounded ones.
  const std::vector<Field> measurement = idl_fields(idl, "Measurement_");
  ASSERT_GE(measurement.size(), 20U);
  EXPECT_EQ(measurement[0], Field("std_msgs::msg::dds_::Header_", "header"));
  EXPECT_EQ(measurement[1], Field("string", "camera_name"));
  EXPECT_EQ(measurement[3], Field("uint64", "seq"));
  EXPECT_NE(std::find(measurement.begin(), measurement.end(), Field("sequence<LinkContact_, 64>", "links")), measurement.end());
  EXPECT_NE(std::find(measurement.begin(), measurement.end(), Field("sequence<uint8>", "seen_free")), measurement.end());
  EXPECT_EQ(idl_fields(idl, "LinkTruth_"),
            (std::vector<Field>{{"int32", "link"}, {"float", "distance_m"}, {"float", "speed_towards_mps"}}));
}

TEST(VerdictMessage, ThePackageBuildsTheMessageWithRosidl) {
  const std::string source = HRCSENSE_SOURCE_DIR;
  const std::string cmake = read_text(source + "/ros2/hrcsense_msgs/CMakeLists.txt");
  EXPECT_NE(cmake.find("rosidl_generate_interfaces"), std::string::npos);
  for (const char* msg : {"\"msg/Verdict.msg\"", "\"msg/Measurement.msg\"", "\"msg/LinkContact.msg\"", "\"msg/LinkTruth.msg\""}) {
    EXPECT_NE(cmake.find(msg), std::string::npos) << msg;
  }
  const std::string package = read_text(source + "/ros2/hrcsense_msgs/package.xml");
  EXPECT_NE(package.find("<name>hrcsense_msgs</name>"), std::string::npos);
  EXPECT_NE(package.find("<member_of_group>rosidl_interface_packages</member_of_group>"), std::string::npos);
}

}  // namespace
