// SPDX-License-Identifier: Apache-2.0
// ros2/hrcsense_msgs/msg/Verdict.msg (what a ROS 2 workspace builds) and dds/idl/hrcsense_msgs.idl
// (what hrcsense writes on the wire) must list the same fields, in the same order, of the same
// types: the wire is positional, so a field out of place there would be read as another one.
// The ROS → IDL type names are the spec's table (../shared/specs/ros2-interop.md, "Wire format").
#include <gtest/gtest.h>

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
      {"std_msgs/Header", "std_msgs::msg::dds_::Header_"}};
  std::vector<Field> fields;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string type, name;
    if (!(words >> type >> name)) continue;
    if (name.find('=') != std::string::npos) continue;
    const auto idl = idl_of.find(type);
    EXPECT_NE(idl, idl_of.end()) << "Verdict.msg: no IDL type known for " << type;
    fields.emplace_back(idl == idl_of.end() ? type : idl->second, name);
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
    std::istringstream words(member);
    std::string type, field;
    if (words >> type >> field) fields.emplace_back(type, field);
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

TEST(VerdictMessage, ThePackageBuildsTheMessageWithRosidl) {
  const std::string source = HRCSENSE_SOURCE_DIR;
  const std::string cmake = read_text(source + "/ros2/hrcsense_msgs/CMakeLists.txt");
  EXPECT_NE(cmake.find("rosidl_generate_interfaces"), std::string::npos);
  EXPECT_NE(cmake.find("\"msg/Verdict.msg\""), std::string::npos);
  const std::string package = read_text(source + "/ros2/hrcsense_msgs/package.xml");
  EXPECT_NE(package.find("<name>hrcsense_msgs</name>"), std::string::npos);
  EXPECT_NE(package.find("<member_of_group>rosidl_interface_packages</member_of_group>"), std::string::npos);
}

}  // namespace
