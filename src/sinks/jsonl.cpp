// SPDX-License-Identifier: Apache-2.0
// hrcsense sinks — JSON Lines: a header, one line per frame, a summary (docs/OUTPUT.md).
// Lines are composed by hand into a reused string so that writing a frame does not allocate.
#include "hrcsense/sinks.hpp"

#include "hrcsense/camera.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#ifndef HRCSENSE_VERSION
#define HRCSENSE_VERSION "unknown"
#endif
#ifndef HRCSENSE_COMMIT
#define HRCSENSE_COMMIT "unknown"
#endif

namespace hrcsense {
namespace {

void put_string(std::string& line, std::string_view text) {
  line += '"';
  for (char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      line += '\\';
      line += ch;
    } else if (byte < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", byte);
      line += escaped;
    } else {
      line += ch;
    }
  }
  line += '"';
}

void put_key(std::string& line, const char* key) {
  if (line.back() != '{') line += ',';
  put_string(line, key);
  line += ':';
}

// Shortest text that reads back as the same float: 9 significant digits at most, which
// keeps metres far below 0.1 mm. JSON has no NaN or infinity: those become null.
void put_float(std::string& line, float value) {
  if (!std::isfinite(value)) {
    line += "null";
    return;
  }
  char buffer[32];
  for (int digits = 6; digits <= 9; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, static_cast<double>(value));
    if (std::strtof(buffer, nullptr) == value) break;
  }
  line += buffer;
}

void put_double(std::string& line, double value) {
  if (!std::isfinite(value)) {
    line += "null";
    return;
  }
  char buffer[40];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  line += buffer;
}

void put_int(std::string& line, int64_t value) {
  char buffer[24];
  std::snprintf(buffer, sizeof buffer, "%lld", static_cast<long long>(value));
  line += buffer;
}

// Seconds from integer nanoseconds, exactly: "3.4" rather than 3.4000000000000004.
void put_seconds(std::string& line, int64_t timestamp_ns) {
  if (timestamp_ns < 0) {
    put_double(line, static_cast<double>(timestamp_ns) * 1e-9);
    return;
  }
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%lld.%09lld", static_cast<long long>(timestamp_ns / 1000000000),
                static_cast<long long>(timestamp_ns % 1000000000));
  std::string_view text(buffer);
  while (text.back() == '0' && text[text.size() - 2] != '.') text.remove_suffix(1);
  line += text;
}

void put_vec3(std::string& line, const Eigen::Vector3f& v) {
  line += '[';
  put_float(line, v.x());
  line += ',';
  put_float(line, v.y());
  line += ',';
  put_float(line, v.z());
  line += ']';
}

void put_truth(std::string& line, const Contact& truth) {
  line += '{';
  put_key(line, "distance_m");
  if (truth.valid) {
    put_float(line, truth.distance_m);
  } else {
    line += "null";
  }
  put_key(line, "closest_base");
  if (truth.valid) {
    put_vec3(line, truth.closest_base);
  } else {
    line += "null";
  }
  line += '}';
}

// The filters as they run; the filtered resolution is the one contact pixels and the learnt
// background refer to. Left out when no configuration said (preset empty).
void put_filters(std::string& line, const RunHeader::Filters& filters) {
  if (filters.preset.empty()) return;
  put_key(line, "filters");
  line += '{';
  put_key(line, "preset");
  put_string(line, filters.preset);
  put_key(line, "domain");
  put_string(line, filters.domain);
  if (!filters.note.empty()) {
    put_key(line, "note");
    put_string(line, filters.note);
  }
  put_key(line, "width");
  put_int(line, filters.intrinsics.width);
  put_key(line, "height");
  put_int(line, filters.intrinsics.height);
  put_key(line, "fx");
  put_float(line, filters.intrinsics.fx);
  put_key(line, "fy");
  put_float(line, filters.intrinsics.fy);
  put_key(line, "ppx");
  put_float(line, filters.intrinsics.ppx);
  put_key(line, "ppy");
  put_float(line, filters.intrinsics.ppy);
  line += '}';
}

}  // namespace

