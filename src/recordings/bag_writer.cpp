// SPDX-License-Identifier: Apache-2.0
// hrcsense — the RealSense .bag writer (ROS bag 2.0, ../shared/specs/realsense-bag-format.md).
#include "hrcsense/recordings/bag_writer.hpp"

#include "hrcsense/camera.hpp"

#include "bag_writer_messages.hpp"

#include <lz4frame.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace hrcsense {
namespace {

using bag_write::camera_info_message;
using bag_write::extrinsics_pose;
using bag_write::f32_message;
using bag_write::key_value_message;
using bag_write::put32;
using bag_write::put64;
using bag_write::put_f32;
using bag_write::put_f64;
using bag_write::put_string;
using bag_write::put_time;
using bag_write::stream_info_message;
using bag_write::string_message;
using bag_write::transform_message;
using bag_write::u32_message;

// Message MD5 sums the SDK writes (spec §3); JointState's is the ROS message's.
constexpr const char* kImageMd5 = "060021388200f6f0f447d0fcd9c64743";
constexpr const char* kCameraInfoMd5 = "c9a58c1b0b154e0e6da7578cb991d214";
constexpr const char* kTransformMd5 = "ac9eff44abf714214112b05d54a3cf9b";
constexpr const char* kKeyValueMd5 = "cf57fdc6617a881a88c16e768132149c";
constexpr const char* kStreamInfoMd5 = "311d7e24eac31bb87271d041bf70ff7d";
constexpr const char* kFloat32Md5 = "73fcbf46b49191e672908e50842a83d4";
constexpr const char* kUInt32Md5 = "304a39449588c7f8ce2df6e8001c5fce";
constexpr const char* kStringMd5 = "992ce8a1687cec8c8bd883ec73ca41d1";
constexpr const char* kJointStateMd5 = "3066dcd76a6cfaef579bd0f34173e9fd";

const std::string kDepthStream = "/device_0/sensor_0/Depth_0";
const std::string kColorStream = "/device_0/sensor_1/Color_0";
constexpr const char* kJointStatesTopic = "/hrcsense/joint_states";

// Static messages sit at ROS time (0 s, 1 ns), the smallest valid bag time; streams from 2 ns.
constexpr int64_t kStaticTimeNs = 1;
constexpr int64_t kFirstStreamTimeNs = 2;
constexpr size_t kBagHeaderBytes = 4096;  // header + data of the bag header record
constexpr char kBagMagic[] = "#ROSBAG V2.0\n";

// A record header under construction: `name=value` fields with uint32 length prefixes.
struct Fields {
  std::vector<uint8_t> bytes;
  Fields& raw(const std::string& name, const uint8_t* value, size_t size) {
    put32(bytes, static_cast<uint32_t>(name.size() + 1 + size));
    bytes.insert(bytes.end(), name.begin(), name.end());
    bytes.push_back('=');
    bytes.insert(bytes.end(), value, value + size);
    return *this;
  }
  Fields& op(uint8_t v) { return raw("op", &v, 1); }
  Fields& u32(const std::string& name, uint32_t v) {
    std::vector<uint8_t> b;
    put32(b, v);
    return raw(name, b.data(), b.size());
  }
  Fields& u64(const std::string& name, uint64_t v) {
    std::vector<uint8_t> b;
    put64(b, v);
    return raw(name, b.data(), b.size());
  }
  Fields& time(const std::string& name, int64_t ns) {
    std::vector<uint8_t> b;
    put_time(b, ns);
    return raw(name, b.data(), b.size());
  }
  Fields& text(const std::string& name, const std::string& v) {
    return raw(name, reinterpret_cast<const uint8_t*>(v.data()), v.size());
  }
};

// Record = uint32 header_len, header, uint32 data_len, data.
void put_record(std::vector<uint8_t>& out, const Fields& header, const uint8_t* data, size_t size) {
  put32(out, static_cast<uint32_t>(header.bytes.size()));
  out.insert(out.end(), header.bytes.begin(), header.bytes.end());
  put32(out, static_cast<uint32_t>(size));
  out.insert(out.end(), data, data + size);
}

void put_connection(std::vector<uint8_t>& out, uint32_t id, const std::string& topic, const std::string& type,
                    const std::string& md5) {
  Fields h;
  h.op(0x07).u32("conn", id).text("topic", topic);
  Fields data;
  // No message definitions: the SDK's playback checks type and md5 only.
  data.text("type", type).text("md5sum", md5).text("message_definition", "");
  put_record(out, h, data.bytes.data(), data.bytes.size());
}

}  // namespace

