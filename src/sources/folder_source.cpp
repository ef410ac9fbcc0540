// SPDX-License-Identifier: Apache-2.0
// hrcsense — a folder of 16-bit depth PNGs as a Source: the datasets' layout and TUM RGB-D's.
#include "bag_messages.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/io.hpp"
#include "hrcsense/recordings.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hrcsense {
namespace {

namespace fs = std::filesystem;

/// Without recorded timestamps, frames are spaced as if at this rate (pacing only).
constexpr double kNominalFps = 30.0;
/// TUM RGB-D stores depth as 5000 units per metre.
constexpr float kTumDepthScaleM = 1.0F / 5000.0F;

std::string read_text(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw IoError(path + ": cannot open");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

/// "1305031102.175304" → 1305031102175304000, exactly (no floating point on the way).
bool parse_seconds_ns(const std::string& text, int64_t& out_ns) {
  const size_t dot = text.find('.');
  const std::string whole = text.substr(0, dot);
  std::string fraction = dot == std::string::npos ? "" : text.substr(dot + 1);
  if (whole.empty() || whole.size() > 10 || fraction.size() > 9) return false;
  const auto digits = [](const std::string& s) {
    return std::all_of(s.begin(), s.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
  };
  if (!digits(whole) || !digits(fraction)) return false;
  fraction.resize(9, '0');
  out_ns = std::stoll(whole) * 1000000000LL + std::stoll(fraction);
  return true;
}

/// Reads a list file: one frame per non-comment line; the path is in column `path_column`,
/// a time in seconds in column `time_column` (-1: none).
void read_list(const std::string& list_path, const fs::path& folder, int path_column, int time_column,
               std::vector<std::string>& files, std::vector<int64_t>& stamps_ns) {
  std::istringstream lines(read_text(list_path));
  std::string line;
  for (int line_no = 1; std::getline(lines, line); ++line_no) {
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream words(line);
    std::vector<std::string> columns;
    for (std::string word; words >> word;) columns.push_back(word);
    const int needed = std::max(path_column, time_column);
    if (static_cast<int>(columns.size()) <= needed) {
      throw IoError(list_path + ":" + std::to_string(line_no) + ": expected at least " + std::to_string(needed + 1) +
                    " columns");
    }
    files.push_back((folder / columns[static_cast<size_t>(path_column)]).string());
    if (time_column >= 0) {
      int64_t ns = 0;
      if (!parse_seconds_ns(columns[static_cast<size_t>(time_column)], ns)) {
        throw IoError(list_path + ":" + std::to_string(line_no) + ": bad timestamp '" +
                      columns[static_cast<size_t>(time_column)] + "'");
      }
      stamps_ns.push_back(ns);
    }
  }
}

float json_number(const nlohmann::json& node, const std::string& what) {
  if (!node.is_number()) throw IoError(what + ": expected a number");
  return node.get<float>();
}

/// The datasets' form: {"width", "height", "depth_K", "depth_units_m", "pixel_convention"}.
Intrinsics intrinsics_from_dataset_json(const nlohmann::json& doc, const std::string& path, float& scale_m) {
  const nlohmann::json& k = doc["depth_K"];
  if (!k.is_array() || k.size() != 3 || !k[0].is_array() || k[0].size() != 3 || !k[1].is_array() ||
      k[1].size() != 3) {
    throw IoError(path + ": depth_K: expected a 3x3 matrix");
  }
  Intrinsics in;
  if (!doc["width"].is_number_integer() || !doc["height"].is_number_integer()) {
    throw IoError(path + ": width, height: expected integers");
  }
  in.width = doc["width"].get<int>();
  in.height = doc["height"].get<int>();
  in.fx = json_number(k[0][0], path + ": depth_K[0][0]");
  in.ppx = json_number(k[0][2], path + ": depth_K[0][2]");
  in.fy = json_number(k[1][1], path + ": depth_K[1][1]");
  in.ppy = json_number(k[1][2], path + ": depth_K[1][2]");
  // MATLAB calibrations put the first pixel's centre at 1; hrcsense (like the SDK) at 0.
  const std::string convention = doc.value("pixel_convention", std::string("0-based"));
  if (convention.rfind("1-based", 0) == 0) {
    in.ppx -= 1.0F;
    in.ppy -= 1.0F;
  }
  if (doc.contains("depth_units_m")) scale_m = json_number(doc["depth_units_m"], path + ": depth_units_m");
  return in;
}

Intrinsics read_intrinsics_file(const std::string& path, float& scale_m) {
  if (!fs::is_regular_file(path)) throw IoError(path + ": intrinsics file missing (every depth folder needs one)");
  const std::string text = read_text(path);
  Intrinsics in;
  try {
    const nlohmann::json doc = nlohmann::json::parse(text);
    in = doc.contains("depth_K") ? intrinsics_from_dataset_json(doc, path, scale_m) : intrinsics_from_json(text, path);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(path + ": " + e.what());
  }
  if (in.width <= 0 || in.height <= 0 || in.width > 16384 || in.height > 16384 || !(in.fx > 0.0F) || !(in.fy > 0.0F)) {
    throw IoError(path + ": implausible intrinsics (size " + std::to_string(in.width) + "x" + std::to_string(in.height) +
                  ", fx and fy must be positive)");
  }
  if (!(scale_m > 0.0F)) throw IoError(path + ": depth_units_m must be positive");
  return in;
}

}  // namespace

FolderSource::FolderSource(RecordingParams params) : params_(std::move(params)) {
  const fs::path folder(params_.path);
  if (!fs::is_directory(folder)) throw IoError(params_.path + ": not a folder");
  if (fs::is_regular_file(folder / "depth.txt")) {
    layout_ = "tum";
    depth_scale_m_ = kTumDepthScaleM;
    read_list((folder / "depth.txt").string(), folder, 1, 0, files_, stamps_ns_);
  } else if (fs::is_regular_file(folder / "frames.txt")) {
    layout_ = "ist";
    read_list((folder / "frames.txt").string(), folder, 1, -1, files_, stamps_ns_);
  } else if (fs::is_directory(folder / "depth")) {
    layout_ = "ist";
    for (const fs::directory_entry& entry : fs::directory_iterator(folder / "depth")) {
      if (entry.path().extension() == ".png") files_.push_back(entry.path().string());
    }
    std::sort(files_.begin(), files_.end());
  } else {
    throw IoError(params_.path + ": no depth.txt, frames.txt or depth/ folder: not a depth recording");
  }
  if (files_.empty()) throw IoError(params_.path + ": no depth frames listed");
  intrinsics_ = read_intrinsics_file((folder / "intrinsics.json").string(), depth_scale_m_);
}

SourceInfo FolderSource::info() const {
  SourceInfo info;
  info.type = "folder";
  info.description = params_.path + " (" + layout_ + " layout, " + std::to_string(files_.size()) + " frames)";
  info.intrinsics = intrinsics_;
  info.stereo_baseline_mm = params_.stereo_baseline_mm;
  info.nominal_fps = kNominalFps;
  info.frame_count = params_.loop ? -1 : static_cast<int64_t>(files_.size());
  return info;
}

Source::Status FolderSource::next(Frame& out) {
  if (!error_.empty()) return Status::error;
  const auto count = static_cast<int64_t>(files_.size());
  if (!params_.loop && played_ >= count) return Status::end;
  const int64_t lap = played_ / count;
  const auto i = static_cast<size_t>(played_ % count);
  const std::string& file = files_[i];
  try {
    read_depth_png(file, out.depth);
  } catch (const IoError& e) {
    error_ = "frame " + std::to_string(played_) + ": " + e.what();
    return Status::error;
  }
  if (out.depth.width != intrinsics_.width || out.depth.height != intrinsics_.height) {
    error_ = "frame " + std::to_string(played_) + ": " + file + ": image is " + std::to_string(out.depth.width) + "x" +
             std::to_string(out.depth.height) + " but the intrinsics say " + std::to_string(intrinsics_.width) + "x" +
             std::to_string(intrinsics_.height);
    return Status::error;
  }
  out.depth.depth_scale_m = depth_scale_m_;
  out.index = played_;
  const auto period_ns = static_cast<int64_t>(1e9 / kNominalFps);
  if (stamps_ns_.empty()) {
    out.timestamp_ns = played_ * period_ns;
  } else {
    // Looping: each lap starts one period after the previous one's last frame.
    out.timestamp_ns = stamps_ns_[i] + lap * (stamps_ns_.back() - stamps_ns_.front() + period_ns);
  }
  out.intrinsics = intrinsics_;
  out.stereo_baseline_mm = params_.stereo_baseline_mm;
  out.color.reset();
  out.truth.reset();
  ++played_;
  return Status::frame;
}

}  // namespace hrcsense

namespace hrcsense {
namespace {

RecordingSummary summarize_folder(const std::string& path) {
  FolderSource source(RecordingParams{path});
  RecordingSummary summary;
  summary.path = path;
  summary.format = "folder (" + source.layout() + " layout)";
  summary.compression = "png";
  RecordingStream depth{"depth", "png (16-bit)", source.info().intrinsics, 0, 0, 0};
  Frame frame;
  Source::Status status = Source::Status::frame;
  while ((status = source.next(frame)) == Source::Status::frame) {
    if (depth.frames == 0) depth.first_ns = frame.timestamp_ns;
    depth.last_ns = frame.timestamp_ns;
    summary.depth_units_m = frame.depth.depth_scale_m;
    ++depth.frames;
  }
  if (status == Source::Status::error) summary.damage = source.error();
  if (source.timestamps_ns().empty()) depth.first_ns = depth.last_ns = 0;  // no recorded times
  summary.streams.push_back(depth);
  // Colour images are listed, not decoded: count them and name their format.
  const fs::path rgb = fs::path(path) / "rgb";
  if (fs::is_directory(rgb)) {
    RecordingStream color{"color", "", {}, 0, 0, 0};
    for (const fs::directory_entry& entry : fs::directory_iterator(rgb)) {
      const std::string ext = entry.path().extension().string();
      if (ext != ".png" && ext != ".jpg" && ext != ".jpeg") continue;
      color.encoding = ext == ".png" ? "png" : "jpeg";
      ++color.frames;
    }
    if (color.frames > 0) summary.streams.push_back(color);
  }
  return summary;
}

}  // namespace

RecordingSummary summarize_recording(const std::string& path) {
  if (fs::is_directory(path)) return summarize_folder(path);
  if (!fs::exists(path)) throw IoError(path + ": no such file or folder");
  return summarize_bag(path);
}

}  // namespace hrcsense
