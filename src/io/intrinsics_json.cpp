// SPDX-License-Identifier: Apache-2.0
// hrcsense — intrinsics as JSON, with the distortion model spelled as the SDK's name string, and
// the folders' intrinsics.json in the datasets' form. Every number is checked after conversion
// to the float it is used as: a value that overflows, or a focal length that is subnormal, would
// put every point at infinity, where the proximity search skips it and the frame says "run".

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "hrcsense/camera.hpp"
#include "io_fail.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/number_text.hpp"

namespace hrcsense {
namespace {

using Json = nlohmann::json;

/// Largest image side a file may declare (the bag reader's limit too).
constexpr int kMaxSide = 16384;
/// Focal lengths are in (kMinFocalPx, kMaxFocalPx) pixels.
constexpr float kMinFocalPx = 1.0F;
constexpr float kMaxFocalPx = 1e5F;

/// The double nearest to the shortest decimal that reads back as `value`, so that 418.265F
/// is written as 418.265 rather than 418.2650146484375, and still reads back bit-exactly.
double shortest_decimal(float value) {
  if (!std::isfinite(value)) {
    return static_cast<double>(value);  // nlohmann writes null; reading it back then fails loudly
  }
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text) - 1, value);
  *result.ptr = '\0';
  return std::strtod(text, nullptr);
}

using io_detail::fail;

const Json& field(const Json& root, const char* name, const std::string& what) {
  const auto it = root.find(name);
  if (it == root.end()) {
    fail(what, std::string("missing field '") + name + "'");
  }
  return *it;
}

int positive_int_field(const Json& root, const char* name, const std::string& what) {
  const Json& value = field(root, name, what);
  if (!value.is_number_integer() || value.get<int64_t>() <= 0 || value.get<int64_t>() > kMaxSide) {
    fail(what, std::string("field '") + name + "' must be an integer in [1, " + std::to_string(kMaxSide) +
                   "] (pixels), found " + value.dump());
  }
  return value.get<int>();
}

/// A JSON number as the float it is used as. The range is checked on the double, before the
/// cast: converting a double beyond FLT_MAX to float is undefined (in practice inf).
float float_value(const Json& value, const std::string& name, const std::string& what) {
  const double wide = value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN();
  if (!std::isfinite(wide) || std::fabs(wide) > static_cast<double>(std::numeric_limits<float>::max())) {
    fail(what, "field '" + name + "' must be a finite number within a float's range (|x| <= 3.4e38), found " +
                   value.dump());
  }
  return static_cast<float>(wide);
}

std::string focal_problem(float f, const char* name) {
  if (std::isnormal(f) && f > kMinFocalPx && f < kMaxFocalPx) return {};
  return std::string("field '") + name + "' (focal length) must be a normal number in (1, 100000) px, found " +
         float_digits_text(f);
}

std::string principal_problem(float p, int size, const char* name) {
  if (std::isfinite(p) && p >= -static_cast<float>(size) && p <= 2.0F * static_cast<float>(size)) return {};
  return std::string("field '") + name + "' (principal point) must be in [-" + std::to_string(size) + ", " +
         std::to_string(2 * size) + "] px for an image " + std::to_string(size) + " px across, found " +
         float_digits_text(p);
}

/// A 3x3 matrix given as rows, or an error naming the field.
void check_3x3(const Json& m, const std::string& name, const std::string& what) {
  bool ok = m.is_array() && m.size() == 3;
  for (size_t i = 0; ok && i < 3; ++i) ok = m[i].is_array() && m[i].size() == 3;
  if (!ok) fail(what, "field '" + name + "' must be a 3x3 matrix (3 rows of 3 numbers)");
}

float matrix_entry(const Json& m, const std::string& name, size_t i, size_t j, const std::string& what) {
  return float_value(m[i][j], name + "[" + std::to_string(i) + "][" + std::to_string(j) + "]", what);
}

