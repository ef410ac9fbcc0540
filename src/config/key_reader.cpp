// SPDX-License-Identifier: Apache-2.0
// hrcsense config internals — typed key reading, dotted paths and number formatting.
#include "key_reader.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>

namespace hrcsense::config_detail {
namespace {

std::vector<std::string> split_key(const std::string& key) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) return parts;
    start = dot + 1;
  }
}

// What the user wrote, for "got ..." in messages; sequences and maps are summarised.
std::string describe(const YAML::Node& node) {
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a map";
  return "nothing";
}

// "a number > 0", "a number in [0, 60]", ...; `float_range` adds a float's limit when there is
// no smaller maximum.
std::string bound_text(Bound bound, double max, bool float_range) {
  const bool has_max = max < (float_range ? static_cast<double>(std::numeric_limits<float>::max())
                                          : std::numeric_limits<double>::max());
  const std::string limit = has_max ? double_text(max) : std::string();
  switch (bound) {
    case Bound::non_negative:
      if (has_max) return "a number >= 0 and <= " + limit;
      return float_range ? "a number >= 0 within a float's range (<= 3.4e38)" : "a number >= 0";
    case Bound::positive:
      if (has_max) return "a number > 0 and <= " + limit;
      return float_range ? "a number > 0 within a float's range (<= 3.4e38)" : "a number > 0";
    case Bound::any: break;
  }
  if (has_max) return "a number <= " + limit;
  return float_range ? "a number within a float's range (|x| <= 3.4e38)" : "a finite number";
}

bool within(double value, Bound bound, double max) {
  return !(bound == Bound::non_negative && value < 0.0) && !(bound == Bound::positive && value <= 0.0) &&
         value <= max;
}

}  // namespace

std::string leading_zero_problem(const std::string& scalar) {
  const size_t sign = !scalar.empty() && (scalar[0] == '-' || scalar[0] == '+') ? 1 : 0;
  size_t end = sign;
  while (end < scalar.size() && scalar[end] >= '0' && scalar[end] <= '9') ++end;
  const std::string digits = scalar.substr(sign, end - sign);
  const bool rest_is_exponent = end == scalar.size() || scalar[end] == 'e' || scalar[end] == 'E';
  if (digits.size() < 2 || digits[0] != '0' || !rest_is_exponent) return {};
  const size_t first = digits.find_first_not_of('0');
  const std::string decimal =
      scalar.substr(0, sign) + (first == std::string::npos ? "0" : digits.substr(first)) + scalar.substr(end);
  std::string octal;
  if (end == scalar.size() && digits.find_first_of("89") == std::string::npos) {
    octal = ", or " + scalar.substr(0, sign) + std::to_string(std::strtoll(digits.c_str(), nullptr, 8)) +
            " if the octal value was meant";
  }
  return "'" + scalar + "' has a leading zero, which YAML 1.1 reads as octal and YAML 1.2 as decimal; write " +
         decimal + octal;
}

bool fits_float(double value) {
  return std::isfinite(value) && std::fabs(value) <= static_cast<double>(std::numeric_limits<float>::max());
}

void fail(const std::string& where, const std::string& key, const std::string& what) {
  throw ConfigError(where + ": key '" + key + "': " + what);
}

YAML::Node find_path(const YAML::Node& root, const std::string& key) {
  YAML::Node current = root;
  for (const std::string& part : split_key(key)) {
    if (!current.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& const_current = current;  // const access never inserts
    YAML::Node child = const_current[part];
    if (!child.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    current.reset(child);
  }
  return current;
}

bool set_path(YAML::Node& root, const std::string& key, const YAML::Node& value) {
  const std::vector<std::string> parts = split_key(key);
  for (const std::string& part : parts) {
    if (part.empty()) return false;
  }
  if (!root.IsMap()) root = YAML::Node(YAML::NodeType::Map);
  YAML::Node current = root;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node child = current[parts[i]];
    if (!child.IsMap()) {
      current[parts[i]] = YAML::Node(YAML::NodeType::Map);
      child.reset(current[parts[i]]);
    }
    current.reset(child);  // reset, not assignment: assignment would overwrite the node
  }
  current[parts.back()] = value;
  return true;
}

std::string float_text(float value) {
  char buffer[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, static_cast<double>(value));
    if (std::strtof(buffer, nullptr) == value) break;
  }
  return buffer;
}