bool color_recordable(const Frame& frame) {
  // A colour stream needs its camera_info: without one the SDK cannot play it, and hrcsense's
  // reader refuses a camera_info with a zero focal length.
  return frame.color && frame.color->width > 0 && frame.color_intrinsics.width == frame.color->width &&
         frame.color_intrinsics.height == frame.color->height && frame.color_intrinsics.fx > 0.0F &&
         frame.color_intrinsics.fy > 0.0F;
}

void BagWriter::FileCloser::operator()(std::FILE* file) const { std::fclose(file); }
void BagWriter::Lz4Freer::operator()(LZ4F_cctx_s* context) const { LZ4F_freeCompressionContext(context); }

BagWriter::BagWriter(std::string path, BagWriterParams params) : path_(std::move(path)), params_(params) {
  file_.reset(std::fopen(path_.c_str(), "wb"));
  if (!file_) throw BagWriteError(path_ + ": cannot create: " + std::strerror(errno));
  // Large chunks go out in one fwrite each; a small stdio buffer is enough.
  write(reinterpret_cast<const uint8_t*>(kBagMagic), sizeof kBagMagic - 1);
  write_bag_header(0, 0, 0);  // index_pos 0 until close(): an unclosed bag says so
  write_static_info();
}

BagWriter::~BagWriter() {
  try {
    close();
  } catch (const BagWriteError&) {  // a destructor must not throw; callers that care call close()
  }
}

void BagWriter::write(const uint8_t* data, size_t size) {
  if (std::fwrite(data, 1, size, file_.get()) != size) {
    const int error = errno;
    throw BagWriteError(path_ + ": write failed at byte " + std::to_string(position_) + ": " + std::strerror(error));
  }
  position_ += size;
}

void BagWriter::write_bag_header(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count) {
  Fields h;
  h.op(0x03).u64("index_pos", index_pos).u32("conn_count", conn_count).u32("chunk_count", chunk_count);
  const std::vector<uint8_t> padding(kBagHeaderBytes - 8 - h.bytes.size(), ' ');
  std::vector<uint8_t> out;
  put_record(out, h, padding.data(), padding.size());
  write(out.data(), out.size());
}

void BagWriter::write_static_info() {
  put_message(topic("/file_version", "std_msgs/UInt32", kUInt32Md5), kStaticTimeNs, u32_message(params_.file_version));
  if (params_.sdk_metadata) {
    // The device as a D435 (the streams' layout is the D435's); the SDK's playback builds its
    // device and sensors from these.
    const uint32_t device = topic("/device_0/info", "diagnostic_msgs/KeyValue", kKeyValueMd5);
    for (const auto& [key, value] : {std::pair<const char*, const char*>{"Name", "Intel RealSense D435"},
                                     {"Serial Number", "000000000000"},
                                     {"Firmware Version", "0.0.0.0"},
                                     {"Product Id", "0B07"},
                                     {"Product Line", "D400"},
                                     {"Recommended Firmware Version", "0.0.0.0"},
                                     {"Usb Type Descriptor", "3.2"}}) {
      put_key_value(device, kStaticTimeNs, key, value);
    }
    put_key_value(topic("/device_0/sensor_0/info", "diagnostic_msgs/KeyValue", kKeyValueMd5), kStaticTimeNs, "Name",
                  "Stereo Module");
    put_key_value(topic("/device_0/sensor_1/info", "diagnostic_msgs/KeyValue", kKeyValueMd5), kStaticTimeNs, "Name",
                  "RGB Camera");
  }
  if (params_.depth_units_option_m > 0.0F) {
    put_option("Depth_Units", params_.depth_units_option_m, "Metres per raw depth unit of the depth image");
  }
  if (params_.stereo_baseline_mm > 0.0F) {
    put_option("Stereo_Baseline", params_.stereo_baseline_mm, "Distance between the two infrared imagers, in mm");
  }
}

