// SPDX-License-Identifier: Apache-2.0
// hrcsense — a RealSense .bag as a Source: the depth stream with its calibration and units.
#include "bag_messages.hpp"
#include "bag_reader.hpp"
#include "recorded_robot_state.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <cmath>
#include <cstring>
#include <map>
#include <memory>

namespace hrcsense {

/// Depth units when neither the image nor an option says (the SDK's default).
constexpr float kDefaultDepthUnitsM = 0.001F;
/// The rate of a bag that states none (no StreamInfo, e.g. a bag written without the SDK's
/// metadata): the D435's default depth rate.
constexpr double kDefaultFps = 30.0;
/// The rates a depth stream's StreamInfo may state: a D400 streams at most 300 frames/s; a
/// damaged 0 would divide by zero in pacing, a huge one would make every gap a skip.
constexpr uint32_t kMaxFps = 1000;

/// Everything BagSource knows while it plays a bag.
struct BagState {
  explicit BagState(const std::string& path) : reader(path) {}

  BagReader reader;
  std::map<uint32_t, bag::TopicRole> roles;  ///< by connection id, filled on first sight
  std::string depth_stream;                  ///< e.g. "Depth_0": the first depth stream seen
  std::string color_stream;                  ///< e.g. "Color_0"
  std::map<std::string, Intrinsics> intrinsics;  ///< by stream, from camera_info
  std::map<std::string, Pose> tf;            ///< by stream: T_stream_reference
  std::map<std::string, uint32_t> fps;       ///< by stream, from its StreamInfo (frames/s)
  float depth_units_option_m = 0.0F;         ///< last Depth_Units option; 0 before any
  float stereo_baseline_mm = 0.0F;
  int file_version = 0;
  // Counts over what has been read so far.
  RecordingStream depth_info{"depth", "", {}, 0, 0, 0, 0};
  RecordingStream color_info{"color", "", {}, 0, 0, 0, 0};
  ColorImage color;                          ///< the latest decoded colour frame
  bool have_color = false;
  /// RecordingParams::with_joint_states: the /hrcsense/joint_states read so far; null without.
  std::shared_ptr<RecordedRobotState> joint_states;
  // Playback.
  Frame pending;                             ///< the first frame, read while opening
  bool has_pending = false;
  int64_t played = 0;
  int64_t lap_offset_ns = 0;                 ///< added to timestamps when looping
  std::string error;

