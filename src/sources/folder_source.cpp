// SPDX-License-Identifier: Apache-2.0
// hrcsense — a folder of 16-bit depth PNGs as a Source: the datasets' layout and TUM RGB-D's.
#include "bag_messages.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/io.hpp"
#include "hrcsense/recordings.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

namespace hrcsense {
namespace {

namespace fs = std::filesystem;

/// Without recorded timestamps, frames are spaced as if at this rate (pacing only).
constexpr double kNominalFps = 30.0;
/// TUM RGB-D stores depth as 5000 units per metre.
constexpr float kTumDepthScaleM = 1.0F / 5000.0F;
/// Largest depth image (pixels) a folder may declare: 32 Mpx, far beyond any depth camera.
constexpr int64_t kMaxDepthPixels = int64_t{1} << 25;
/// TUM's associate.py pairs depth and colour images up to 20 ms apart.
constexpr int64_t kMaxColorOffsetNs = 20'000'000;

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
  // Ten digits of seconds can exceed int64 nanoseconds (year 2262): refuse those.
  const int64_t seconds = std::stoll(whole);
  if (seconds > std::numeric_limits<int64_t>::max() / 1000000000LL - 1) return false;
  out_ns = seconds * 1000000000LL + std::stoll(fraction);
  return true;
}

/// Reads a list file: one frame per non-comment line; the path is in column `path_column`,
/// a time in seconds in column `time_column` (-1: none), and, where a line has it, a colour
/// image in column `color_column` (-1: none; `colors` gets "" for lines without one).
void read_list(const std::string& list_path, const fs::path& folder, int path_column, int time_column,
               std::vector<std::string>& files, std::vector<int64_t>& stamps_ns, int color_column = -1,
               std::vector<std::string>* colors = nullptr) {
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
    if (colors != nullptr) {
      const bool has = color_column >= 0 && static_cast<int>(columns.size()) > color_column;
      colors->push_back(has ? (folder / columns[static_cast<size_t>(color_column)]).string() : std::string());
    }
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

/// A 3x3 matrix given as rows, or an error naming the field.
void check_3x3(const nlohmann::json& m, const std::string& what) {
  if (!m.is_array() || m.size() != 3 || !m[0].is_array() || m[0].size() != 3 || !m[1].is_array() ||
      m[1].size() != 3 || !m[2].is_array() || m[2].size() != 3) {
    throw IoError(what + ": expected a 3x3 matrix");
  }
}

/// The colour camera of the datasets' form (`rgb_K`, `depth_to_rgb_R`, `depth_to_rgb_T_m`),
/// where the file has it; the colour image size comes from the images.
void color_calibration_from_dataset_json(const nlohmann::json& doc, const std::string& path, bool one_based,
                                         Intrinsics& color, std::optional<Extrinsics>& depth_to_color) {
  if (doc.contains("rgb_K")) {
    const nlohmann::json& k = doc.at("rgb_K");
    check_3x3(k, path + ": rgb_K");
    color.fx = json_number(k[0][0], path + ": rgb_K[0][0]");
    color.ppx = json_number(k[0][2], path + ": rgb_K[0][2]") - (one_based ? 1.0F : 0.0F);
    color.fy = json_number(k[1][1], path + ": rgb_K[1][1]");
    color.ppy = json_number(k[1][2], path + ": rgb_K[1][2]") - (one_based ? 1.0F : 0.0F);
  }
  if (doc.contains("depth_to_rgb_R") && doc.contains("depth_to_rgb_T_m")) {
    const nlohmann::json& r = doc.at("depth_to_rgb_R");
    const nlohmann::json& t = doc.at("depth_to_rgb_T_m");
    check_3x3(r, path + ": depth_to_rgb_R");
    if (!t.is_array() || t.size() != 3) throw IoError(path + ": depth_to_rgb_T_m: expected 3 numbers");
    Extrinsics e;
    for (size_t i = 0; i < 3; ++i) {
      e.translation_m[i] = json_number(t[i], path + ": depth_to_rgb_T_m");
      // P_rgb = R·P_depth + T; the SDK's layout is column-major.
      for (size_t j = 0; j < 3; ++j) e.rotation[3 * j + i] = json_number(r[i][j], path + ": depth_to_rgb_R");
    }
    depth_to_color = e;
  }
}

/// The datasets' form: {"width", "height", "depth_K", "depth_units_m", "pixel_convention"}.
Intrinsics intrinsics_from_dataset_json(const nlohmann::json& doc, const std::string& path, float& scale_m) {
  // .at() and contains(), never operator[] on a const document: a missing key must be an
  // error, not a read past the end of the object (found by fuzz/folder_fuzz.cpp).
  const nlohmann::json& k = doc.at("depth_K");
  check_3x3(k, path + ": depth_K");
  Intrinsics in;
  if (!doc.contains("width") || !doc.contains("height") || !doc.at("width").is_number_integer() ||
      !doc.at("height").is_number_integer()) {
    throw IoError(path + ": width, height: expected integers");
  }
  in.width = doc.at("width").get<int>();
  in.height = doc.at("height").get<int>();
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
  if (doc.contains("depth_units_m")) scale_m = json_number(doc.at("depth_units_m"), path + ": depth_units_m");
  return in;
}

Intrinsics read_intrinsics_file(const std::string& path, float& scale_m, Intrinsics& color,
                                 std::optional<Extrinsics>& depth_to_color) {
  if (!fs::is_regular_file(path)) throw IoError(path + ": intrinsics file missing (every depth folder needs one)");
  const std::string text = read_text(path);
  Intrinsics in;
  try {
    const nlohmann::json doc = nlohmann::json::parse(text);
    in = doc.contains("depth_K") ? intrinsics_from_dataset_json(doc, path, scale_m) : intrinsics_from_json(text, path);
    if (doc.is_object() && doc.contains("depth_K")) {
      const bool one_based = doc.value("pixel_convention", std::string("0-based")).rfind("1-based", 0) == 0;
      color_calibration_from_dataset_json(doc, path, one_based, color, depth_to_color);
    }
  } catch (const nlohmann::json::exception& e) {
    throw IoError(path + ": " + e.what());
  }
  // The pixel count is bounded too: the depth PNGs are checked against this size before their
  // pixels are allocated, so the file's numbers bound every depth buffer (64 MiB at most).
  if (in.width <= 0 || in.height <= 0 || in.width > 16384 || in.height > 16384 ||
      static_cast<int64_t>(in.width) * in.height > kMaxDepthPixels || !(in.fx > 0.0F) || !(in.fy > 0.0F)) {
    throw IoError(path + ": implausible intrinsics (size " + std::to_string(in.width) + "x" + std::to_string(in.height) +
                  ", fx and fy must be positive)");
  }
  if (!(scale_m > 0.0F)) throw IoError(path + ": depth_units_m must be positive");
  return in;
}

/// TUM: for each depth time, the colour image of rgb.txt nearest in time, "" when none is
/// within kMaxColorOffsetNs.
std::vector<std::string> associate_colors(const std::vector<int64_t>& depth_ns, std::vector<std::string> rgb_files,
                                          std::vector<int64_t> rgb_ns) {
  std::vector<size_t> order(rgb_ns.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return rgb_ns[a] < rgb_ns[b]; });
  std::vector<int64_t> sorted_ns;
  for (size_t i : order) sorted_ns.push_back(rgb_ns[i]);
  std::vector<std::string> colors;
  for (const int64_t t : depth_ns) {
    const auto after = std::lower_bound(sorted_ns.begin(), sorted_ns.end(), t);
    int64_t best = -1;
    int64_t best_gap = kMaxColorOffsetNs + 1;
    for (auto it : {after, after == sorted_ns.begin() ? sorted_ns.end() : after - 1}) {
      if (it == sorted_ns.end()) continue;
      const int64_t gap = *it > t ? *it - t : t - *it;
      if (gap < best_gap) {
        best_gap = gap;
        best = it - sorted_ns.begin();
      }
    }
    colors.push_back(best < 0 ? std::string() : rgb_files[order[static_cast<size_t>(best)]]);
  }
  return colors;
}

/// The datasets without frames.txt: `rgb/<stem>.png`, `.jpg` or `.jpeg` beside `depth/<stem>.png`.
std::vector<std::string> colors_beside(const fs::path& folder, const std::vector<std::string>& depth_files) {
  std::vector<std::string> colors;
  bool any = false;
  for (const std::string& depth : depth_files) {
    std::string found;
    for (const char* ext : {".png", ".jpg", ".jpeg"}) {
      const fs::path candidate = folder / "rgb" / (fs::path(depth).stem().string() + ext);
      if (fs::is_regular_file(candidate)) {
        found = candidate.string();
        break;
      }
    }
    any = any || !found.empty();
    colors.push_back(found);
  }
  if (!any) colors.clear();
  return colors;
}

/// Decodes a colour image by its extension (.png, .jpg, .jpeg); IoError naming the file.
void read_color_image(const std::string& path, ColorImage& out) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  if (ext == ".png") return read_color_png(path, out);
  if (ext == ".jpg" || ext == ".jpeg") return read_color_jpeg(path, out);
  throw IoError(path + ": colour images must be .png, .jpg or .jpeg");
}

}  // namespace

