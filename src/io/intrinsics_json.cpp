// SPDX-License-Identifier: Apache-2.0
// hrcsense — intrinsics as JSON, with the distortion model spelled as the SDK's name string.

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "hrcsense/camera.hpp"
#include "hrcsense/io.hpp"

namespace hrcsense {
namespace {

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

[[noreturn]] void fail(const std::string& what, const std::string& problem) {
  throw IoError(what + ": " + problem);
}

const nlohmann::json& field(const nlohmann::json& root, const char* name, const std::string& what) {
  const auto it = root.find(name);
  if (it == root.end()) {
    fail(what, std::string("missing field '") + name + "'");
  }
  return *it;
}

int positive_int_field(const nlohmann::json& root, const char* name, const std::string& what) {
  const nlohmann::json& value = field(root, name, what);
  if (!value.is_number_integer() || value.get<int64_t>() <= 0 || value.get<int64_t>() > 1'000'000) {
    fail(what,
         std::string("field '") + name + "' must be a positive integer (pixels), found " + value.dump());
  }
  return value.get<int>();
}

float float_field(const nlohmann::json& root, const char* name, const std::string& what, bool positive) {
  const nlohmann::json& value = field(root, name, what);
  if (!value.is_number()) {
    fail(what, std::string("field '") + name + "' must be a number, found " + value.dump());
  }
  const auto number = static_cast<float>(value.get<double>());
  if (!std::isfinite(number) || (positive && !(number > 0.0F))) {
    fail(what, std::string("field '") + name + "' must be a finite" + (positive ? " positive" : "") +
                   " number, found " + value.dump());
  }
  return number;
}

}  // namespace

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
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::parse_error& e) {
    fail(what, std::string("invalid JSON: ") + e.what());
  }
  if (!root.is_object()) {
    fail(what, "intrinsics must be a JSON object, found " + std::string(root.type_name()));
  }
  Intrinsics in;
  in.width = positive_int_field(root, "width", what);
  in.height = positive_int_field(root, "height", what);
  in.fx = float_field(root, "fx", what, true);
  in.fy = float_field(root, "fy", what, true);
  in.ppx = float_field(root, "ppx", what, false);
  in.ppy = float_field(root, "ppy", what, false);

  const nlohmann::json& model = field(root, "model", what);
  const auto parsed_model = model.is_string() ? distortion_from_name(model.get<std::string>()) : std::nullopt;
  if (!parsed_model) {
    fail(what,
         "field 'model' must be one of \"None\", \"Modified Brown Conrady\", \"Inverse Brown Conrady\", "
         "\"Ftheta\", \"Brown Conrady\", \"Kannala Brandt4\"; found " +
             model.dump());
  }
  in.model = *parsed_model;

  const nlohmann::json& coeffs = field(root, "coeffs", what);
  if (!coeffs.is_array() || coeffs.size() != in.coeffs.size()) {
    fail(what, "field 'coeffs' must be an array of 5 numbers, found " + coeffs.dump());
  }
  for (size_t i = 0; i < in.coeffs.size(); ++i) {
    const auto value = coeffs[i].is_number() ? static_cast<float>(coeffs[i].get<double>())
                                             : std::numeric_limits<float>::quiet_NaN();
    if (!std::isfinite(value)) {
      fail(what,
           "field 'coeffs[" + std::to_string(i) + "]' must be a finite number, found " + coeffs[i].dump());
    }
    in.coeffs[i] = value;
  }
  return in;
}

}  // namespace hrcsense