void BagWriter::put_option(const std::string& name, float value, const std::string& description) {
  const std::string option = "/device_0/sensor_0/option/" + name;
  put_message(topic(option + "/value", "std_msgs/Float32", kFloat32Md5), kStaticTimeNs, f32_message(value));
  // The SDK's playback reads every option's description beside its value and logs an error
  // for each one missing (its viewer then shows "N/A"): always write both (spec §3).
  put_message(topic(option + "/description", "std_msgs/String", kStringMd5), kStaticTimeNs,
              string_message(description));
}

uint32_t BagWriter::topic(const std::string& name, const char* type, const char* md5) {
  for (const Connection& c : connections_) {
    if (c.topic == name) return c.id;
  }
  connections_.push_back(Connection{static_cast<uint32_t>(connections_.size()), name, type, md5});
  return connections_.back().id;
}

// Opens a message data record in the chunk; its body is appended to chunk_, then end_message()
// fills in the length (so that an 800 KB image is copied once, straight into the chunk).
void BagWriter::begin_message(uint32_t conn, int64_t time_ns) {
  if (in_chunk_.count(conn) == 0) {
    const Connection& c = connections_[conn];
    put_connection(chunk_, c.id, c.topic, c.type, c.md5);  // a topic's connection precedes its messages
    in_chunk_.insert({conn, {}});
  }
  if (current_.counts.empty()) current_.start_ns = time_ns;
  current_.start_ns = std::min(current_.start_ns, time_ns);
  current_.end_ns = std::max(current_.end_ns, time_ns);
  ++current_.counts[conn];
  in_chunk_[conn].push_back({time_ns, static_cast<uint32_t>(chunk_.size())});
  Fields h;
  h.op(0x02).u32("conn", conn).time("time", time_ns);
  put32(chunk_, static_cast<uint32_t>(h.bytes.size()));
  chunk_.insert(chunk_.end(), h.bytes.begin(), h.bytes.end());
  message_start_ = chunk_.size();
  put32(chunk_, 0);  // data_len, patched by end_message()
}

void BagWriter::end_message() {
  const auto size = static_cast<uint32_t>(chunk_.size() - message_start_ - 4);
  for (int i = 0; i < 4; ++i) chunk_[message_start_ + static_cast<size_t>(i)] = static_cast<uint8_t>(size >> (8 * i));
}

void BagWriter::put_message(uint32_t conn, int64_t time_ns, const std::vector<uint8_t>& message) {
  begin_message(conn, time_ns);
  chunk_.insert(chunk_.end(), message.begin(), message.end());
  end_message();
  if (chunk_.size() > params_.chunk_bytes) flush_chunk();
}

void BagWriter::put_key_value(uint32_t conn, int64_t time_ns, const std::string& key, const std::string& value) {
  put_message(conn, time_ns, key_value_message(key, value));
}

int64_t BagWriter::bag_time(int64_t timestamp_ns) {
  if (!have_first_time_) {
    first_timestamp_ns_ = timestamp_ns;
    have_first_time_ = true;
  }
  return kFirstStreamTimeNs + std::max<int64_t>(timestamp_ns - first_timestamp_ns_, 0);
}