FolderSource::FolderSource(RecordingParams params) : params_(std::move(params)) {
  const fs::path folder(params_.path);
  if (!fs::is_directory(folder)) throw IoError(params_.path + ": not a folder");
  if (fs::is_regular_file(folder / "depth.txt")) {
    layout_ = "tum";
    depth_scale_m_ = kTumDepthScaleM;
    read_list((folder / "depth.txt").string(), folder, 1, 0, files_, stamps_ns_);
    if (fs::is_regular_file(folder / "rgb.txt")) {
      std::vector<std::string> rgb_files;
      std::vector<int64_t> rgb_ns;
      read_list((folder / "rgb.txt").string(), folder, 1, 0, rgb_files, rgb_ns);
      color_files_ = associate_colors(stamps_ns_, std::move(rgb_files), std::move(rgb_ns));
    }
  } else if (fs::is_regular_file(folder / "frames.txt")) {
    layout_ = "ist";
    read_list((folder / "frames.txt").string(), folder, 1, -1, files_, stamps_ns_, 2, &color_files_);
    if (std::all_of(color_files_.begin(), color_files_.end(), [](const std::string& f) { return f.empty(); })) {
      color_files_.clear();
    }
  } else if (fs::is_directory(folder / "depth")) {
    layout_ = "ist";
    for (const fs::directory_entry& entry : fs::directory_iterator(folder / "depth")) {
      if (entry.path().extension() == ".png") files_.push_back(entry.path().string());
    }
    std::sort(files_.begin(), files_.end());
    color_files_ = colors_beside(folder, files_);
  } else {
    throw IoError(params_.path + ": no depth.txt, frames.txt or depth/ folder: not a depth recording");
  }
  if (files_.empty()) throw IoError(params_.path + ": no depth frames listed");
  intrinsics_ = read_intrinsics_file((folder / "intrinsics.json").string(), depth_scale_m_, color_intrinsics_,
                                     depth_to_color_);
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
    // A list may name anything; a device or a pipe would block or never end.
    if (!fs::is_regular_file(file)) throw IoError(file + ": missing or not a regular file");
    read_depth_png(file, out.depth, intrinsics_.width, intrinsics_.height);
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
  out.truth.reset();
  const std::string no_color;
  const std::string& color_file = color_files_.empty() ? no_color : color_files_[i];
  if (!params_.with_color || color_file.empty()) {
    out.color.reset();
    out.color_intrinsics = Intrinsics{};
    out.depth_to_color.reset();
  } else {
    if (!out.color) out.color.emplace();
    try {
      if (!fs::is_regular_file(color_file)) throw IoError(color_file + ": missing or not a regular file");
      read_color_image(color_file, *out.color);
    } catch (const IoError& e) {
      error_ = "frame " + std::to_string(played_) + ": colour: " + e.what();
      return Status::error;
    }
    out.color_intrinsics = color_intrinsics_;
    out.color_intrinsics.width = out.color->width;
    out.color_intrinsics.height = out.color->height;
    out.depth_to_color = depth_to_color_;
  }
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