std::string double_text(double value) {
  char buffer[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  return buffer;
}

KeyReader::KeyReader(YAML::Node root, std::string where)
    : root_(std::move(root)), effective_(YAML::NodeType::Map), where_(std::move(where)) {}

void KeyReader::fail(const std::string& key, const std::string& what) const {
  config_detail::fail(where_, key, what);
}

void KeyReader::fail_pair(const std::string& key_a, const std::string& key_b, const std::string& what) const {
  throw ConfigError(where_ + ": keys '" + key_a + "' and '" + key_b + "': " + what);
}

YAML::Node KeyReader::lookup(const std::string& key) {
  known_.insert(key);
  YAML::Node node = find_path(root_, key);
  // An explicit null ("key:" with no value) means "use the default".
  if (node.IsDefined() && node.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
  return node;
}

void KeyReader::set_effective(const std::string& key, const YAML::Node& value) {
  set_path(effective_, key, value);
}

YAML::Node KeyReader::raw(const std::string& key) { return lookup(key); }

double KeyReader::scalar_number(const std::string& key, const YAML::Node& node) const {
  const std::string zero = node.IsScalar() ? leading_zero_problem(node.Scalar()) : std::string();
  if (!zero.empty()) fail(key, zero);
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    fail(key, "expected a number, got " + describe(node));
  }
  return value;
}

float KeyReader::scalar_float(const std::string& key, const YAML::Node& node, float max_abs) const {
  const double value = scalar_number(key, node);
  if (!fits_float(value) || std::fabs(value) > static_cast<double>(max_abs)) {
    const bool limited = max_abs < std::numeric_limits<float>::max();
    fail(key, "expected numbers " +
                  (limited ? "in [-" + float_text(max_abs) + ", " + float_text(max_abs) + "]"
                           : std::string("within a float's range (|x| <= 3.4e38)")) +
                  ", got " + describe(node));
  }
  return static_cast<float>(value);
}

void KeyReader::text(const std::string& key, std::string& value) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    if (!node.IsScalar()) fail(key, "expected a string, got " + describe(node));
    value = node.Scalar();
  }
  set_effective(key, YAML::Node(value));
}

void KeyReader::choice(const std::string& key, std::string& value,
                       const std::vector<std::string>& allowed) {
  text(key, value);
  for (const std::string& option : allowed) {
    if (value == option) return;
  }
  std::string list;
  for (const std::string& option : allowed) list += (list.empty() ? "" : ", ") + option;
  fail(key, "expected one of " + list + ", got '" + value + "'");
}

void KeyReader::flag(const std::string& key, bool& value) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined() && (!node.IsScalar() || !YAML::convert<bool>::decode(node, value))) {
    fail(key, "expected true or false, got " + describe(node));
  }
  set_effective(key, YAML::Node(value));
}

void KeyReader::integer(const std::string& key, int64_t& value, int64_t min, int64_t max) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    const std::string zero = node.IsScalar() ? leading_zero_problem(node.Scalar()) : std::string();
    if (!zero.empty()) fail(key, zero);
    const std::string expected =
        "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
    int64_t read = 0;
    if (!node.IsScalar() || !YAML::convert<int64_t>::decode(node, read) || read < min || read > max) {
      fail(key, "expected " + expected + ", got " + describe(node));
    }
    value = read;
  }
  set_effective(key, YAML::Node(value));
}

void KeyReader::integer(const std::string& key, int& value, int min, int max) {
  int64_t wide = value;
  integer(key, wide, min, max);
  value = static_cast<int>(wide);
}

void KeyReader::integer(const std::string& key, uint64_t& value) {
  // Read as signed so that "-1" is an error rather than a wrapped-around huge seed.
  int64_t wide = static_cast<int64_t>(value);
  integer(key, wide, 0, std::numeric_limits<int64_t>::max());
  value = static_cast<uint64_t>(wide);
}

