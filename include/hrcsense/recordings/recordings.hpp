// SPDX-License-Identifier: Apache-2.0
// hrcsense — recorded sources: a folder of 16-bit depth PNGs and RealSense .bag files (ROS bag 2.0).
#pragma once

#include "hrcsense/source.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {

/// One image stream of a recording, as `summarize_recording` found it.
struct RecordingStream {
  std::string name;          ///< "depth", "color"
  std::string encoding;      ///< "mono16", "rgb8", "png", "jpeg", ...
  Intrinsics intrinsics;     ///< width and height are the resolution
  int64_t frames = 0;        ///< frames found (a damaged file: frames before the damage)
  int64_t first_ns = 0;      ///< timestamp of the first frame, nanoseconds (0 when unknown)
  int64_t last_ns = 0;       ///< timestamp of the last frame, nanoseconds
  uint32_t fps = 0;          ///< the rate the recording states (bag: StreamInfo), frames/s; 0: none
};

/// What a recording holds, for `hrcsense info` and for tests. Read by going through the
/// whole recording once.
/// A recording's kind: the SDK's .bag file or a folder of PNG frames.
enum class RecordingFormat { bag, folder };

struct RecordingSummary {
  std::string path;
  RecordingFormat format = RecordingFormat::bag;
  std::string folder_layout;        ///< folder: "ist" or "TUM"; bag: empty
  std::string compression;          ///< bag: chunk compressions seen ("lz4", "none", "lz4+none"); folder: "png"
  std::vector<RecordingStream> streams;  ///< depth first
  float depth_units_m = 0.001F;     ///< metres per raw depth unit
  float stereo_baseline_mm = 0.0F;  ///< 0 when the recording does not say
  int file_version = 0;             ///< bag: the SDK's /file_version; 0 when absent
  bool indexed = false;             ///< bag: read through its index (false: linear scan)
  /// bag: the colour stream's pose relative to the depth stream (maps depth-frame points into
  /// the colour frame), when the bag has both streams' tf messages.
  std::optional<Pose> T_color_depth;
  std::string damage;               ///< empty, or the error at which reading stopped
};

/// Reads the whole recording at `path` (a .bag file or a folder) and says what it holds.
/// Throws IoError when the recording cannot be opened at all (missing, wrong magic, no
/// intrinsics); damage later in the file is reported in `damage` instead.
RecordingSummary summarize_recording(const std::string& path);

/// The recording's format as `hrcsense info` prints it: "bag", "folder (ist layout)",
/// "folder (TUM layout)".
std::string recording_format_text(const RecordingSummary& summary);

/// Options shared by the recorded sources.
struct RecordingParams {
  std::string path;                 ///< folder or .bag file
  bool loop = false;                ///< start over at the end (indices and timestamps keep rising)
  float stereo_baseline_mm = 0.0F;  ///< used when the recording does not carry a baseline
  bool with_color = false;          ///< also decode colour frames into Frame::color (bag, folder)
  /// bag: also read the robot's joint states (/hrcsense/joint_states) for recorded_robot_state();
  /// a malformed one is then an error like a damaged frame.
  bool with_joint_states = false;
};