  const bag::TopicRole& role_of(uint32_t conn) {
    auto found = roles.find(conn);
    if (found != roles.end()) return found->second;
    const auto connection = reader.connections().find(conn);
    bag::TopicRole role;
    if (connection != reader.connections().end()) role = bag::classify_topic(connection->second.topic);
    return roles.emplace(conn, role).first->second;
  }
};

namespace {

[[noreturn]] void message_error(const BagState& s, const BagMessage& m, const std::string& problem) {
  const auto connection = s.reader.connections().find(m.conn);
  const std::string topic = connection == s.reader.connections().end() ? "?" : connection->second.topic;
  throw IoError(s.reader.path() + ": byte offset " + std::to_string(m.chunk_offset) + " (chunk): topic " + topic + ": " +
                problem);
}

float read_float_message(const BagState& s, const BagMessage& m) {
  bag::Cursor c{m.data, m.size};
  const auto value = c.get<float>();
  if (!c.ok) message_error(s, m, "Float32 message is cut off");
  return value;
}

void note_stream(RecordingStream& stream, const bag::ImageView& image, int64_t stamp_ns) {
  if (stream.frames == 0) stream.first_ns = stamp_ns;
  stream.last_ns = stamp_ns;
  stream.encoding = std::string(image.encoding);
  ++stream.frames;
}

/// Converts an rgb8 / bgr8 / rgba8 / bgra8 image into `out` (RGB).
void decode_color(const BagState& s, const BagMessage& m, const bag::ImageView& image, ColorImage& out) {
  const std::string_view enc = image.encoding;
  const size_t bpp = (enc == "rgb8" || enc == "bgr8") ? 3 : (enc == "rgba8" || enc == "bgra8") ? 4 : 0;
  if (bpp == 0) message_error(s, m, "colour encoding '" + std::string(enc) + "' is not supported");
  if (image.step < image.width * bpp) message_error(s, m, "colour step is smaller than a row");
  const bool bgr = enc[0] == 'b';
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgb.resize(static_cast<size_t>(image.width) * image.height * 3);
  uint8_t* dst = out.rgb.data();
  for (uint32_t v = 0; v < image.height; ++v) {
    const uint8_t* src = image.pixels + static_cast<size_t>(v) * image.step;
    for (uint32_t u = 0; u < image.width; ++u, src += bpp, dst += 3) {
      dst[0] = src[bgr ? 2 : 0];
      dst[1] = src[1];
      dst[2] = src[bgr ? 0 : 2];
    }
  }
}

/// Fills `out` from a depth image message. Throws IoError for anything inconsistent.
void decode_depth(BagState& s, const BagMessage& m, const bag::ImageView& image, Frame& out) {
  if (image.encoding != "mono16" && image.encoding != "16UC1" && image.encoding != "Z16") {
    message_error(s, m, "depth encoding '" + std::string(image.encoding) + "' is not 16-bit");
  }
  if (image.step < image.width * 2) message_error(s, m, "depth step is smaller than a row");
  const auto found = s.intrinsics.find(s.depth_stream);
  if (found == s.intrinsics.end()) message_error(s, m, "depth frame before the depth stream's camera_info");
  const Intrinsics& in = found->second;
  if (static_cast<uint32_t>(in.width) != image.width || static_cast<uint32_t>(in.height) != image.height) {
    message_error(s, m, "depth frame is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                            " but its camera_info says " + std::to_string(in.width) + "x" + std::to_string(in.height));
  }
  out.depth.resize(in.width, in.height);
  for (uint32_t v = 0; v < image.height; ++v) {
    std::memcpy(out.depth.pixels.data() + static_cast<size_t>(v) * image.width,
                image.pixels + static_cast<size_t>(v) * image.step, static_cast<size_t>(image.width) * 2);
  }
  // Units: the image's own field, else the last Depth_Units option, else the SDK default.
  float units_m = image.depth_units_m > 0.0F ? image.depth_units_m : s.depth_units_option_m;
  out.depth.depth_scale_m = units_m > 0.0F ? units_m : kDefaultDepthUnitsM;
  out.intrinsics = in;
  out.stereo_baseline_mm = s.stereo_baseline_mm;
  out.timestamp_ns = (image.stamp_ns != 0 ? image.stamp_ns : m.time_ns) + s.lap_offset_ns;
  out.truth.reset();
}

/// Hands a /hrcsense/joint_states message to s.joint_states, stamped on the playback's timeline
/// as the frames are; "" or what is wrong with it, naming the frame it comes before.
std::string read_joint_state(BagState& s, const BagMessage& m, const bag::Cursor& cursor) {
  bag::JointStateMessage joints;
  const std::string problem = bag::parse_joint_state(cursor, joints);
  if (!problem.empty()) return "before frame " + std::to_string(s.played) + ": " + problem;
  const int64_t stamp_ns = (joints.stamp_ns != 0 ? joints.stamp_ns : m.time_ns) + s.lap_offset_ns;
  s.joint_states->add(stamp_ns, joints.position_rad, joints.velocity_rad_s);
  return {};
}

/// Keeps a stream's stated rate; "" or what is wrong. Only depth streams must state a usable
/// rate (it paces the replay); the others' rates are kept as they are.
std::string read_stream_info(BagState& s, const bag::TopicRole& role, const bag::Cursor& cursor) {
  bag::StreamInfoMessage info;
  std::string problem = bag::parse_stream_info(cursor, info);
  if (!problem.empty()) return problem;
  if (role.stream.rfind("Depth_", 0) == 0 && (info.fps == 0 || info.fps > kMaxFps)) {
    return "StreamInfo field fps is " + std::to_string(info.fps) + ", not a frame rate (1 to " +
           std::to_string(kMaxFps) + " frames/s)";
  }
  s.fps[role.stream] = info.fps;
  return {};
}

/// The depth stream's stated rate, else kDefaultFps.
double depth_fps(const BagState& s) {
  const auto found = s.fps.find(s.depth_stream);
  return found == s.fps.end() ? kDefaultFps : static_cast<double>(found->second);
}

/// Handles messages until one depth frame has been decoded into `out` (true) or the bag ends
/// (false). Colour frames are decoded only when `with_color`. Throws IoError on damage.
bool read_depth_frame(BagState& s, bool with_color, Frame& out) {
  BagMessage m;
  while (s.reader.next(m)) {
    const bag::TopicRole& role = s.role_of(m.conn);
    const bag::Cursor cursor{m.data, m.size};
    std::string problem;
    switch (role.role) {
      case bag::Role::other:
        break;
      case bag::Role::file_version: {
        bag::Cursor c = cursor;
        s.file_version = static_cast<int>(c.get<uint32_t>());
        break;
      }
      case bag::Role::depth_units:
        s.depth_units_option_m = read_float_message(s, m);
        break;
      case bag::Role::stereo_baseline:
        s.stereo_baseline_mm = read_float_message(s, m);
        break;
      case bag::Role::camera_info:
        problem = bag::parse_camera_info(cursor, s.intrinsics[role.stream]);
        break;
      case bag::Role::stream_info:
        problem = read_stream_info(s, role, cursor);
        break;
      case bag::Role::tf:
        problem = bag::parse_transform(cursor, s.tf[role.stream]);
        break;
      case bag::Role::joint_states:
        if (s.joint_states) problem = read_joint_state(s, m, cursor);
        break;
      case bag::Role::image: {
        bag::ImageView image;
        problem = bag::parse_image(cursor, image);
        if (!problem.empty()) break;
        const int64_t stamp_ns = image.stamp_ns != 0 ? image.stamp_ns : m.time_ns;
        if (s.depth_stream.empty() && role.stream.rfind("Depth_", 0) == 0) s.depth_stream = role.stream;
        if (s.color_stream.empty() && role.stream.rfind("Color_", 0) == 0) s.color_stream = role.stream;
        if (role.stream == s.depth_stream) {
          decode_depth(s, m, image, out);
          note_stream(s.depth_info, image, stamp_ns);
          return true;
        }
        if (role.stream == s.color_stream) {
          note_stream(s.color_info, image, stamp_ns);
          if (with_color) {
            decode_color(s, m, image, s.color);
            s.have_color = true;
          }
        }
        break;
      }
    }
    if (!problem.empty()) message_error(s, m, problem);
  }
  return false;
}

/// The colour stream's intrinsics and the depth → colour extrinsics, as far as the bag has them.
void set_color_calibration(const BagState& s, Frame& out) {
  const auto color_in = s.intrinsics.find(s.color_stream);
  out.color_intrinsics = color_in == s.intrinsics.end() ? Intrinsics{} : color_in->second;
  const auto depth_tf = s.tf.find(s.depth_stream);
  const auto color_tf = s.tf.find(s.color_stream);
  if (depth_tf == s.tf.end() || color_tf == s.tf.end()) {
    out.depth_to_color.reset();
    return;
  }
  // Both tfs are given from the group's reference stream: E_depth→color = E_color ∘ E_depth⁻¹.
  const Pose T_color_depth = color_tf->second * depth_tf->second.inverse();
  Extrinsics e;
  for (int i = 0; i < 3; ++i) {
    e.translation_m[static_cast<size_t>(i)] = static_cast<float>(T_color_depth.translation()(i));
    for (int j = 0; j < 3; ++j) e.rotation[static_cast<size_t>(3 * j + i)] = static_cast<float>(T_color_depth.linear()(i, j));
  }
  out.depth_to_color = e;
}

}  // namespace

BagSource::BagSource(RecordingParams params) : params_(std::move(params)), state_(std::make_unique<BagState>(params_.path)) {
  if (params_.with_joint_states) state_->joint_states = std::make_shared<RecordedRobotState>(params_.path);
  // Chunks holding only images nobody asked for (colour without with_color, infrared), or
  // joint states without with_joint_states, are not even decompressed: the SDK writes one chunk per large frame, so this halves the work.
  state_->reader.set_wanted([with_color = params_.with_color, with_joints = params_.with_joint_states](
                                const BagConnection& connection) {
    const bag::TopicRole role = bag::classify_topic(connection.topic);
    if (role.role == bag::Role::joint_states) return with_joints;
    if (role.role != bag::Role::image) return true;
    return role.stream.rfind("Depth_", 0) == 0 || (with_color && role.stream.rfind("Color_", 0) == 0);
  });
  // The first frame is read now so that info() can report the depth intrinsics.
  if (!read_depth_frame(*state_, params_.with_color, state_->pending)) {
    throw IoError(params_.path + ": no depth frames (topic /device_0/sensor_<s>/Depth_<i>/image/data)");
  }
  state_->has_pending = true;
}

BagSource::~BagSource() = default;

SourceInfo BagSource::info() const {
  const BagState& s = *state_;
  SourceInfo info;
  info.type = "bag";
  info.description = params_.path + " (" + s.depth_stream + ", " +
                     (s.reader.indexed() ? "indexed" : "not indexed: " + s.reader.index_problem()) + ")";
  info.intrinsics = s.pending.intrinsics.width > 0 ? s.pending.intrinsics : s.intrinsics.at(s.depth_stream);
  info.stereo_baseline_mm = s.stereo_baseline_mm > 0.0F ? s.stereo_baseline_mm : params_.stereo_baseline_mm;
  info.nominal_fps = depth_fps(s);  // the rate the bag states, which pacing and the watchdog count in
  info.frame_count = -1;
  if (s.reader.indexed() && !params_.loop) {
    for (const auto& [id, connection] : s.reader.connections()) {
      if (bag::classify_topic(connection.topic).stream == s.depth_stream &&
          bag::classify_topic(connection.topic).role == bag::Role::image) {
        const auto count = s.reader.indexed_counts().find(id);
        info.frame_count = count == s.reader.indexed_counts().end() ? 0 : static_cast<int64_t>(count->second);
      }
    }
  }
  return info;
}

std::string BagSource::error() const { return state_->error; }

Source::Status BagSource::next(Frame& out) {
  BagState& s = *state_;
  if (!s.error.empty()) return Status::error;
  try {
    if (s.has_pending) {
      std::swap(out, s.pending);
      s.has_pending = false;
    } else if (!read_depth_frame(s, params_.with_color, out)) {
      if (!params_.loop) return Status::end;
      // Each lap starts one nominal period (of the bag's stated rate) after the last frame of the
      // previous one.
      s.lap_offset_ns += s.depth_info.last_ns - s.depth_info.first_ns + std::llround(1e9 / depth_fps(s));
      s.reader.rewind();
      if (!read_depth_frame(s, params_.with_color, out)) return Status::end;
    }
  } catch (const IoError& e) {
    s.error = e.what();
    return Status::error;
  }
  if (params_.stereo_baseline_mm > 0.0F && out.stereo_baseline_mm <= 0.0F) out.stereo_baseline_mm = params_.stereo_baseline_mm;
  if (s.have_color) {
    out.color = s.color;
    set_color_calibration(s, out);
  } else {
    out.color.reset();
    out.color_intrinsics = Intrinsics{};
    out.depth_to_color.reset();
  }
  out.index = s.played++;
  if (s.joint_states) s.joint_states->frame_delivered(out.timestamp_ns);
  return Status::frame;
}

std::unique_ptr<RobotStateSource> BagSource::recorded_robot_state() const {
  const BagState& s = *state_;
  if (!s.joint_states) return nullptr;
  // Indexed: every connection is known at open; scanned: those before the first depth frame,
  // where a recording made by hrcsense has its first joint state.
  for (const auto& [id, connection] : s.reader.connections()) {
    if (connection.topic == bag::kJointStatesTopic) return share_recorded_robot_state(s.joint_states);
  }
  return nullptr;
}

/// Reads a whole bag for `summarize_recording`.
RecordingSummary summarize_bag(const std::string& path) {
  BagState s(path);
  RecordingSummary summary;
  summary.path = path;
  summary.format = RecordingFormat::bag;
  Frame frame;
  try {
    while (read_depth_frame(s, false, frame)) {
    }
  } catch (const IoError& e) {
    summary.damage = e.what();
  }
  if (s.depth_info.frames == 0 && summary.damage.empty()) throw IoError(path + ": no depth frames");
  summary.compression = s.reader.compressions();
  summary.indexed = s.reader.indexed();
  summary.file_version = s.file_version;
  summary.stereo_baseline_mm = s.stereo_baseline_mm;
  summary.depth_units_m = s.depth_units_option_m > 0.0F ? s.depth_units_option_m : kDefaultDepthUnitsM;
  if (s.depth_info.frames > 0) summary.depth_units_m = frame.depth.depth_scale_m;
  s.depth_info.intrinsics = s.intrinsics[s.depth_stream];
  if (s.fps.count(s.depth_stream) != 0) s.depth_info.fps = s.fps.at(s.depth_stream);
  summary.streams.push_back(s.depth_info);
  if (!s.color_stream.empty()) {
    s.color_info.intrinsics = s.intrinsics[s.color_stream];
    if (s.fps.count(s.color_stream) != 0) s.color_info.fps = s.fps.at(s.color_stream);
    summary.streams.push_back(s.color_info);
    const auto depth_tf = s.tf.find(s.depth_stream);
    const auto color_tf = s.tf.find(s.color_stream);
    if (depth_tf != s.tf.end() && color_tf != s.tf.end()) {
      // Both are given from the group's reference stream: E_depth→color = E_color ∘ E_depth⁻¹.
      summary.T_color_depth = color_tf->second * depth_tf->second.inverse();
    }
  }
  return summary;
}

}  // namespace hrcsense