void BagWriter::start_stream(const std::string& stream, const char* encoding, const Intrinsics& intrinsics,
                             const Pose& T_stream_ref) {
  if (params_.sdk_metadata) {
    put_message(topic(stream + "/info", "realsense_msgs/StreamInfo", kStreamInfoMd5), kStaticTimeNs,
                stream_info_message(params_.fps, encoding));
  }
  put_message(topic(stream + "/info/camera_info", "sensor_msgs/CameraInfo", kCameraInfoMd5), kStaticTimeNs,
              camera_info_message(intrinsics));
  put_message(topic(stream + "/tf/0", "geometry_msgs/Transform", kTransformMd5), kStaticTimeNs,
              transform_message(T_stream_ref));
}

void BagWriter::put_image(const std::string& stream, int64_t timestamp_ns, uint32_t seq, int width, int height,
                          const char* encoding, const uint8_t* pixels, size_t step, float depth_units_m) {
  const int64_t time_ns = bag_time(timestamp_ns);
  const size_t bytes = step * static_cast<size_t>(height);
  begin_message(topic(stream + "/image/data", "sensor_msgs/Image", kImageMd5), time_ns);
  put32(chunk_, seq);
  put_time(chunk_, timestamp_ns);
  put_string(chunk_, params_.trailing_depth_units ? "1" : "");
  put32(chunk_, static_cast<uint32_t>(height));
  put32(chunk_, static_cast<uint32_t>(width));
  put_string(chunk_, encoding);
  chunk_.push_back(0);  // is_bigendian
  put32(chunk_, static_cast<uint32_t>(step));
  put32(chunk_, static_cast<uint32_t>(bytes));
  chunk_.insert(chunk_.end(), pixels, pixels + bytes);
  if (params_.trailing_depth_units) put_f32(chunk_, depth_units_m);
  end_message();
  if (params_.sdk_metadata) {
    // Several KeyValue messages at the frame's time, in the frame's chunk (spec §3); values are
    // decimal strings, the frame timestamp in milliseconds.
    const uint32_t meta = topic(stream + "/image/metadata", "diagnostic_msgs/KeyValue", kKeyValueMd5);
    char stamp_ms[32];
    std::snprintf(stamp_ms, sizeof stamp_ms, "%.6f", static_cast<double>(timestamp_ns) / 1e6);
    const std::pair<const char*, std::string> items[] = {{"system_time", stamp_ms},
                                                         {"timestamp_domain", "System Time"},
                                                         {"Frame Counter", std::to_string(seq)},
                                                         {"Frame Timestamp", stamp_ms}};
    for (const auto& [key, value] : items) {
      begin_message(meta, time_ns);
      const std::vector<uint8_t> body = key_value_message(key, value);
      chunk_.insert(chunk_.end(), body.begin(), body.end());
      end_message();
    }
  }
  if (chunk_.size() > params_.chunk_bytes) flush_chunk();
}

void BagWriter::add_depth(const Frame& frame) {
  const DepthImage& d = frame.depth;
  // The image is read through width × height: a mismatched buffer would be read past its end.
  if (d.width <= 0 || d.height <= 0 || d.pixels.size() != static_cast<size_t>(d.width) * static_cast<size_t>(d.height)) {
    throw BagWriteError(path_ + ": frame " + std::to_string(frame.index) + ": depth image of " + std::to_string(d.width) +
                        "x" + std::to_string(d.height) + " px holds " + std::to_string(d.pixels.size()) + " pixels");
  }
  if (!depth_started_) {
    start_stream(kDepthStream, "mono16", frame.intrinsics, Pose::Identity());  // depth: group 0's reference
    depth_started_ = true;
  }
  put_image(kDepthStream, frame.timestamp_ns, static_cast<uint32_t>(frame.index), d.width, d.height, "mono16",
            reinterpret_cast<const uint8_t*>(d.pixels.data()), static_cast<size_t>(d.width) * 2, d.depth_scale_m);
}