void JsonLinesSink::header(const RunHeader& header) {
  std::string& line = line_;
  line.assign("{");
  put_key(line, "type");
  put_string(line, "header");
  put_key(line, "version");
  put_string(line, header.version.empty() ? HRCSENSE_VERSION : header.version);
  put_key(line, "commit");
  put_string(line, header.commit.empty() ? HRCSENSE_COMMIT : header.commit);
  put_key(line, "config_hash");
  put_string(line, header.config_hash);

  const SourceInfo& source = header.source;
  put_key(line, "source");
  line += '{';
  put_key(line, "type");
  put_string(line, source.type);
  put_key(line, "description");
  put_string(line, source.description);
  put_key(line, "frame_count");
  put_int(line, source.frame_count);
  put_key(line, "nominal_fps");
  put_double(line, source.nominal_fps);
  put_key(line, "stereo_baseline_mm");
  put_float(line, source.stereo_baseline_mm);
  line += '}';

  const Intrinsics& in = source.intrinsics;
  put_key(line, "intrinsics");
  line += '{';
  put_key(line, "width");
  put_int(line, in.width);
  put_key(line, "height");
  put_int(line, in.height);
  put_key(line, "fx");
  put_float(line, in.fx);
  put_key(line, "fy");
  put_float(line, in.fy);
  put_key(line, "ppx");
  put_float(line, in.ppx);
  put_key(line, "ppy");
  put_float(line, in.ppy);
  put_key(line, "model");
  put_string(line, distortion_name(in.model));
  put_key(line, "coeffs");
  line += '[';
  for (size_t i = 0; i < in.coeffs.size(); ++i) {
    if (i > 0) line += ',';
    put_float(line, in.coeffs[i]);
  }
  line += "]}";
  put_filters(line, header.filters);
  line += "}\n";
  out_ << line;
}

void JsonLinesSink::frame(const FrameResult& result) {
  std::string& line = line_;
  const Contact& contact = result.contact;
  line.assign("{");
  put_key(line, "type");
  put_string(line, result.source_frame ? "frame" : "verdict");
  put_key(line, "frame");
  put_int(line, result.frame);
  put_key(line, "timestamp_ns");
  put_int(line, result.timestamp_ns);
  put_key(line, "timestamp_s");
  put_seconds(line, result.timestamp_ns);
  put_key(line, "valid");
  line += result.valid ? "true" : "false";
  put_key(line, "verdict");
  put_string(line, verdict_name(result.verdict.state));
  put_key(line, "verdict_reason");
  put_string(line, result.verdict.reason);
  put_key(line, "speed_scale");
  put_float(line, result.verdict.speed_scale);

  put_key(line, "distance_m");
  if (contact.valid) {
    put_float(line, contact.distance_m);
  } else {
    line += "null";
  }
  const std::pair<const char*, const Eigen::Vector3f*> points[] = {
      {"closest_camera", &contact.closest_camera},
      {"closest_base", &contact.closest_base},
      {"closest_robot_base", &contact.closest_robot_base}};
  for (const auto& [key, point] : points) {
    put_key(line, key);
    if (contact.valid) {
      put_vec3(line, *point);
    } else {
      line += "null";
    }
  }
  put_key(line, "robot_link");
  if (contact.valid) {
    put_int(line, contact.robot_link);
  } else {
    line += "null";
  }

  put_key(line, "inside");  // a foreground point inside (or on) a capsule: distance 0
  line += contact.valid ? (contact.inside ? "true" : "false") : "null";
  put_key(line, "backend");  // the one that searched (auto's pick), else the configured one
  put_string(line, result.backend != nullptr ? result.backend : backend_.c_str());
  put_key(line, "foreground_points");
  put_int(line, static_cast<int64_t>(result.foreground_points));
  put_key(line, "invalid_pixels");
  put_int(line, static_cast<int64_t>(result.invalid_pixels));
  put_key(line, "latency_us");
  put_double(line, result.latency_us);
  put_key(line, "timings_us");
  line += '{';
  for (const StageTiming& timing : result.timings) {
    put_key(line, timing.stage);
    put_double(line, timing.us);
  }
  line += '}';
  if (result.truth) {
    put_key(line, "truth");
    put_truth(line, *result.truth);
  }
  line += "}\n";
  out_ << line;
}

void JsonLinesSink::summary(const RunSummary& summary) {
  std::string& line = line_;
  line.assign("{");
  put_key(line, "type");
  put_string(line, "summary");
  const std::pair<const char*, int64_t> counts[] = {
      {"frames_in", summary.frames_in},       {"frames_processed", summary.frames_processed},
      {"frames_dropped", summary.frames_dropped}, {"frames_valid", summary.frames_valid},
      {"verdict_run", summary.verdict_run},   {"verdict_slow", summary.verdict_slow},
      {"verdict_stop", summary.verdict_stop}};
  for (const auto& [key, value] : counts) {
    put_key(line, key);
    put_int(line, value);
  }
  const std::pair<const char*, double> figures[] = {{"wall_s", summary.wall_s},
                                                    {"fps", summary.fps},
                                                    {"latency_p50_us", summary.latency_p50_us},
                                                    {"latency_p99_us", summary.latency_p99_us}};
  for (const auto& [key, value] : figures) {
    put_key(line, key);
    put_double(line, value);
  }
  put_key(line, "min_distance_m");
  if (summary.min_distance_m >= 0.0F) {
    put_float(line, summary.min_distance_m);
  } else {
    line += "null";  // never any foreground
  }
  put_key(line, "end_reason");
  put_string(line, summary.end_reason);
  line += "}\n";
  out_ << line;
  out_.flush();
}

}  // namespace hrcsense