void KeyReader::number(const std::string& key, double& value, Bound bound, double max) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    const double read = scalar_number(key, node);
    if (!within(read, bound, max)) fail(key, "expected " + bound_text(bound, max, false) + ", got " + describe(node));
    value = read;
  }
  set_effective(key, YAML::Node(double_text(value)));
}

void KeyReader::number(const std::string& key, float& value, Bound bound, float max) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    const double read = scalar_number(key, node);
    // Checked again as the float it becomes: 1e-46 > 0, but it becomes the float 0.
    const float narrow = fits_float(read) ? static_cast<float>(read) : 0.0F;
    if (!fits_float(read) || !within(static_cast<double>(narrow), bound, static_cast<double>(max))) {
      fail(key, "expected " + bound_text(bound, static_cast<double>(max), true) + ", got " + describe(node));
    }
    value = narrow;
  }
  set_effective(key, YAML::Node(float_text(value)));
}

void KeyReader::number_in(const std::string& key, double& value, double min, double max, const std::string& unit) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    const double read = scalar_number(key, node);
    if (!(read >= min && read <= max)) {
      fail(key, "expected a number in [" + double_text(min) + ", " + double_text(max) + "]" + unit + ", got " +
                    describe(node));
    }
    value = read;
  }
  set_effective(key, YAML::Node(double_text(value)));
}

void KeyReader::vec3(const std::string& key, Eigen::Vector3f& value, float max_abs) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    if (!node.IsSequence() || node.size() != 3) {
      fail(key, "expected a list of 3 numbers [x, y, z], got " + describe(node));
    }
    for (size_t i = 0; i < 3; ++i) value[static_cast<int>(i)] = scalar_float(key, node[i], max_abs);
  }
  YAML::Node out(YAML::NodeType::Sequence);
  out.SetStyle(YAML::EmitterStyle::Flow);
  for (int i = 0; i < 3; ++i) out.push_back(float_text(value[i]));
  set_effective(key, out);
}

void KeyReader::vec3_list(const std::string& key, std::vector<Eigen::Vector3f>& value, float max_abs) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    if (!node.IsSequence()) fail(key, "expected a list of [x, y, z] lists, got " + describe(node));
    value.clear();
    for (const YAML::Node& item : node) {
      if (!item.IsSequence() || item.size() != 3) {
        fail(key, "expected a list of [x, y, z] lists, got an item that is " + describe(item));
      }
      value.emplace_back(scalar_float(key, item[0], max_abs), scalar_float(key, item[1], max_abs),
                         scalar_float(key, item[2], max_abs));
    }
  }
  YAML::Node out(YAML::NodeType::Sequence);
  for (const Eigen::Vector3f& v : value) {
    YAML::Node point(YAML::NodeType::Sequence);
    point.SetStyle(YAML::EmitterStyle::Flow);
    for (int i = 0; i < 3; ++i) point.push_back(float_text(v[i]));
    out.push_back(point);
  }
  set_effective(key, out);
}

void KeyReader::number_list(const std::string& key, std::vector<double>& value, size_t size) {
  const YAML::Node node = lookup(key);
  if (node.IsDefined()) {
    const std::string expected =
        size > 0 ? "a list of " + std::to_string(size) + " numbers" : std::string("a list of numbers");
    if (!node.IsSequence() || (size > 0 && node.size() != 0 && node.size() != size)) {
      fail(key, "expected " + expected + ", got " +
                    (node.IsSequence() ? std::to_string(node.size()) + " numbers" : describe(node)));
    }
    value.clear();
    for (const YAML::Node& item : node) value.push_back(scalar_number(key, item));
  }
  YAML::Node out(YAML::NodeType::Sequence);
  out.SetStyle(YAML::EmitterStyle::Flow);
  for (double v : value) out.push_back(double_text(v));
  set_effective(key, out);
}

}  // namespace hrcsense::config_detail