void BagWriter::add_color(int64_t timestamp_ns, uint32_t frame_number, const ColorImage& color,
                          const Intrinsics& intrinsics, const Pose& T_color_depth) {
  if (color.width <= 0 || color.height <= 0 ||
      color.rgb.size() != static_cast<size_t>(color.width) * static_cast<size_t>(color.height) * 3) {
    throw BagWriteError(path_ + ": colour image of " + std::to_string(color.width) + "x" + std::to_string(color.height) +
                        " px holds " + std::to_string(color.rgb.size()) + " bytes, not 3 per pixel");
  }
  if (!color_started_) {
    start_stream(kColorStream, "rgb8", intrinsics, T_color_depth);
    color_started_ = true;
  }
  put_image(kColorStream, timestamp_ns, frame_number, color.width, color.height, "rgb8", color.rgb.data(),
            static_cast<size_t>(color.width) * 3, 0.0F);
}

void BagWriter::add_frame(const Frame& frame, const RobotState* robot_state) {
  // Colour and joints first: a reader that pairs each depth frame with the latest colour frame
  // and joint state in file order (hrcsense's BagSource) then gets this frame's own. The joints
  // after the colour keep an SDK-sized colour image in a chunk of its own, which a reader that
  // wants no colour skips undecompressed.
  if (color_recordable(frame)) {
    const Pose T_color_depth = frame.depth_to_color ? extrinsics_pose(*frame.depth_to_color) : Pose::Identity();
    // The depth frame's number: a frame's colour and depth images are one capture.
    add_color(frame.timestamp_ns, static_cast<uint32_t>(frame.index), *frame.color, frame.color_intrinsics,
              T_color_depth);
  }
  if (robot_state != nullptr) add_joint_state(frame.timestamp_ns, robot_state->q_rad, robot_state->qd_rad_s);
  add_depth(frame);
}

void BagWriter::add_joint_state(int64_t timestamp_ns, const JointAngles& position_rad,
                                const std::optional<JointAngles>& velocity_rad_s) {
  std::vector<uint8_t> b;
  put32(b, 0);  // header: seq, stamp, frame_id
  put_time(b, timestamp_ns);
  put_string(b, "");
  const bool named = params_.joint_names.size() == position_rad.size();
  put32(b, static_cast<uint32_t>(position_rad.size()));  // name[]
  for (size_t i = 0; i < position_rad.size(); ++i) {
    put_string(b, named ? params_.joint_names[i] : "joint_" + std::to_string(i));
  }
  put32(b, static_cast<uint32_t>(position_rad.size()));  // position[]
  for (double q : position_rad) put_f64(b, q);
  put32(b, velocity_rad_s ? static_cast<uint32_t>(velocity_rad_s->size()) : 0U);  // velocity[]
  if (velocity_rad_s) {
    for (double qd : *velocity_rad_s) put_f64(b, qd);
  }
  put32(b, 0);  // effort[]: not known
  put_message(topic(kJointStatesTopic, "sensor_msgs/JointState", kJointStateMd5), bag_time(timestamp_ns), b);
}

void BagWriter::flush_chunk() {
  if (chunk_.empty()) return;
  const char* compression = "none";
  const uint8_t* data = chunk_.data();
  size_t size = chunk_.size();
  if (params_.compression == BagCompression::lz4) {
    compression = "lz4";
    size = compress_chunk_lz4();
    data = packed_.data();
  }
  current_.pos = position_;
  std::vector<uint8_t> head;
  Fields h;
  h.op(0x05).text("compression", compression).u32("size", static_cast<uint32_t>(chunk_.size()));
  put32(head, static_cast<uint32_t>(h.bytes.size()));
  head.insert(head.end(), h.bytes.begin(), h.bytes.end());
  put32(head, static_cast<uint32_t>(size));
  write(head.data(), head.size());
  write(data, size);
  write_chunk_index();
  // A killed recorder leaves every closed chunk in the file (the kernel has it after fflush).
  if (std::fflush(file_.get()) != 0) {
    throw BagWriteError(path_ + ": write failed at byte " + std::to_string(position_) + ": " + std::strerror(errno));
  }
  chunk_infos_.push_back(current_);
  current_ = ChunkInfo{};
  chunk_.clear();
  in_chunk_.clear();
}

