// SPDX-License-Identifier: Apache-2.0
// Tests of what intrinsics files may hold: numbers that overflow a float, subnormal or absurd
// focal lengths, principal points far off the image, non-finite coefficients, duplicate keys;
// in hrcsense's own form and in the datasets' form. Each error names the file and the field.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "hrcsense/io/io.hpp"

namespace hrcsense {
namespace {

const char* kGood = R"({"width":640,"height":480,"fx":390.4315,"fy":390.4315,"ppx":331.3879,"ppy":242.1873,)"
                    R"("model":"Brown Conrady","coeffs":[0,0,0,0,0]})";
const char* kDataset = R"({"width": 640, "height": 480, "depth_units_m": 0.001,)"
                       R"( "depth_K": [[567.9, 0, 312.1], [0, 568.9, 242.6], [0, 0, 1]]})";

/// The IoError message of reading `text` in hrcsense's form, "" when it reads.
std::string own_error(const std::string& text) {
  try {
    (void)intrinsics_from_json(text, "cell.json");
  } catch (const IoError& e) {
    return e.what();
  }
  return {};
}

std::string dataset_error(const std::string& text) {
  try {
    (void)folder_calibration_from_json(text, "people/intrinsics.json");
  } catch (const IoError& e) {
    return e.what();
  }
  return {};
}

/// kGood with field `name` set to the JSON number written as `number` (the text is spliced in
/// so that values beyond a float, such as 1e39, reach the reader as written).
std::string own_with(const std::string& name, const std::string& number) {
  nlohmann::json doc = nlohmann::json::parse(kGood);
  doc[name] = "@";
  std::string text = doc.dump();
  text.replace(text.find("\"@\""), 3, number);
  return text;
}

void expect_mentions(const std::string& message, const std::string& a, const std::string& b) {
  EXPECT_NE(message.find(a), std::string::npos) << "'" << a << "' not in: " << message;
  EXPECT_NE(message.find(b), std::string::npos) << "'" << b << "' not in: " << message;
}

TEST(IntrinsicsChecks, OwnFormRefusesValuesThatAreNotUsableFloats) {
  EXPECT_EQ(own_error(kGood), "");
  // 1e39 is a finite double but an infinite float; 1e-39 is a subnormal float (fx > 0 held).
  for (const char* value : {"1e39", "-1e39", "1e-39", "0", "-1", "0.5", "1", "100000", "3e38"}) {
    expect_mentions(own_error(own_with("fx", value)), "cell.json", "'fx'");
    expect_mentions(own_error(own_with("fy", value)), "cell.json", "'fy'");
  }
  EXPECT_EQ(own_error(own_with("fx", "1.5")), "");     // just above the lower bound
  EXPECT_EQ(own_error(own_with("fy", "99999")), "");   // just below the upper one
  // Principal point within [-width, 2·width] = [-640, 1280] and [-480, 960].
  EXPECT_EQ(own_error(own_with("ppx", "-640")), "");
  EXPECT_EQ(own_error(own_with("ppx", "1280")), "");
  for (const char* value : {"-640.5", "1280.5", "1e39", "1e30"}) {
    expect_mentions(own_error(own_with("ppx", value)), "cell.json", "'ppx'");
  }
  expect_mentions(own_error(own_with("ppy", "961")), "cell.json", "'ppy'");
  expect_mentions(own_error(own_with("width", "20000")), "cell.json", "'width'");
  std::string coeffs = kGood;
  coeffs.replace(coeffs.find("[0,0,0,0,0]"), 11, "[0,0,1e39,0,0]");
  expect_mentions(own_error(coeffs), "cell.json", "'coeffs[2]'");
}

TEST(IntrinsicsChecks, DatasetFormNamesTheMatrixEntry) {
  EXPECT_EQ(dataset_error(kDataset), "");
  const auto with_k = [](const std::string& entry, const std::string& value) {
    std::string text = kDataset;
    text.replace(text.find(entry), entry.size(), value);
    return dataset_error(text);
  };
  expect_mentions(with_k("567.9", "1e39"), "people/intrinsics.json", "depth_K[0][0]");
  expect_mentions(with_k("567.9", "1e-39"), "people/intrinsics.json", "depth_K[0][0]");
  expect_mentions(with_k("568.9", "1e-39"), "people/intrinsics.json", "depth_K[1][1]");
  expect_mentions(with_k("312.1", "1e39"), "people/intrinsics.json", "depth_K[0][2]");
  expect_mentions(with_k("242.6", "-1000"), "people/intrinsics.json", "depth_K[1][2]");
  expect_mentions(with_k("0.001", "1e-39"), "people/intrinsics.json", "depth_units_m");
  expect_mentions(with_k("0.001", "2"), "people/intrinsics.json", "depth_units_m");
  std::string rgb = kDataset;
  rgb.insert(rgb.size() - 1, R"(, "rgb_K": [[1e-39, 0, 1], [0, 500, 1], [0, 0, 1]])");
  expect_mentions(dataset_error(rgb), "people/intrinsics.json", "rgb_K[0][0]");
}

TEST(IntrinsicsChecks, DatasetFormShiftsOneBasedCentresAndKeepsColour) {
  const FolderCalibration c = folder_calibration_from_json(
      R"json({"width": 4, "height": 3, "pixel_convention": "1-based (MATLAB)", "depth_K": [[500, 0, 2.5], [0, 501, 2], [0, 0, 1]],)json"
      R"( "rgb_K": [[400, 0, 16.5], [0, 401, 12.5], [0, 0, 1]], "depth_to_rgb_R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],)"
      R"( "depth_to_rgb_T_m": [-0.025, 0, 0]})",
      "f.json");
  EXPECT_EQ(c.depth.ppx, 1.5F);
  EXPECT_EQ(c.depth.ppy, 1.0F);
  EXPECT_EQ(c.depth_units_m, 0.0F);  // not given: the layout's default applies
  EXPECT_EQ(c.color.fx, 400.0F);
  EXPECT_EQ(c.color.ppx, 15.5F);
  ASSERT_TRUE(c.depth_to_color.has_value());
  EXPECT_EQ(c.depth_to_color->translation_m[0], -0.025F);
}

TEST(IntrinsicsChecks, DuplicateKeysAreErrorsNamingFileAndKey) {
  // nlohmann keeps the last of two equal keys: a hand-edited "fx" appended would silently win.
  std::string own = kGood;
  own.insert(own.size() - 1, R"(,"fx":1000)");
  EXPECT_EQ(own_error(own), "cell.json: duplicate key 'fx' (a JSON reader would keep only one of them)");
  std::string dataset = kDataset;
  dataset.insert(dataset.size() - 1, R"(, "depth_units_m": 0.0001)");
  expect_mentions(dataset_error(dataset), "people/intrinsics.json", "duplicate key 'depth_units_m'");
  // Inside a nested object the path names the object.
  const std::string nested = R"({"width": 4, "height": 3, "depth_K": [[500, 0, 2], [0, 500, 1], [0, 0, 1]],)"
                             R"( "extra": {"a": 1, "a": 2}})";
  expect_mentions(dataset_error(nested), "people/intrinsics.json", "duplicate key 'extra.a'");
  // The same key in two different objects is no duplicate.
  EXPECT_NO_THROW(check_unique_json_keys(R"({"a": {"x": 1}, "b": {"x": 2}, "c": [{"x": 1}, {"x": 2}]})", "t"));
}

}  // namespace
}  // namespace hrcsense
