// SPDX-License-Identifier: Apache-2.0
// A small ROS bag 2.0 writer in the RealSense SDK's topic layout, for tests, benchmarks and the
// fuzz seed corpus (../shared/specs/realsense-bag-format.md). Not the recorder: it writes what
// the reader needs (file version, depth units and baseline options, camera_info, tf, depth and
// colour images, the index) and nothing the reader ignores. Throws std::runtime_error.
#pragma once

#include "hrcsense/camera.hpp"
#include "hrcsense/types.hpp"

#include <lz4frame.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense::test {

enum class BagCompression { none, lz4 };

struct BagWriterParams {
  BagCompression compression = BagCompression::lz4;
  /// false: leave index_pos 0 and write no connection/chunk info records at the end, as a
  /// recording that was never closed (the reader then scans the chunks).
  bool write_index = true;
  /// true: images carry the trailing depth-units field of SDK >= 2.49 (frame_id "1").
  bool trailing_depth_units = true;
  /// > 0: also write the Depth_Units option (the only source of units when no trailing field).
  float depth_units_option_m = 0.0F;
  float stereo_baseline_mm = 0.0F;  ///< > 0: write the Stereo_Baseline option
  uint32_t file_version = 4;
  /// A chunk is closed once its uncompressed size exceeds this (the SDK: 768 KiB).
  size_t chunk_bytes = 768 * 1024;
};