/// The colour camera of the datasets' form (`rgb_K`, `depth_to_rgb_R`, `depth_to_rgb_T_m`),
/// where the file has it; the colour image size comes from the images.
void read_color_calibration(const Json& doc, bool one_based, const std::string& what, FolderCalibration& out) {
  if (doc.contains("rgb_K")) {
    const Json& k = doc.at("rgb_K");
    check_3x3(k, "rgb_K", what);
    const float shift = one_based ? 1.0F : 0.0F;
    out.color.fx = matrix_entry(k, "rgb_K", 0, 0, what);
    out.color.ppx = matrix_entry(k, "rgb_K", 0, 2, what) - shift;
    out.color.fy = matrix_entry(k, "rgb_K", 1, 1, what);
    out.color.ppy = matrix_entry(k, "rgb_K", 1, 2, what) - shift;
    for (const std::string& problem : {focal_problem(out.color.fx, "rgb_K[0][0]"), focal_problem(out.color.fy, "rgb_K[1][1]")}) {
      if (!problem.empty()) fail(what, problem);
    }
  }
  if (doc.contains("depth_to_rgb_R") && doc.contains("depth_to_rgb_T_m")) {
    const Json& r = doc.at("depth_to_rgb_R");
    const Json& t = doc.at("depth_to_rgb_T_m");
    check_3x3(r, "depth_to_rgb_R", what);
    if (!t.is_array() || t.size() != 3) fail(what, "field 'depth_to_rgb_T_m' must be 3 numbers");
    Extrinsics e;
    for (size_t i = 0; i < 3; ++i) {
      e.translation_m[i] = float_value(t[i], "depth_to_rgb_T_m[" + std::to_string(i) + "]", what);
      // P_rgb = R·P_depth + T; the SDK's layout is column-major.
      for (size_t j = 0; j < 3; ++j) e.rotation[3 * j + i] = matrix_entry(r, "depth_to_rgb_R", i, j, what);
    }
    out.depth_to_color = e;
  }
}

/// The datasets' form: {"width", "height", "depth_K", "depth_units_m", "pixel_convention", ...}.
FolderCalibration dataset_calibration(const Json& doc, const std::string& what) {
  FolderCalibration out;
  Intrinsics& in = out.depth;
  in.width = positive_int_field(doc, "width", what);
  in.height = positive_int_field(doc, "height", what);
  const Json& k = doc.at("depth_K");
  check_3x3(k, "depth_K", what);
  in.fx = matrix_entry(k, "depth_K", 0, 0, what);
  in.ppx = matrix_entry(k, "depth_K", 0, 2, what);
  in.fy = matrix_entry(k, "depth_K", 1, 1, what);
  in.ppy = matrix_entry(k, "depth_K", 1, 2, what);
  // MATLAB calibrations put the first pixel's centre at 1; hrcsense (like the SDK) at 0.
  const bool one_based = doc.value("pixel_convention", std::string("0-based")).rfind("1-based", 0) == 0;
  if (one_based) {
    in.ppx -= 1.0F;
    in.ppy -= 1.0F;
  }
  const std::string problem =
      intrinsics_problem(in, IntrinsicsFieldNames{"depth_K[0][0]", "depth_K[1][1]", "depth_K[0][2]", "depth_K[1][2]", "coeffs"});
  if (!problem.empty()) fail(what, problem);
  if (doc.contains("depth_units_m")) {
    out.depth_units_m = float_value(doc.at("depth_units_m"), "depth_units_m", what);
    // The SDK's depth-units option spans 1e-6 .. 0.01 m; more than a metre per unit is no depth camera.
    if (!(out.depth_units_m >= 1e-6F && out.depth_units_m <= 1.0F)) {
      fail(what, "field 'depth_units_m' must be in [1e-6, 1] m, found " + doc.at("depth_units_m").dump());
    }
  }
  read_color_calibration(doc, one_based, what, out);
  return out;
}

Json parse_object(const std::string& json_text, const std::string& what) {
  Json root;
  try {
    root = Json::parse(json_text);
  } catch (const Json::parse_error& e) {
    fail(what, std::string("invalid JSON: ") + e.what());
  } catch (const Json::exception& e) {
    fail(what, std::string("invalid JSON: ") + e.what());  // e.g. a number overflowing a double
  }
  check_unique_json_keys(json_text, what);
  if (!root.is_object()) {
    fail(what, "intrinsics must be a JSON object, found " + std::string(root.type_name()));
  }
  return root;
}

}  // namespace

std::string intrinsics_problem(const Intrinsics& in, const IntrinsicsFieldNames& names) {
  if (in.width < 1 || in.width > kMaxSide || in.height < 1 || in.height > kMaxSide) {
    return "width and height must be in [1, " + std::to_string(kMaxSide) + "] px, found " + std::to_string(in.width) +
           "x" + std::to_string(in.height);
  }
  for (const std::string& problem : {focal_problem(in.fx, names.fx), focal_problem(in.fy, names.fy),
                                     principal_problem(in.ppx, in.width, names.ppx),
                                     principal_problem(in.ppy, in.height, names.ppy)}) {
    if (!problem.empty()) return problem;
  }
  for (size_t i = 0; i < in.coeffs.size(); ++i) {
    if (!std::isfinite(in.coeffs[i])) {
      return std::string("field '") + names.coeffs + "[" + std::to_string(i) + "]' must be finite, found " +
             float_digits_text(in.coeffs[i]);
    }
  }
  return {};
}

