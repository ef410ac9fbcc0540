// SPDX-License-Identifier: Apache-2.0
// hrcsense — sweeps and the resumable result table of `hrcsense eval` (eval/sweep.hpp).

#include "hrcsense/eval/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace hrcsense::eval {
namespace {

constexpr size_t kMaxAxisValues = 10000;

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  size_t begin = 0;
  for (;;) {
    const size_t end = text.find(separator, begin);
    parts.push_back(text.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
    if (end == std::string::npos) return parts;
    begin = end + 1;
  }
}

// A decimal number as written in a range ("-0.25", "8"): its value and its count of decimals.
// Exponents, hex and the like are refused: the decimals decide how the values are written.
bool parse_decimal(const std::string& text, double& value, int& decimals) {
  if (text.empty() || text.find_first_not_of("+-.0123456789") != std::string::npos) return false;
  size_t used = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  if (used != text.size() || !std::isfinite(value)) return false;
  const size_t dot = text.find('.');
  decimals = dot == std::string::npos ? 0 : static_cast<int>(text.size() - dot - 1);
  return true;
}

// `value` with `decimals` decimals, trailing zeros (and a bare dot) dropped; never "-0".
std::string decimal_text(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  std::string text = buffer;
  if (text.find('.') != std::string::npos) {
    while (text.back() == '0') text.pop_back();
    if (text.back() == '.') text.pop_back();
  }
  if (text == "-0") text = "0";
  return text;
}

std::vector<std::string> range_values(const std::string& argument, const std::string& range) {
  const std::vector<std::string> parts = split(range, ':');
  const auto fail = [&](const std::string& why) { return std::invalid_argument("--sweep '" + argument + "': " + why); };
  if (parts.size() > 3) throw fail("expected A:B or A:B:STEP");
  double a = 0.0, b = 0.0, step = 1.0;
  int decimals_a = 0, decimals_b = 0, decimals_step = 0;
  if (!parse_decimal(parts[0], a, decimals_a) || !parse_decimal(parts[1], b, decimals_b) ||
      (parts.size() == 3 && !parse_decimal(parts[2], step, decimals_step))) {
    throw fail("expected decimal numbers in A:B[:STEP], e.g. 0.25:1:0.25");
  }
  if (!(step > 0.0)) throw fail("expected STEP > 0");
  if (!(a <= b)) throw fail("expected A <= B");
  // Half a millionth of a step of slack, so that 0.1:0.3:0.1 includes 0.3 despite rounding.
  const double steps = std::floor((b - a) / step + 1e-6);
  if (steps + 1.0 > static_cast<double>(kMaxAxisValues)) {
    throw fail("more than " + std::to_string(kMaxAxisValues) + " values");
  }
  const int decimals = std::max({decimals_a, decimals_b, decimals_step});
  std::vector<std::string> values;
  for (int64_t i = 0; i <= static_cast<int64_t>(steps); ++i) {
    values.push_back(decimal_text(a + static_cast<double>(i) * step, decimals));
  }
  return values;
}

}  // namespace

SweepAxis parse_sweep(const std::string& argument) {
  const size_t equals = argument.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw std::invalid_argument("--sweep '" + argument +
                                "': expected KEY=V1,V2,... or KEY=A:B[:STEP], e.g. filters.temporal.persistence=0:8");
  }
  SweepAxis axis;
  axis.key = argument.substr(0, equals);
  if (axis.key.find('.') == std::string::npos) {
    throw std::invalid_argument("--sweep '" + argument + "': '" + axis.key +
                                "' is no configuration key (keys have a section: safety.stop_distance_m)");
  }
  const std::string rest = argument.substr(equals + 1);
  if (rest.find(':') != std::string::npos) {
    axis.values = range_values(argument, rest);
    return axis;
  }
  axis.values = split(rest, ',');
  for (const std::string& value : axis.values) {
    if (value.empty()) throw std::invalid_argument("--sweep '" + argument + "': an empty value");
  }
  return axis;
}

std::vector<SweepPoint> sweep_grid(const std::vector<SweepAxis>& axes) {
  std::set<std::string> keys;
  size_t count = 1;
  for (const SweepAxis& axis : axes) {
    if (!keys.insert(axis.key).second) throw std::invalid_argument("--sweep: " + axis.key + " is swept twice");
    count *= axis.values.size();
  }
  std::vector<SweepPoint> points(count);
  for (size_t index = 0; index < count; ++index) {
    // Mixed-radix digits of the index, the last axis the fastest.
    size_t rest = index;
    std::vector<std::string> settings(axes.size());
    for (size_t a = axes.size(); a-- > 0;) {
      const size_t n = axes[a].values.size();
      settings[a] = axes[a].key + "=" + axes[a].values[rest % n];
      rest /= n;
    }
    points[index].index = static_cast<int64_t>(index);
    points[index].settings = std::move(settings);
  }
  return points;
}

std::string settings_text(const SweepPoint& point) {
  std::string text;
  for (const std::string& setting : point.settings) text += (text.empty() ? "" : ";") + setting;
  return text;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') {
      quoted += "\"\"";
    } else {
      quoted += c == '\n' || c == '\r' ? ' ' : c;  // a row stays one line: resume reads lines
    }
  }
  return quoted + "\"";
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c != '"') {
        fields.back() += c;
      } else if (i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else {
        quoted = false;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  if (quoted) throw std::invalid_argument("unterminated quote");
  return fields;
}

std::string row_key(const std::vector<std::string>& key_fields) {
  std::string key;
  for (const std::string& field : key_fields) key += csv_field(field) + ",";
  return key;
}

ResumeState resume_results(const std::string& path, const std::string& header, size_t key_columns) {
  ResumeState state;
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    std::ofstream out(path, std::ios::binary);
    out << header << '\n';
    if (!out.flush()) throw std::runtime_error(path + ": cannot write");
    return state;
  }
  std::ifstream in(path, std::ios::binary);
  std::stringstream whole;
  whole << in.rdbuf();
  const std::string text = whole.str();
  // Only lines that end in a line break are complete; a cut-off last one is dropped.
  const size_t complete = text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1;
  state.dropped_partial = complete < text.size();
  std::vector<std::string> lines = split(text.substr(0, complete), '\n');
  lines.pop_back();  // after the last line break
  if (lines.empty() || lines[0] != header) {
    throw std::runtime_error(path + ": not this sweep's table (its header differs); use another --out or remove it");
  }
  const size_t columns = split_csv_line(header).size();
  std::map<std::string, size_t> first_line;  // row key -> the line it first appeared on (1-based)
  for (size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> fields;
    try {
      fields = split_csv_line(lines[i]);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(path + ":" + std::to_string(i + 1) + ": " + e.what());
    }
    if (fields.size() != columns) {
      throw std::runtime_error(path + ":" + std::to_string(i + 1) + ": expected " + std::to_string(columns) +
                               " fields, got " + std::to_string(fields.size()));
    }
    fields.resize(key_columns);
    const std::string key = row_key(fields);
    const auto [at, fresh] = first_line.emplace(key, i + 1);
    if (!fresh) {
      // Two rows of one sweep point: a table merged from two runs, which no summary may average.
      throw std::runtime_error(path + ":" + std::to_string(i + 1) + ": the row " + key + " is there twice (also line " +
                               std::to_string(at->second) + "); use another --out or remove one");
    }
    state.done.insert(key);
  }
  state.existed = true;
  state.rows = static_cast<int64_t>(lines.size()) - 1;
  if (state.dropped_partial) std::filesystem::resize_file(path, complete);
  return state;
}

}  // namespace hrcsense::eval
