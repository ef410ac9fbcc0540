// SPDX-License-Identifier: Apache-2.0
// hrcsense — a RealSense .bag writer (ROS bag 2.0 in the SDK's topic layout, file version 4;
// ../shared/specs/realsense-bag-format.md): depth (Z16 as mono16) and colour (rgb8) streams with
// their camera_info, tf, stream info, per-frame metadata, the device's and sensors' info, the
// Depth_Units and Stereo_Baseline options, optional robot joint states, LZ4 or uncompressed
// chunks and the index. Each closed chunk goes to the file at once, so a recording that is
// killed stays readable up to its last complete chunk.
#pragma once

#include "hrcsense/types.hpp"

#include <array>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

struct LZ4F_cctx_s;

namespace hrcsense {

/// A failed write, open or close of a recording; the message names the file and the cause
/// (e.g. "out.bag: write failed: No space left on device").
class BagWriteError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class BagCompression { none, lz4 };

/// A UR arm's joints as ROS names them (the UR ROS driver's joint_states), joint 1 first.
inline constexpr std::array<const char*, kJointCount> kUrJointNames = {
    "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"};

struct BagWriterParams {
  BagCompression compression = BagCompression::lz4;  ///< the D435's SDK default
  /// false: leave index_pos 0 and write no connection/chunk info records at the end, as a
  /// recording that was never closed (tests of the reader's scan).
  bool write_index = true;
  /// true: images carry the trailing depth-units field of SDK >= 2.49 (frame_id "1").
  bool trailing_depth_units = true;
  /// > 0: write the Depth_Units option (the only source of units when no trailing field).
  float depth_units_option_m = 0.0F;
  float stereo_baseline_mm = 0.0F;  ///< > 0: write the Stereo_Baseline option
  uint32_t file_version = 4;
  /// true: the device and sensor info, stream info and per-frame metadata the SDK's playback
  /// expects (false: only what hrcsense's reader needs, for small test bags).
  bool sdk_metadata = true;
  uint32_t fps = 30;                ///< written in the streams' StreamInfo
  /// A chunk is closed once its uncompressed size exceeds this (the SDK: 768 KiB).
  size_t chunk_bytes = 768 * 1024;
  /// The names add_joint_state gives the joints, joint 1 first (kUrJointNames for a UR arm);
  /// empty: "joint_0" ... "joint_5".
  std::vector<std::string> joint_names;
};

/// True when add_frame records the frame's colour image: it has one, and its calibration
/// (Frame::color_intrinsics of the image's size, focal lengths known). A folder without `rgb_K`
/// has colour without calibration: its frames are recorded without colour.
bool color_recordable(const Frame& frame);

/// Writes one bag; messages go into chunks as they come, the index on close() (or destruction).
/// Every method throws BagWriteError naming the file when the file system refuses, or when an
/// image's buffer does not match its size.
class BagWriter {
 public:
  explicit BagWriter(std::string path, BagWriterParams params = {});
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  /// The frame's depth image (and its colour image when color_recordable, with depth_to_color as
  /// the colour stream's tf), and with `robot_state` the robot's joints at it (add_joint_state:
  /// positions and velocities), in that order: colour, joints, depth. Stream info, camera_info
  /// and tf go out with a stream's first frame.
  void add_frame(const Frame& frame, const RobotState* robot_state = nullptr);
  /// The depth image alone. Bag time: the frame's timestamp relative to the first frame's
  /// (plus 2 ns: the SDK's playback reads streams from there), header stamp: its timestamp.
  void add_depth(const Frame& frame);
  /// An rgb8 colour image numbered `frame_number` (header.seq and the "Frame Counter" metadata;
  /// add_frame gives the frame's index, as for its depth image); T_color_depth (depth-frame
  /// points into the colour frame, the SDK's depth→colour extrinsics) is the colour stream's tf.
  void add_color(int64_t timestamp_ns, uint32_t frame_number, const ColorImage& color, const Intrinsics& intrinsics,
                 const Pose& T_color_depth = Pose::Identity());
  /// The robot's joints at a frame as `/hrcsense/joint_states` (sensor_msgs/JointState stamped
  /// `timestamp_ns`: names from params.joint_names, positions in rad, velocities in rad/s when
  /// given, no efforts). Write it before the frame's depth image: a reader in file order
  /// (BagSource) then has a frame's joints when the frame arrives.
  void add_joint_state(int64_t timestamp_ns, const JointAngles& position_rad,
                       const std::optional<JointAngles>& velocity_rad_s = std::nullopt);

  /// Flushes the last chunk, writes the index (unless params.write_index is false) and patches
  /// the bag header. Further calls do nothing.
  void close();

  /// Bytes in the file so far (closed chunks), the open chunk's uncompressed bytes not included.
  uint64_t bytes_written() const { return position_; }
  /// The open chunk's uncompressed bytes (what it adds to the file at most, before compression).
  uint64_t pending_bytes() const { return chunk_.size(); }
  const std::string& path() const { return path_; }

 private:
  struct Connection {
    uint32_t id = 0;
    std::string topic, type, md5;
  };
  struct ChunkInfo {
    uint64_t pos = 0;
    int64_t start_ns = 0, end_ns = 0;
    std::map<uint32_t, uint32_t> counts;
  };
  struct FileCloser {
    void operator()(std::FILE* file) const;
  };
  struct Lz4Freer {
    void operator()(LZ4F_cctx_s* context) const;
  };

  void write(const uint8_t* data, size_t size);
  void write_bag_header(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count);
  void write_static_info();
  /// A Depth_Units or Stereo_Baseline option of the stereo module: its value and description.
  void put_option(const std::string& name, float value, const std::string& description);
  uint32_t topic(const std::string& name, const char* type, const char* md5);
  void begin_message(uint32_t conn, int64_t time_ns);
  void end_message();
  void put_message(uint32_t conn, int64_t time_ns, const std::vector<uint8_t>& message);
  void put_key_value(uint32_t conn, int64_t time_ns, const std::string& key, const std::string& value);
  void put_image(const std::string& stream, int64_t timestamp_ns, uint32_t seq, int width, int height,
                 const char* encoding, const uint8_t* pixels, size_t step, float depth_units_m);
  void start_stream(const std::string& stream, const char* encoding, const Intrinsics& intrinsics,
                    const Pose& T_stream_ref);
  int64_t bag_time(int64_t timestamp_ns);
  void flush_chunk();
  /// Compresses chunk_ into packed_ (one LZ4 frame); returns the compressed size in bytes.
  size_t compress_chunk_lz4();
  void write_chunk_index();

  std::string path_;
  BagWriterParams params_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  uint64_t position_ = 0;
  std::vector<Connection> connections_;
  std::vector<ChunkInfo> chunk_infos_;
  ChunkInfo current_;
  std::vector<uint8_t> chunk_;   ///< the open chunk, uncompressed
  std::vector<uint8_t> packed_;  ///< its compressed form, reused
  /// One compression context for every chunk: a fresh one per chunk would allocate and clear
  /// its 1 MiB block buffer each time.
  std::unique_ptr<LZ4F_cctx_s, Lz4Freer> lz4_;
  size_t message_start_ = 0;     ///< where the open message's data_len field is in chunk_
  /// Index entries of the open chunk per connection: (time, offset in the chunk).
  std::map<uint32_t, std::vector<std::pair<int64_t, uint32_t>>> in_chunk_;
  bool depth_started_ = false;
  bool color_started_ = false;
  bool have_first_time_ = false;
  int64_t first_timestamp_ns_ = 0;
};

}  // namespace hrcsense