namespace bag_writer_detail {

inline void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
inline void put64(std::vector<uint8_t>& b, uint64_t v) {
  put32(b, static_cast<uint32_t>(v));
  put32(b, static_cast<uint32_t>(v >> 32));
}
inline void put_f32(std::vector<uint8_t>& b, float v) {
  uint32_t bits = 0;
  std::memcpy(&bits, &v, 4);
  put32(b, bits);
}
inline void put_f64(std::vector<uint8_t>& b, double v) {
  uint64_t bits = 0;
  std::memcpy(&bits, &v, 8);
  put64(b, bits);
}
inline void put_string(std::vector<uint8_t>& b, const std::string& s) {
  put32(b, static_cast<uint32_t>(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
/// ROS time: uint32 sec, uint32 nsec.
inline void put_time(std::vector<uint8_t>& b, int64_t ns) {
  put32(b, static_cast<uint32_t>(ns / 1000000000LL));
  put32(b, static_cast<uint32_t>(ns % 1000000000LL));
}

/// A record header under construction: `name=value` fields with uint32 length prefixes.
struct Fields {
  std::vector<uint8_t> bytes;
  Fields& raw(const std::string& name, const std::vector<uint8_t>& value) {
    put32(bytes, static_cast<uint32_t>(name.size() + 1 + value.size()));
    bytes.insert(bytes.end(), name.begin(), name.end());
    bytes.push_back('=');
    bytes.insert(bytes.end(), value.begin(), value.end());
    return *this;
  }
  Fields& op(uint8_t v) { return raw("op", {v}); }
  Fields& u32(const std::string& name, uint32_t v) {
    std::vector<uint8_t> b;
    put32(b, v);
    return raw(name, b);
  }
  Fields& u64(const std::string& name, uint64_t v) {
    std::vector<uint8_t> b;
    put64(b, v);
    return raw(name, b);
  }
  Fields& time(const std::string& name, int64_t ns) {
    std::vector<uint8_t> b;
    put_time(b, ns);
    return raw(name, b);
  }
  Fields& text(const std::string& name, const std::string& v) { return raw(name, {v.begin(), v.end()}); }
};

/// Record = uint32 header_len, header, uint32 data_len, data.
inline void put_record(std::vector<uint8_t>& out, const Fields& header, const uint8_t* data, size_t size) {
  put32(out, static_cast<uint32_t>(header.bytes.size()));
  out.insert(out.end(), header.bytes.begin(), header.bytes.end());
  put32(out, static_cast<uint32_t>(size));
  out.insert(out.end(), data, data + size);
}

}  // namespace bag_writer_detail

/// Writes a bag; frames go into chunks as they come, the index on close() (or destruction).
class BagWriter {
 public:
  explicit BagWriter(const std::string& path, BagWriterParams params = {}) : params_(params) {
    file_.reset(std::fopen(path.c_str(), "wb"));
    if (!file_) throw std::runtime_error(path + ": cannot create");
    write(reinterpret_cast<const uint8_t*>("#ROSBAG V2.0\n"), 13);
    write_bag_header(0, 0, 0);  // patched in close()
    put_message(topic("/file_version", "std_msgs/UInt32", "304a39449588c7f8ce2df6e8001c5fce"), 1,
                u32_message(params_.file_version));
    if (params_.depth_units_option_m > 0.0F) {
      put_message(topic("/device_0/sensor_0/option/Depth_Units/value", "std_msgs/Float32",
                        "73fcbf46b49191e672908e50842a83d4"),
                  1, f32_message(params_.depth_units_option_m));
    }
    if (params_.stereo_baseline_mm > 0.0F) {
      put_message(topic("/device_0/sensor_0/option/Stereo_Baseline/value", "std_msgs/Float32",
                        "73fcbf46b49191e672908e50842a83d4"),
                  1, f32_message(params_.stereo_baseline_mm));
    }
  }
  ~BagWriter() {
    try {
      close();
    } catch (const std::exception&) {  // a destructor must not throw; close() reports it
    }
  }
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  /// A depth frame (Z16, `mono16`) with its intrinsics; camera_info and an identity tf go out
  /// with the first one. Bag time = the frame's timestamp.
  void add_depth(const Frame& frame) {
    const DepthImage& d = frame.depth;
    if (!depth_started_) {
      put_message(topic(kDepth + "/info/camera_info", "sensor_msgs/CameraInfo", kCameraInfoMd5), 1,
                  camera_info_message(frame.intrinsics));
      put_message(topic(kDepth + "/tf/0", "geometry_msgs/Transform", kTransformMd5), 1,
                  transform_message(Pose::Identity()));
      depth_started_ = true;
    }
    put_message(topic(kDepth + "/image/data", "sensor_msgs/Image", kImageMd5), frame.timestamp_ns,
                image_message(frame.timestamp_ns, static_cast<uint32_t>(frame.index), d.width, d.height, "mono16",
                              reinterpret_cast<const uint8_t*>(d.pixels.data()), static_cast<size_t>(d.width) * 2,
                              d.depth_scale_m));
  }

  /// An rgb8 colour frame; camera_info and tf (T_color_depth: depth-frame points into the
  /// colour frame, the SDK's depth→colour extrinsics) go out with the first one.
  void add_color(int64_t timestamp_ns, const ColorImage& color, const Intrinsics& intrinsics,
                 const Pose& T_color_depth = Pose::Identity()) {
    if (!color_started_) {
      put_message(topic(kColor + "/info/camera_info", "sensor_msgs/CameraInfo", kCameraInfoMd5), 1,
                  camera_info_message(intrinsics));
      put_message(topic(kColor + "/tf/0", "geometry_msgs/Transform", kTransformMd5), 1,
                  transform_message(T_color_depth));
      color_started_ = true;
    }
    put_message(topic(kColor + "/image/data", "sensor_msgs/Image", kImageMd5), timestamp_ns,
                image_message(timestamp_ns, 0, color.width, color.height, "rgb8", color.rgb.data(),
                              static_cast<size_t>(color.width) * 3, 0.0F));
  }

  /// Flushes the last chunk, writes the index (unless params.write_index is false) and patches
  /// the bag header. Further calls do nothing.
  void close() {
    if (!file_) return;
    flush_chunk();
    if (params_.write_index) {
      const uint64_t index_pos = position_;
      std::vector<uint8_t> out;
      for (const Connection& c : connections_) put_connection(out, c);
      for (const ChunkInfo& info : chunk_infos_) {
        bag_writer_detail::Fields h;
        h.op(0x06).u32("ver", 1).u64("chunk_pos", info.pos).time("start_time", info.start_ns)
            .time("end_time", info.end_ns).u32("count", static_cast<uint32_t>(info.counts.size()));
        std::vector<uint8_t> data;
        for (const auto& [conn, count] : info.counts) {
          bag_writer_detail::put32(data, conn);
          bag_writer_detail::put32(data, count);
        }
        bag_writer_detail::put_record(out, h, data.data(), data.size());
      }
      write(out.data(), out.size());
      if (std::fseek(file_.get(), 13, SEEK_SET) != 0) throw std::runtime_error("bag writer: cannot seek");
      write_bag_header(index_pos, static_cast<uint32_t>(connections_.size()),
                       static_cast<uint32_t>(chunk_infos_.size()));  // in place, over the first one
    }
    const bool ok = std::fclose(file_.release()) == 0;
    if (!ok) throw std::runtime_error("bag writer: cannot close the file");
  }

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
    void operator()(std::FILE* f) const { std::fclose(f); }
  };

  static inline const std::string kDepth = "/device_0/sensor_0/Depth_0";
  static inline const std::string kColor = "/device_0/sensor_1/Color_0";
  static constexpr const char* kImageMd5 = "060021388200f6f0f447d0fcd9c64743";
  static constexpr const char* kCameraInfoMd5 = "c9a58c1b0b154e0e6da7578cb991d214";
  static constexpr const char* kTransformMd5 = "ac9eff44abf714214112b05d54a3cf9b";

  void write(const uint8_t* data, size_t size) {
    if (std::fwrite(data, 1, size, file_.get()) != size) throw std::runtime_error("bag writer: write failed");
    position_ += size;
  }

  void write_bag_header(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count) {
    bag_writer_detail::Fields h;
    h.op(0x03).u64("index_pos", index_pos).u32("conn_count", conn_count).u32("chunk_count", chunk_count);
    // header_len + data_len = 4096: the data is padding (spaces).
    const std::vector<uint8_t> padding(4096 - 8 - h.bytes.size(), ' ');
    std::vector<uint8_t> out;
    bag_writer_detail::put_record(out, h, padding.data(), padding.size());
    write(out.data(), out.size());
  }

  uint32_t topic(const std::string& name, const char* type, const char* md5) {
    for (const Connection& c : connections_) {
      if (c.topic == name) return c.id;
    }
    connections_.push_back(Connection{static_cast<uint32_t>(connections_.size()), name, type, md5});
    return connections_.back().id;
  }

  void put_connection(std::vector<uint8_t>& out, const Connection& c) const {
    bag_writer_detail::Fields h;
    h.op(0x07).u32("conn", c.id).text("topic", c.topic);
    bag_writer_detail::Fields data;
    data.text("type", c.type).text("md5sum", c.md5).text("message_definition", "");
    bag_writer_detail::put_record(out, h, data.bytes.data(), data.bytes.size());
  }

  void put_message(uint32_t conn, int64_t time_ns, const std::vector<uint8_t>& message) {
    if (in_chunk_.count(conn) == 0) {
      put_connection(chunk_, connections_[conn]);  // a topic's connection precedes its first message
      in_chunk_.insert({conn, {}});
    }
    ChunkInfo& info = current_;
    if (info.counts.empty()) info.start_ns = time_ns;
    info.start_ns = std::min(info.start_ns, time_ns);
    info.end_ns = std::max(info.end_ns, time_ns);
    ++info.counts[conn];
    in_chunk_[conn].push_back({time_ns, static_cast<uint32_t>(chunk_.size())});
    bag_writer_detail::Fields h;
    h.op(0x02).u32("conn", conn).time("time", time_ns);
    bag_writer_detail::put_record(chunk_, h, message.data(), message.size());
    if (chunk_.size() > params_.chunk_bytes) flush_chunk();
  }

  void flush_chunk() {
    if (chunk_.empty()) return;
    std::vector<uint8_t> packed;
    const char* compression = "none";
    const std::vector<uint8_t>* data = &chunk_;
    if (params_.compression == BagCompression::lz4) {
      compression = "lz4";
      LZ4F_preferences_t prefs{};
      prefs.frameInfo.blockSizeID = LZ4F_max1MB;
      prefs.frameInfo.blockMode = LZ4F_blockIndependent;
      prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
      packed.resize(LZ4F_compressFrameBound(chunk_.size(), &prefs));
      const size_t n = LZ4F_compressFrame(packed.data(), packed.size(), chunk_.data(), chunk_.size(), &prefs);
      if (LZ4F_isError(n)) throw std::runtime_error(std::string("bag writer: lz4: ") + LZ4F_getErrorName(n));
      packed.resize(n);
      data = &packed;
    }
    current_.pos = position_;
    std::vector<uint8_t> out;
    bag_writer_detail::Fields h;
    h.op(0x05).text("compression", compression).u32("size", static_cast<uint32_t>(chunk_.size()));
    bag_writer_detail::put_record(out, h, data->data(), data->size());
    for (const auto& [conn, entries] : in_chunk_) {
      bag_writer_detail::Fields ih;
      ih.op(0x04).u32("ver", 1).u32("conn", conn).u32("count", static_cast<uint32_t>(entries.size()));
      std::vector<uint8_t> index;
      for (const auto& [time_ns, offset] : entries) {
        bag_writer_detail::put_time(index, time_ns);
        bag_writer_detail::put32(index, offset);
      }
      bag_writer_detail::put_record(out, ih, index.data(), index.size());
    }
    write(out.data(), out.size());
    chunk_infos_.push_back(current_);
    current_ = ChunkInfo{};
    chunk_.clear();
    in_chunk_.clear();
  }

  static std::vector<uint8_t> u32_message(uint32_t v) {
    std::vector<uint8_t> b;
    bag_writer_detail::put32(b, v);
    return b;
  }
  static std::vector<uint8_t> f32_message(float v) {
    std::vector<uint8_t> b;
    bag_writer_detail::put_f32(b, v);
    return b;
  }

  std::vector<uint8_t> image_message(int64_t stamp_ns, uint32_t seq, int width, int height, const std::string& encoding,
                                     const uint8_t* pixels, size_t step, float depth_units_m) const {
    using namespace bag_writer_detail;
    std::vector<uint8_t> b;
    b.reserve(64 + step * static_cast<size_t>(height));
    put32(b, seq);
    put_time(b, stamp_ns);
    put_string(b, params_.trailing_depth_units ? "1" : "");
    put32(b, static_cast<uint32_t>(height));
    put32(b, static_cast<uint32_t>(width));
    put_string(b, encoding);
    b.push_back(0);  // is_bigendian
    put32(b, static_cast<uint32_t>(step));
    put32(b, static_cast<uint32_t>(step * static_cast<size_t>(height)));
    b.insert(b.end(), pixels, pixels + step * static_cast<size_t>(height));
    if (params_.trailing_depth_units) put_f32(b, depth_units_m);
    return b;
  }

  static std::vector<uint8_t> camera_info_message(const Intrinsics& in) {
    using namespace bag_writer_detail;
    std::vector<uint8_t> b;
    put32(b, 0);  // header: seq, stamp, frame_id
    put_time(b, 0);
    put_string(b, "");
    put32(b, static_cast<uint32_t>(in.height));
    put32(b, static_cast<uint32_t>(in.width));
    put_string(b, std::string(distortion_name(in.model)));
    put32(b, 5);
    for (float c : in.coeffs) put_f64(b, c);
    const double k[9] = {in.fx, 0.0, in.ppx, 0.0, in.fy, in.ppy, 0.0, 0.0, 1.0};
    for (double v : k) put_f64(b, v);
    for (int i = 0; i < 9 + 12; ++i) put_f64(b, 0.0);  // R, P: the SDK leaves them zero
    put32(b, 0);                                      // binning_x, binning_y
    put32(b, 0);
    for (int i = 0; i < 4; ++i) put32(b, 0);  // roi
    b.push_back(0);
    return b;
  }

  static std::vector<uint8_t> transform_message(const Pose& T) {
    std::vector<uint8_t> b;
    const Eigen::Quaterniond q(T.linear());
    for (double v : {T.translation().x(), T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w()}) {
      bag_writer_detail::put_f64(b, v);
    }
    return b;
  }

  BagWriterParams params_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  uint64_t position_ = 0;
  std::vector<Connection> connections_;
  std::vector<ChunkInfo> chunk_infos_;
  ChunkInfo current_;
  std::vector<uint8_t> chunk_;  ///< the open chunk, uncompressed
  /// Index entries of the open chunk per connection: (time, offset in the chunk).
  std::map<uint32_t, std::vector<std::pair<int64_t, uint32_t>>> in_chunk_;
  bool depth_started_ = false;
  bool color_started_ = false;
};

}  // namespace hrcsense::test