/// A folder of depth PNGs. Two layouts:
/// - `depth/NNNNNN.png` (+ optional `frames.txt` listing "index depth_path ..." lines and
///   `rgb/`) with `intrinsics.json`, as the datasets in ../shared/data;
/// - the TUM RGB-D layout: `depth.txt` ("timestamp_s path" lines), depth scale 5000 per metre,
///   with `intrinsics.json` beside it.
/// `intrinsics.json` is either hrcsense's own format (io.hpp) or {"width", "height",
/// "depth_K": 3x3, "depth_units_m", "pixel_convention"}; a 1-based pixel convention is turned
/// into hrcsense's 0-based one (ppx, ppy minus 1).
/// Colour (decoded only with `with_color`): .png or .jpg/.jpeg images named in the third column
/// of frames.txt, else `rgb/<depth file stem>.*`; TUM: `rgb.txt`, the image nearest in time
/// (within 20 ms). The datasets' optional `rgb_K`, `depth_to_rgb_R` and `depth_to_rgb_T_m` give
/// Frame::color_intrinsics and Frame::depth_to_color.
class FolderSource : public Source {
 public:
  /// Lists the frames and reads the intrinsics; throws IoError naming the file when the folder,
  /// its frame list or its intrinsics are missing, unreadable or not regular files (a FIFO would
  /// block), or when the list's first frame line is already malformed (naming file and line).
  explicit FolderSource(RecordingParams params);
  SourceInfo info() const override;
  /// A PNG that cannot be read, or whose size or bit depth differs from the intrinsics, is an
  /// error naming the file and frame; every later call repeats it. So is a damaged colour image
  /// (when decoded), or a JPEG in a build without libturbojpeg, and a malformed line of
  /// frames.txt / depth.txt: the frames listed before it play, then the error names file:line.
  Status next(Frame& out) override;
  std::string error() const override { return error_; }

  /// The layout found: "ist" or "tum".
  const std::string& layout() const { return layout_; }
  /// The depth files in playback order.
  const std::vector<std::string>& depth_files() const { return files_; }
  /// Recorded timestamps (ns), one per file; empty when the folder has none.
  const std::vector<int64_t>& timestamps_ns() const { return stamps_ns_; }
  /// The colour image of each depth file ("" where there is none); empty when the folder has no colour.
  const std::vector<std::string>& color_files() const { return color_files_; }

 private:
  RecordingParams params_;
  std::string layout_;
  Intrinsics intrinsics_;
  float depth_scale_m_ = 0.001F;
  std::vector<std::string> files_;
  std::vector<int64_t> stamps_ns_;
  std::vector<std::string> color_files_;
  Intrinsics color_intrinsics_;                 ///< width 0 until an image gives the size; fx 0: unknown
  std::optional<Extrinsics> depth_to_color_;
  int64_t played_ = 0;
  std::string list_error_;  ///< the list's first malformed line, reported after the frames before it
  std::string error_;

  bool read_depth(const std::string& file, DepthImage& depth);
  bool read_color(const std::string& color_file, Frame& out);
};

class BagReader;
struct BagState;

/// A RealSense .bag recording (ROS bag 2.0, chunks none / lz4 / bz2): the depth stream of the
/// SDK's topic layout (`/device_0/sensor_<s>/Depth_<i>/image/data`) with its camera_info,
/// depth units (the image's trailing field, else the Depth_Units option, else 0.001) and,
/// with `with_color`, the latest colour frame. Reads through the index when there is one,
/// else scans the file. Streams: memory stays flat however long the recording.
class BagSource : public Source {
 public:
  /// Opens the bag and reads up to its first depth frame; throws IoError naming the file and
  /// byte offset when that fails (wrong magic, damaged start, no depth stream).
  explicit BagSource(RecordingParams params);
  ~BagSource() override;
  BagSource(const BagSource&) = delete;
  BagSource& operator=(const BagSource&) = delete;
  SourceInfo info() const override;
  /// After damage (truncation, a corrupt chunk, an unknown compression, a malformed message)
  /// returns `error` with a message naming the file and byte offset; every later call too.
  Status next(Frame& out) override;
  std::string error() const override;
  /// With `with_joint_states`: the recorded joint states as a RobotStateSource (origin
  /// `recorded`; docs/RECORDINGS.md, "Joint states"): for each frame the state stamped with its
  /// timestamp, exactly, as this source has read it (the recording writes a frame's joint state
  /// before its images); none for a frame is an invalid state. Joints are mapped by name
  /// (UR's, optionally prefixed, or joint_0..joint_5). May outlive this source. Null without
  /// `with_joint_states`, or when the bag has no /hrcsense/joint_states topic (indexed: anywhere;
  /// not indexed: before its first depth frame).
  std::unique_ptr<RobotStateSource> recorded_robot_state() const;

 private:
  RecordingParams params_;
  std::unique_ptr<BagState> state_;
};

}  // namespace hrcsense