// One LZ4 frame as roslz4 writes it (spec §2): 1 MiB independent blocks, content checksum.
size_t BagWriter::compress_chunk_lz4() {
  LZ4F_preferences_t prefs{};
  prefs.frameInfo.blockSizeID = LZ4F_max1MB;
  prefs.frameInfo.blockMode = LZ4F_blockIndependent;
  prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
  prefs.autoFlush = 1;  // every block goes out in compressUpdate: End only adds the checksum
  if (!lz4_) {
    LZ4F_cctx* context = nullptr;
    const size_t made = LZ4F_createCompressionContext(&context, LZ4F_VERSION);
    if (LZ4F_isError(made)) throw BagWriteError(path_ + ": lz4: " + LZ4F_getErrorName(made));
    lz4_.reset(context);
  }
  packed_.resize(LZ4F_compressFrameBound(chunk_.size(), &prefs));
  const auto check = [this](size_t made) {
    if (LZ4F_isError(made)) throw BagWriteError(path_ + ": lz4 compression failed: " + LZ4F_getErrorName(made));
    return made;
  };
  uint8_t* out = packed_.data();
  const size_t room = packed_.size();
  size_t n = check(LZ4F_compressBegin(lz4_.get(), out, room, &prefs));
  n += check(LZ4F_compressUpdate(lz4_.get(), out + n, room - n, chunk_.data(), chunk_.size(), nullptr));
  n += check(LZ4F_compressEnd(lz4_.get(), out + n, room - n, nullptr));
  return n;
}

// The index data records after a chunk: per connection, each message's time and offset in it.
void BagWriter::write_chunk_index() {
  std::vector<uint8_t> index;
  for (const auto& [conn, entries] : in_chunk_) {
    Fields ih;
    ih.op(0x04).u32("ver", 1).u32("conn", conn).u32("count", static_cast<uint32_t>(entries.size()));
    std::vector<uint8_t> body;
    for (const auto& [time_ns, offset] : entries) {
      put_time(body, time_ns);
      put32(body, offset);
    }
    put_record(index, ih, body.data(), body.size());
  }
  write(index.data(), index.size());
}

void BagWriter::close() {
  if (!file_) return;
  // A failure on the way still closes the file (once); the error goes to the caller.
  std::unique_ptr<std::FILE, FileCloser> closing;
  try {
    flush_chunk();
    if (params_.write_index) {
      const uint64_t index_pos = position_;
      std::vector<uint8_t> out;
      for (const Connection& c : connections_) put_connection(out, c.id, c.topic, c.type, c.md5);
      for (const ChunkInfo& info : chunk_infos_) {
        Fields h;
        h.op(0x06).u32("ver", 1).u64("chunk_pos", info.pos).time("start_time", info.start_ns)
            .time("end_time", info.end_ns).u32("count", static_cast<uint32_t>(info.counts.size()));
        std::vector<uint8_t> body;
        for (const auto& [conn, count] : info.counts) {
          put32(body, conn);
          put32(body, count);
        }
        put_record(out, h, body.data(), body.size());
      }
      write(out.data(), out.size());
      const uint64_t end = position_;
      if (std::fseek(file_.get(), static_cast<long>(sizeof kBagMagic - 1), SEEK_SET) != 0) {
        throw BagWriteError(path_ + ": cannot seek to the bag header: " + std::strerror(errno));
      }
      write_bag_header(index_pos, static_cast<uint32_t>(connections_.size()),
                       static_cast<uint32_t>(chunk_infos_.size()));  // in place, over the first one
      position_ = end;
    }
  } catch (const BagWriteError&) {
    closing.reset(file_.release());
    throw;
  }
  if (std::fclose(file_.release()) != 0) throw BagWriteError(path_ + ": cannot close: " + std::strerror(errno));
}

}  // namespace hrcsense
