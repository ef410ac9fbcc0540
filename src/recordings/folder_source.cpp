// SPDX-License-Identifier: Apache-2.0
// hrcsense — a folder of 16-bit depth PNGs as a Source: the datasets' layout and TUM RGB-D's.
#include "bag_messages.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

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
  require_regular_file(path, "");  // a FIFO would block the open below forever
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

/// Where a list file keeps what (column numbers from 0; -1: not in this list).
struct ListColumns {
  int path = 1;
  int time = -1;   ///< time in seconds, "1305031102.175304"
  int color = -1;  ///< colour image, where a line has it
  int index = -1;  ///< the frame's number: digits only
};

/// A line for an error message: at most 60 characters, control bytes shown as '?'.
std::string quoted_line(const std::string& line) {
  std::string out = line.substr(0, 60);
  for (char& ch : out) {
    if (std::iscntrl(static_cast<unsigned char>(ch)) != 0) ch = '?';
  }
  return "'" + out + (line.size() > 60 ? "...'" : "'");
}

bool all_digits(const std::string& text) {
  return !text.empty() && text.size() <= 18 &&
         std::all_of(text.begin(), text.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
}

/// Reads a list file: one frame per non-comment line. Stops at the first malformed line and
/// returns "<file>:<line>: <problem>, got '<line>'" (the lines before it are kept, so that the
/// good frames still play); "" when every line is good.
std::string read_list(const std::string& list_path, const fs::path& folder, const ListColumns& c,
                      std::vector<std::string>& files, std::vector<int64_t>& stamps_ns,
                      std::vector<std::string>* colors = nullptr) {
  std::istringstream lines(read_text(list_path));
  std::string line;
  for (int line_no = 1; std::getline(lines, line); ++line_no) {
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream words(line);
    std::vector<std::string> columns;
    for (std::string word; words >> word;) columns.push_back(word);
    const auto column = [&](int i) { return columns[static_cast<size_t>(i)]; };
    const std::string at = list_path + ":" + std::to_string(line_no) + ": ";
    const int needed = std::max({c.path, c.time, c.index});
    if (static_cast<int>(columns.size()) <= needed) {
      return at + "expected at least " + std::to_string(needed + 1) + " columns, got " + quoted_line(line);
    }
    if (c.index >= 0 && !all_digits(column(c.index))) {
      return at + "expected a frame number in column " + std::to_string(c.index + 1) + ", got " + quoted_line(line);
    }
    int64_t ns = 0;
    // Digits only, at most 10 before the point: no NaN, infinity, sign or exponent gets through.
    if (c.time >= 0 && !parse_seconds_ns(column(c.time), ns)) {
      return at + "bad timestamp '" + column(c.time).substr(0, 40) +
             "' (expected seconds like 1305031102.175304, before the year 2262), got " + quoted_line(line);
    }
    if (c.time >= 0) stamps_ns.push_back(ns);
    files.push_back((folder / column(c.path)).string());
    if (colors != nullptr) {
      const bool has = c.color >= 0 && static_cast<int>(columns.size()) > c.color;
      colors->push_back(has ? (folder / column(c.color)).string() : std::string());
    }
  }
  return {};
}

Intrinsics read_intrinsics_file(const std::string& path, float& scale_m, Intrinsics& color,
                                 std::optional<Extrinsics>& depth_to_color) {
  if (!fs::exists(fs::symlink_status(path))) throw IoError(path + ": intrinsics file missing (every depth folder needs one)");
  FolderCalibration calibration = folder_calibration_from_json(read_text(path), path);
  // The pixel count is bounded too: the depth PNGs are checked against this size before their
  // pixels are allocated, so the file's numbers bound every depth buffer (64 MiB at most).
  const Intrinsics& in = calibration.depth;
  if (static_cast<int64_t>(in.width) * in.height > kMaxDepthPixels) {
    throw IoError(path + ": implausible intrinsics (size " + std::to_string(in.width) + "x" + std::to_string(in.height) +
                  ", more than 32 Mpx)");
  }
  if (calibration.depth_units_m > 0.0F) scale_m = calibration.depth_units_m;
  color = calibration.color;
  depth_to_color = calibration.depth_to_color;
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
      if (fs::exists(fs::symlink_status(candidate))) {
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
  // Found by name; read_text then refuses a list that is a FIFO, a device or a folder rather
  // than passing over it to another layout.
  const auto present = [&folder](const char* name) { return fs::exists(fs::symlink_status(folder / name)); };
  if (present("depth.txt")) {
    layout_ = "tum";
    depth_scale_m_ = kTumDepthScaleM;
    list_error_ = read_list((folder / "depth.txt").string(), folder, ListColumns{1, 0}, files_, stamps_ns_);
    if (present("rgb.txt")) {
      std::vector<std::string> rgb_files;
      std::vector<int64_t> rgb_ns;
      // Colour only: a bad line there is an error at once (it would pair the wrong images).
      const std::string problem = read_list((folder / "rgb.txt").string(), folder, ListColumns{1, 0}, rgb_files, rgb_ns);
      if (!problem.empty()) throw IoError(problem);
      color_files_ = associate_colors(stamps_ns_, std::move(rgb_files), std::move(rgb_ns));
    }
  } else if (present("frames.txt")) {
    layout_ = "ist";
    list_error_ =
        read_list((folder / "frames.txt").string(), folder, ListColumns{1, -1, 2, 0}, files_, stamps_ns_, &color_files_);
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
  // A list whose first frame line is already malformed has nothing to play: say which line.
  if (files_.empty()) throw IoError(list_error_.empty() ? params_.path + ": no depth frames listed" : list_error_);
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
  // After the good frames, a malformed list line is the damage (no second lap over it).
  if (played_ >= count && (!params_.loop || !list_error_.empty())) {
    if (list_error_.empty()) return Status::end;
    error_ = "frame " + std::to_string(played_) + ": " + list_error_;
    return Status::error;
  }
  const int64_t lap = played_ / count;
  const auto i = static_cast<size_t>(played_ % count);
  if (!read_depth(files_[i], out.depth)) return Status::error;
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
  } else if (!read_color(color_file, out)) {
    return Status::error;
  }
  ++played_;
  return Status::frame;
}

// The current frame's depth image, which must have the intrinsics' size; false with error_
// naming the frame and the file otherwise.
bool FolderSource::read_depth(const std::string& file, DepthImage& depth) {
  try {
    // A list may name anything; a device or a pipe would block or never end.
    require_regular_file(file, "depth image");
    read_depth_png(file, depth, intrinsics_.width, intrinsics_.height);
  } catch (const IoError& e) {
    error_ = "frame " + std::to_string(played_) + ": " + e.what();
    return false;
  }
  if (depth.width != intrinsics_.width || depth.height != intrinsics_.height) {
    error_ = "frame " + std::to_string(played_) + ": " + file + ": image is " + std::to_string(depth.width) + "x" +
             std::to_string(depth.height) + " but the intrinsics say " + std::to_string(intrinsics_.width) + "x" +
             std::to_string(intrinsics_.height);
    return false;
  }
  return true;
}

// The current frame's colour image with its intrinsics (the image's own size) and the
// depth-to-colour extrinsics; false with error_ when it cannot be read.
bool FolderSource::read_color(const std::string& color_file, Frame& out) {
  if (!out.color) out.color.emplace();
  try {
    require_regular_file(color_file, "colour image");
    read_color_image(color_file, *out.color);
  } catch (const IoError& e) {
    error_ = "frame " + std::to_string(played_) + ": colour: " + e.what();
    return false;
  }
  out.color_intrinsics = color_intrinsics_;
  out.color_intrinsics.width = out.color->width;
  out.color_intrinsics.height = out.color->height;
  out.depth_to_color = depth_to_color_;
  return true;
}

}  // namespace hrcsense

namespace hrcsense {
namespace {

RecordingSummary summarize_folder(const std::string& path) {
  FolderSource source(RecordingParams{path});
  RecordingSummary summary;
  summary.path = path;
  summary.format = RecordingFormat::folder;
  summary.folder_layout = source.layout();
  summary.compression = "png";
  RecordingStream depth{"depth", "png (16-bit)", source.info().intrinsics, 0, 0, 0, 0};
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
    RecordingStream color{"color", "", {}, 0, 0, 0, 0};
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

std::string recording_format_text(const RecordingSummary& summary) {
  switch (summary.format) {
    case RecordingFormat::bag: return "bag";
    case RecordingFormat::folder: return "folder (" + summary.folder_layout + " layout)";
  }
  return "unknown";
}

}  // namespace hrcsense