void check_unique_json_keys(const std::string& json_text, const std::string& what) {
  // One set of keys per open object, with the key that led into it, for the path in the message.
  struct Level {
    std::set<std::string> keys;
    std::string path;
    std::string last_key;
  };
  std::vector<Level> levels;
  const Json::parser_callback_t callback = [&](int /*depth*/, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start: {
        std::string path;
        if (!levels.empty()) path = levels.back().path.empty() ? levels.back().last_key : levels.back().path + "." + levels.back().last_key;
        levels.push_back(Level{{}, path, {}});
        break;
      }
      case Json::parse_event_t::object_end:
        if (!levels.empty()) levels.pop_back();
        break;
      case Json::parse_event_t::key: {
        Level& level = levels.back();
        level.last_key = parsed.get<std::string>();
        if (!level.keys.insert(level.last_key).second) {
          fail(what, "duplicate key '" + (level.path.empty() ? level.last_key : level.path + "." + level.last_key) +
                         "' (a JSON reader would keep only one of them)");
        }
        break;
      }
      default:
        break;
    }
    return true;
  };
  try {
    const Json parsed = Json::parse(json_text, callback);
    (void)parsed;
  } catch (const Json::exception&) {
    // Not JSON: the caller's own parse reports it.
  }
}

std::string intrinsics_to_json(const Intrinsics& intrinsics) {
  nlohmann::ordered_json json;
  json["width"] = intrinsics.width;
  json["height"] = intrinsics.height;
  json["fx"] = shortest_decimal(intrinsics.fx);
  json["fy"] = shortest_decimal(intrinsics.fy);
  json["ppx"] = shortest_decimal(intrinsics.ppx);
  json["ppy"] = shortest_decimal(intrinsics.ppy);
  json["model"] = std::string(distortion_name(intrinsics.model));
  nlohmann::ordered_json coeffs = nlohmann::ordered_json::array();
  for (const float c : intrinsics.coeffs) {
    coeffs.push_back(shortest_decimal(c));
  }
  json["coeffs"] = coeffs;
  return json.dump();
}

Intrinsics intrinsics_from_json(const std::string& json_text, const std::string& what) {
  const Json root = parse_object(json_text, what);
  Intrinsics in;
  in.width = positive_int_field(root, "width", what);
  in.height = positive_int_field(root, "height", what);
  in.fx = float_value(field(root, "fx", what), "fx", what);
  in.fy = float_value(field(root, "fy", what), "fy", what);
  in.ppx = float_value(field(root, "ppx", what), "ppx", what);
  in.ppy = float_value(field(root, "ppy", what), "ppy", what);

  const Json& model = field(root, "model", what);
  const auto parsed_model = model.is_string() ? distortion_from_name(model.get<std::string>()) : std::nullopt;
  if (!parsed_model) {
    fail(what,
         "field 'model' must be one of \"None\", \"Modified Brown Conrady\", \"Inverse Brown Conrady\", "
         "\"Ftheta\", \"Brown Conrady\", \"Kannala Brandt4\"; found " +
             model.dump());
  }
  in.model = *parsed_model;

  const Json& coeffs = field(root, "coeffs", what);
  if (!coeffs.is_array() || coeffs.size() != in.coeffs.size()) {
    fail(what, "field 'coeffs' must be an array of 5 numbers, found " + coeffs.dump());
  }
  for (size_t i = 0; i < in.coeffs.size(); ++i) {
    in.coeffs[i] = float_value(coeffs[i], "coeffs[" + std::to_string(i) + "]", what);
  }
  const std::string problem = intrinsics_problem(in);
  if (!problem.empty()) fail(what, problem);
  return in;
}

FolderCalibration folder_calibration_from_json(const std::string& json_text, const std::string& what) {
  const Json doc = parse_object(json_text, what);
  if (!doc.contains("depth_K")) {
    FolderCalibration out;
    out.depth = intrinsics_from_json(json_text, what);
    return out;
  }
  try {
    return dataset_calibration(doc, what);
  } catch (const Json::exception& e) {
    fail(what, e.what());  // e.g. pixel_convention that is not a string
  }
}

}  // namespace hrcsense
