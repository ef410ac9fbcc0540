// SPDX-License-Identifier: Apache-2.0
// Recording (issue C2 part 3): the simulator's depth + colour recorded through the Recorder and
// read back by hrcsense's own reader frame for frame against a second, identical simulator; the
// records the spec lists for SDK playback; joint states; split files; write errors and drops
// (record_cli_test.cpp runs the commands). Needs no ../shared data.
#include "../support/scenes.hpp"
#include "recordings_test_util.hpp"

#include "common/assembly.hpp"
#include "hrcsense/recordings/bag_writer.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recorder.hpp"
#include "hrcsense/recordings/recordings.hpp"
#include "src/recordings/bag_reader.hpp"

#include "../support/sanitized.hpp"

#include <gtest/gtest.h>


#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <thread>

namespace hrcsense {
namespace {

using test::scene_path;

namespace fs = std::filesystem;
using test::ScratchDir;

// 300 frames (10 s of the cell); under the sanitizers, whose simulator renders each frame several
// times slower, 60 (the chunks, the index and the colour stream are the same code either way).
constexpr int kRoundTripFrames = test::kSanitized ? 60 : 300;
constexpr int kPushWaitMs = 10000;

/// The colour simulator of config/cell-ur5.yaml (848x480 depth + colour), `frames` long.
std::unique_ptr<Source> cell_source(int frames, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> sets = {"sim.frames=" + std::to_string(frames)};
  sets.insert(sets.end(), extra.begin(), extra.end());
  return make_source(load_config(scene_path("cell-ur5.yaml"), sets));
}

RecorderParams recorder_params(const std::string& path) {
  RecorderParams params;
  params.path = path;
  params.queue_frames = 4;
  return params;
}

/// Records `frames` frames of the cell to `path`; the recorder's stats.
RecorderStats record_cell(const RecorderParams& params, int frames, const std::vector<std::string>& extra = {}) {
  std::unique_ptr<Source> source = cell_source(frames, extra);
  Recorder recorder(params);
  Frame frame;
  for (int i = 0; i < frames && source->next(frame) == Source::Status::frame; ++i) {
    EXPECT_TRUE(recorder.push_wait(frame, kPushWaitMs)) << "frame " << i;
  }
  return recorder.close();
}

void expect_same_intrinsics(const Intrinsics& got, const Intrinsics& want, const std::string& what) {
  EXPECT_EQ(got.width, want.width) << what;
  EXPECT_EQ(got.height, want.height) << what;
  EXPECT_FLOAT_EQ(got.fx, want.fx) << what;
  EXPECT_FLOAT_EQ(got.fy, want.fy) << what;
  EXPECT_FLOAT_EQ(got.ppx, want.ppx) << what;
  EXPECT_FLOAT_EQ(got.ppy, want.ppy) << what;
  EXPECT_EQ(got.model, want.model) << what;
  for (size_t i = 0; i < 5; ++i) EXPECT_FLOAT_EQ(got.coeffs[i], want.coeffs[i]) << what << " coeff " << i;
}

TEST(Recorder, SimulatorDepthAndColourReadBackPixelIdentical) {
  ScratchDir dir("recorder");
  const std::string path = dir / "cell.bag";
  const RecorderStats stats = record_cell(recorder_params(path), kRoundTripFrames);
  ASSERT_TRUE(stats.error.empty()) << stats.error;
  EXPECT_EQ(stats.frames_recorded, kRoundTripFrames);
  EXPECT_EQ(stats.frames_dropped, 0);
  ASSERT_EQ(stats.files, std::vector<std::string>{path});

  // The expectation: a second simulator on the same configuration, frame for frame.
  std::unique_ptr<Source> truth = cell_source(kRoundTripFrames);
  RecordingParams params{path};
  params.with_color = true;
  BagSource bag(params);
  Frame want, got;
  int frames = 0;
  int64_t first_want_ns = 0, first_got_ns = 0;
  while (frames < kRoundTripFrames + 1 && bag.next(got) == Source::Status::frame) {
    ASSERT_EQ(truth->next(want), Source::Status::frame) << "the bag has more frames than were recorded";
    if (frames == 0) {
      first_want_ns = want.timestamp_ns;
      first_got_ns = got.timestamp_ns;
      expect_same_intrinsics(got.intrinsics, want.intrinsics, "depth");
      ASSERT_TRUE(want.color.has_value()) << "the cell renders colour";
      expect_same_intrinsics(got.color_intrinsics, want.color_intrinsics, "colour");
      ASSERT_TRUE(want.depth_to_color && got.depth_to_color);
      for (size_t i = 0; i < 9; ++i) {
        EXPECT_NEAR(got.depth_to_color->rotation[i], want.depth_to_color->rotation[i], 1e-6) << "rotation " << i;
      }
      for (size_t i = 0; i < 3; ++i) {
        EXPECT_NEAR(got.depth_to_color->translation_m[i], want.depth_to_color->translation_m[i], 1e-7) << "t " << i;
      }
    }
    EXPECT_FLOAT_EQ(got.depth.depth_scale_m, want.depth.depth_scale_m) << "frame " << frames;
    ASSERT_EQ(got.depth.pixels, want.depth.pixels) << "depth of frame " << frames;
    ASSERT_TRUE(got.color.has_value()) << "frame " << frames;
    ASSERT_EQ(got.color->rgb, want.color->rgb) << "colour of frame " << frames;
    // A stamp of 0 cannot be told from "none" in the message: compare relative to the first.
    EXPECT_LE(std::llabs((got.timestamp_ns - first_got_ns) - (want.timestamp_ns - first_want_ns)), 1000)
        << "frame " << frames;
    if (want.timestamp_ns != 0) {
      EXPECT_LE(std::llabs(got.timestamp_ns - want.timestamp_ns), 1000) << "frame " << frames;
    }
    ++frames;
  }
  EXPECT_EQ(frames, kRoundTripFrames);
  EXPECT_EQ(bag.error(), "");
  const RecordingSummary summary = summarize_recording(path);
  EXPECT_TRUE(summary.indexed);
  EXPECT_EQ(summary.compression, "lz4");
  EXPECT_EQ(summary.file_version, 4);
  EXPECT_TRUE(summary.damage.empty()) << summary.damage;
}

// ---- The records of spec §1 and the topics / types / md5s of spec §3, parsed here on their own.

uint32_t le32(const std::vector<char>& b, size_t at) {
  uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

/// A record's header fields by name, and where its data is.
struct RawRecord {
  std::map<std::string, std::string> fields;
  size_t data_at = 0, data_len = 0, end = 0;
};

RawRecord raw_record(const std::vector<char>& b, size_t at) {
  RawRecord r;
  const uint32_t header_len = le32(b, at);
  size_t p = at + 4;
  while (p < at + 4 + header_len) {
    const uint32_t len = le32(b, p);
    const std::string field(b.data() + p + 4, len);
    const size_t eq = field.find('=');
    r.fields[field.substr(0, eq)] = field.substr(eq + 1);
    p += 4 + len;
  }
  r.data_len = le32(b, p);
  r.data_at = p + 4;
  r.end = r.data_at + r.data_len;
  return r;
}

uint32_t field32(const RawRecord& r, const std::string& name) {
  uint32_t v = 0;
  std::memcpy(&v, r.fields.at(name).data(), 4);
  return v;
}

TEST(Recorder, WritesEveryRecordTheSpecListsForSdkPlayback) {
  ScratchDir dir("recorder");
  const std::string path = dir / "cell.bag";
  ASSERT_TRUE(record_cell(recorder_params(path), 3).error.empty());
  const std::vector<char> b = test::read_bytes(path);
  ASSERT_GT(b.size(), 4096U);
  ASSERT_EQ(std::string(b.data(), 13), "#ROSBAG V2.0\n");
  const RawRecord header = raw_record(b, 13);
  ASSERT_EQ(header.fields.at("op"), std::string(1, '\x03'));
  EXPECT_EQ(header.end - 13, 4096U) << "bag header record: header + data = 4096 bytes";
  uint64_t index_pos = 0;
  std::memcpy(&index_pos, header.fields.at("index_pos").data(), 8);
  ASSERT_GT(index_pos, header.end);
  ASSERT_LT(index_pos, b.size());
  const uint32_t conn_count = field32(header, "conn_count");
  const uint32_t chunk_count = field32(header, "chunk_count");
  EXPECT_GE(chunk_count, 3U) << "an 848x480 depth frame alone exceeds a 768 KiB chunk";

  // Chunks, each followed by its index data records, up to index_pos.
  size_t at = header.end;
  std::vector<size_t> chunk_positions;
  while (at < index_pos) {
    const RawRecord chunk = raw_record(b, at);
    ASSERT_EQ(chunk.fields.at("op"), std::string(1, '\x05')) << "at byte " << at;
    EXPECT_EQ(chunk.fields.at("compression"), "lz4");
    chunk_positions.push_back(at);
    at = chunk.end;
    while (at < index_pos && raw_record(b, at).fields.at("op") == std::string(1, '\x04')) {
      const RawRecord index = raw_record(b, at);
      EXPECT_EQ(field32(index, "ver"), 1U);
      EXPECT_EQ(index.data_len, field32(index, "count") * 12U);
      at = index.end;
    }
  }
  EXPECT_EQ(chunk_positions.size(), chunk_count);
  // Then conn_count connection records and chunk_count chunk infos, to the end of the file.
  at = index_pos;
  std::set<std::string> topics;
  for (uint32_t i = 0; i < conn_count; ++i) {
    const RawRecord c = raw_record(b, at);
    ASSERT_EQ(c.fields.at("op"), std::string(1, '\x07'));
    topics.insert(c.fields.at("topic"));
    at = c.end;
  }
  for (uint32_t i = 0; i < chunk_count; ++i) {
    const RawRecord info = raw_record(b, at);
    ASSERT_EQ(info.fields.at("op"), std::string(1, '\x06'));
    uint64_t chunk_pos = 0;
    std::memcpy(&chunk_pos, info.fields.at("chunk_pos").data(), 8);
    EXPECT_EQ(chunk_pos, chunk_positions[i]);
    EXPECT_EQ(info.data_len, field32(info, "count") * 8U);
    at = info.end;
  }
  EXPECT_EQ(at, b.size()) << "nothing after the chunk infos";

  // Spec §3: topic -> (type, md5).
  const std::map<std::string, std::pair<std::string, std::string>> expected = {
      {"/file_version", {"std_msgs/UInt32", "304a39449588c7f8ce2df6e8001c5fce"}},
      {"/device_0/info", {"diagnostic_msgs/KeyValue", "cf57fdc6617a881a88c16e768132149c"}},
      {"/device_0/sensor_0/info", {"diagnostic_msgs/KeyValue", "cf57fdc6617a881a88c16e768132149c"}},
      {"/device_0/sensor_1/info", {"diagnostic_msgs/KeyValue", "cf57fdc6617a881a88c16e768132149c"}},
      {"/device_0/sensor_0/option/Depth_Units/value", {"std_msgs/Float32", "73fcbf46b49191e672908e50842a83d4"}},
      {"/device_0/sensor_0/Depth_0/info", {"realsense_msgs/StreamInfo", "311d7e24eac31bb87271d041bf70ff7d"}},
      {"/device_0/sensor_0/Depth_0/info/camera_info", {"sensor_msgs/CameraInfo", "c9a58c1b0b154e0e6da7578cb991d214"}},
      {"/device_0/sensor_0/Depth_0/tf/0", {"geometry_msgs/Transform", "ac9eff44abf714214112b05d54a3cf9b"}},
      {"/device_0/sensor_0/Depth_0/image/data", {"sensor_msgs/Image", "060021388200f6f0f447d0fcd9c64743"}},
      {"/device_0/sensor_0/Depth_0/image/metadata", {"diagnostic_msgs/KeyValue", "cf57fdc6617a881a88c16e768132149c"}},
      {"/device_0/sensor_1/Color_0/info", {"realsense_msgs/StreamInfo", "311d7e24eac31bb87271d041bf70ff7d"}},
      {"/device_0/sensor_1/Color_0/info/camera_info", {"sensor_msgs/CameraInfo", "c9a58c1b0b154e0e6da7578cb991d214"}},
      {"/device_0/sensor_1/Color_0/tf/0", {"geometry_msgs/Transform", "ac9eff44abf714214112b05d54a3cf9b"}},
      {"/device_0/sensor_1/Color_0/image/data", {"sensor_msgs/Image", "060021388200f6f0f447d0fcd9c64743"}},
      {"/device_0/sensor_1/Color_0/image/metadata", {"diagnostic_msgs/KeyValue", "cf57fdc6617a881a88c16e768132149c"}},
  };
  BagReader reader(path);
  ASSERT_TRUE(reader.indexed()) << reader.index_problem();
  std::map<std::string, uint32_t> ids;
  for (const auto& [id, c] : reader.connections()) ids[c.topic] = id;
  for (const auto& [topic, type_md5] : expected) {
    ASSERT_EQ(ids.count(topic), 1U) << "missing topic " << topic;
    const BagConnection& c = reader.connections().at(ids[topic]);
    EXPECT_EQ(c.type, type_md5.first) << topic;
    EXPECT_EQ(c.md5sum, type_md5.second) << topic;
    EXPECT_EQ(topics.count(topic), 1U) << topic << " not among the index's connection records";
  }
  EXPECT_EQ(reader.indexed_counts().at(ids["/device_0/sensor_0/Depth_0/image/data"]), 3U);
  EXPECT_EQ(reader.indexed_counts().at(ids["/device_0/sensor_1/Color_0/image/data"]), 3U);
  // Static messages at (0 s, 1 ns), the device's Name among its info, streams from 2 ns.
  BagMessage m;
  std::set<std::string> device_keys;
  int64_t first_depth_ns = -1;
  for (int guard = 0; guard < 1000 && reader.next(m); ++guard) {
    const std::string& topic = reader.connections().at(m.conn).topic;
    if (topic == "/file_version") {
      EXPECT_EQ(m.time_ns, 1);
      uint32_t version = 0;
      std::memcpy(&version, m.data, 4);
      EXPECT_EQ(version, 4U);
    }
    if (topic == "/device_0/info") {
      uint32_t key_len = 0;
      std::memcpy(&key_len, m.data, 4);
      device_keys.insert(std::string(reinterpret_cast<const char*>(m.data) + 4, key_len));
      EXPECT_EQ(m.time_ns, 1);
    }
    if (topic == "/device_0/sensor_0/Depth_0/image/data" && first_depth_ns < 0) first_depth_ns = m.time_ns;
  }
  EXPECT_EQ(first_depth_ns, 2);
  for (const char* key : {"Name", "Serial Number", "Firmware Version", "Product Id", "Product Line"}) {
    EXPECT_EQ(device_keys.count(key), 1U) << key;
  }
}

/// The image messages' header.seq (the first uint32, spec §4) and the "Frame Counter" metadata
/// values of `stream` ("/device_0/sensor_1/Color_0"), in file order.
struct FrameNumbers {
  std::vector<uint32_t> seq;
  std::vector<std::string> counter;
};
FrameNumbers frame_numbers(const std::string& path, const std::string& stream) {
  FrameNumbers out;
  BagReader reader(path);
  BagMessage m;
  for (int guard = 0; guard < 100000 && reader.next(m); ++guard) {
    const std::string& topic = reader.connections().at(m.conn).topic;
    if (topic == stream + "/image/data") {
      uint32_t seq = 0;
      std::memcpy(&seq, m.data, 4);
      out.seq.push_back(seq);
    }
    if (topic == stream + "/image/metadata") {  // KeyValue: string key, string value
      uint32_t key_len = 0, value_len = 0;
      std::memcpy(&key_len, m.data, 4);
      const std::string key(reinterpret_cast<const char*>(m.data) + 4, key_len);
      std::memcpy(&value_len, m.data + 4 + key_len, 4);
      if (key == "Frame Counter") out.counter.emplace_back(reinterpret_cast<const char*>(m.data) + 8 + key_len, value_len);
    }
  }
  return out;
}

TEST(Recorder, ColourFramesAreNumberedAsTheFramesTheyBelongTo) {
  ScratchDir dir("recorder");
  const std::string path = dir / "numbers.bag";
  ASSERT_TRUE(record_cell(recorder_params(path), 3, {"sim.width=424", "sim.height=240"}).error.empty());
  // The simulator numbers its frames 0, 1, 2; a frame's colour image is part of the same capture.
  const FrameNumbers color = frame_numbers(path, "/device_0/sensor_1/Color_0");
  EXPECT_EQ(color.seq, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(color.counter, (std::vector<std::string>{"0", "1", "2"}));
  const FrameNumbers depth = frame_numbers(path, "/device_0/sensor_0/Depth_0");
  EXPECT_EQ(depth.seq, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(Recorder, EveryOptionValueHasItsDescription) {
  ScratchDir dir("recorder");
  const std::string path = dir / "options.bag";
  RecorderParams params = recorder_params(path);
  params.bag.stereo_baseline_mm = 50.0F;
  ASSERT_TRUE(record_cell(params, 1, {"sim.width=424", "sim.height=240"}).error.empty());
  // Spec §3: each `option/<Name>/value` comes with an `option/<Name>/description`, a
  // std_msgs/String (md5 992ce8a1687cec8c8bd883ec73ca41d1) written once.
  BagReader reader(path);
  std::map<std::string, std::string> type_of, md5_of;
  for (const auto& [id, c] : reader.connections()) {
    type_of[c.topic] = c.type;
    md5_of[c.topic] = c.md5sum;
  }
  std::map<std::string, int> descriptions;  // topic -> messages
  BagMessage m;
  for (int guard = 0; guard < 100000 && reader.next(m); ++guard) {
    const std::string& topic = reader.connections().at(m.conn).topic;
    if (topic.size() < 12 || topic.compare(topic.size() - 12, 12, "/description") != 0) continue;
    ++descriptions[topic];
    uint32_t length = 0;
    ASSERT_GE(m.size, 4U) << topic;
    std::memcpy(&length, m.data, 4);
    EXPECT_EQ(m.size, 4U + length) << topic << ": one string";
    EXPECT_GT(length, 0U) << topic << ": a description says something";
  }
  int values = 0;
  for (const auto& [topic, type] : type_of) {
    const size_t at = topic.rfind("/value");
    if (topic.find("/option/") == std::string::npos || at == std::string::npos || at + 6 != topic.size()) continue;
    ++values;
    const std::string description = topic.substr(0, at) + "/description";
    ASSERT_EQ(type_of.count(description), 1U) << "no " << description;
    EXPECT_EQ(type_of[description], "std_msgs/String");
    EXPECT_EQ(md5_of[description], "992ce8a1687cec8c8bd883ec73ca41d1");
    EXPECT_EQ(descriptions[description], 1) << description;
  }
  EXPECT_EQ(values, 2) << "Depth_Units and Stereo_Baseline";
}

TEST(Recorder, JointStatesGoToTheirOwnTopic) {
  ScratchDir dir("recorder");
  const std::string path = dir / "joints.bag";
  {
    std::unique_ptr<Source> source = cell_source(2, {"sim.width=424", "sim.height=240"});
    BagWriter writer(path);
    Frame frame;
    ASSERT_EQ(source->next(frame), Source::Status::frame);
    writer.add_frame(frame);
    writer.add_joint_state(frame.timestamp_ns, JointAngles{0.5, -1.0, 1.5, -2.0, 2.5, -3.0});
    writer.close();
  }
  BagReader reader(path);
  BagMessage m;
  bool found = false;
  for (int guard = 0; guard < 1000 && reader.next(m); ++guard) {
    const BagConnection& c = reader.connections().at(m.conn);
    if (c.topic != "/hrcsense/joint_states") continue;
    found = true;
    EXPECT_EQ(c.type, "sensor_msgs/JointState");
    // header (4 + 8 + 4 + 0), name[] (4 + 6 × (4 + 7)), position[] (4 + 6 × 8), velocity[], effort[]
    ASSERT_EQ(m.size, 16U + 4 + 6 * 11 + 4 + 48 + 8);
    double q = 0.0;
    std::memcpy(&q, m.data + 16 + 4 + 6 * 11 + 4 + 8 * 5, 8);
    EXPECT_EQ(q, -3.0);
  }
  EXPECT_TRUE(found);
}

// `run --record` (issue 31, defect 6): the joint state recorded for a frame is the one
// processing reported (state_used), not the capture-time lookup pushed with it; a frame
// processing skipped (a newer one was reported first) or never reached (the run ended) keeps
// the lookup; one measured against no state, or a non-finite one, is recorded without. Read
// back through the recorded state source, which is what a replay decides on.
TEST(Recorder, TheStateProcessingUsedIsTheOneRecorded) {
  ScratchDir dir("recorder");
  const std::string path = dir / "used.bag";
  const auto state_with = [](double q1) {
    RobotState s;
    s.valid = true;
    s.q_rad = JointAngles{q1, -1.0, 1.5, -2.0, 2.5, -3.0};
    return s;
  };
  {
    std::unique_ptr<Source> source = cell_source(6, {"sim.width=424", "sim.height=240"});
    RecorderParams params = recorder_params(path);
    params.queue_frames = 16;  // room for every frame: none may be dropped here
    Recorder recorder(params);
    std::vector<Frame> frames(6);
    for (Frame& frame : frames) {
      ASSERT_EQ(source->next(frame), Source::Status::frame);
    }
    // Frame i is pushed with the capture-time lookup q1 = 0.1·i.
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(recorder.push_awaiting_state(frames[i], state_with(0.1 * i)));
    recorder.state_used(0, state_with(0.55));  // processing measured frame 0 against 0.55
    recorder.state_used(2, state_with(0.75));  // frame 1 was replaced before processing took it
    ASSERT_TRUE(recorder.push_awaiting_state(frames[3], state_with(0.3)));
    recorder.state_used(3, RobotState{});  // no state
    ASSERT_TRUE(recorder.push_awaiting_state(frames[4], state_with(0.4)));
    RobotState nan = state_with(0.95);
    nan.q_rad[2] = std::nan("");
    recorder.state_used(4, nan);
    ASSERT_TRUE(recorder.push_awaiting_state(frames[5], state_with(0.5)));  // the run ends first
    const RecorderStats stats = recorder.close();
    ASSERT_TRUE(stats.error.empty()) << stats.error;
    EXPECT_EQ(stats.frames_recorded, 6);
  }
  RecordingParams params{path};
  params.with_joint_states = true;
  BagSource bag(params);
  std::unique_ptr<RobotStateSource> states = bag.recorded_robot_state();
  ASSERT_NE(states, nullptr);
  const std::vector<double> expected_q1{0.55, 0.1, 0.75, -1.0, -1.0, 0.5};  // -1: no state recorded
  Frame frame;
  for (size_t i = 0; i < expected_q1.size(); ++i) {
    ASSERT_EQ(bag.next(frame), Source::Status::frame) << i;
    RobotState state;
    const bool found = states->state_at(frame.timestamp_ns, state);
    if (expected_q1[i] < 0.0) {
      EXPECT_FALSE(found) << "frame " << i << " was measured against no usable state";
      continue;
    }
    ASSERT_TRUE(found) << "frame " << i << ": " << states->error();
    EXPECT_EQ(state.q_rad[0], expected_q1[i]) << "frame " << i;
  }
}

TEST(Recorder, SplitsIntoNumberedCompleteFiles) {
  ScratchDir dir("recorder");
  RecorderParams params = recorder_params(dir / "split.bag");
  params.split_mb = 1;
  params.bag.compression = BagCompression::none;  // sizes that do not depend on the pixels
  // 424x240: 203 520 B depth + 305 280 B colour per frame, so a 1 MiB file holds 3 frames.
  const int frames = 10;
  const RecorderStats stats = record_cell(params, frames, {"sim.width=424", "sim.height=240"});
  ASSERT_TRUE(stats.error.empty()) << stats.error;
  ASSERT_EQ(stats.files.size(), 4U);
  int64_t total = 0;
  for (size_t i = 0; i < stats.files.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "split-%03zu.bag", i);
    EXPECT_EQ(stats.files[i], dir / name);
    const RecordingSummary summary = summarize_recording(stats.files[i]);
    EXPECT_TRUE(summary.indexed) << stats.files[i];
    EXPECT_TRUE(summary.damage.empty()) << summary.damage;
    ASSERT_EQ(summary.streams.size(), 2U) << "each file carries both streams' calibration";
    total += summary.streams[0].frames;
    if (i + 1 < stats.files.size()) {
      EXPECT_EQ(summary.streams[0].frames, 3) << stats.files[i];
    }
  }
  EXPECT_EQ(total, frames);
  EXPECT_FALSE(fs::exists(dir / "split.bag"));
  EXPECT_EQ(split_file_name("a/b.bag", 12), "a/b-012.bag");
  EXPECT_EQ(split_file_name("noext", 0), "noext-000.bag");
}

TEST(Recorder, AFullDiskIsAnErrorNamingTheFileAndLaterFramesCountAsDropped) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  RecorderParams params = recorder_params("/dev/full");
  std::unique_ptr<Source> source = cell_source(6, {"sim.width=424", "sim.height=240"});
  Recorder recorder(params);
  Frame frame;
  int pushed = 0;
  for (int i = 0; i < 6 && source->next(frame) == Source::Status::frame; ++i) {
    if (recorder.push_wait(frame, kPushWaitMs)) ++pushed;
    // Give the writer the time to fail on the first frame (bounded: 5 s).
    for (int wait = 0; wait < 500 && i == 0 && !recorder.failed(); ++wait) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  const RecorderStats stats = recorder.close();
  EXPECT_TRUE(recorder.failed());
  EXPECT_NE(stats.error.find("/dev/full"), std::string::npos) << stats.error;
  EXPECT_NE(stats.error.find(std::strerror(ENOSPC)), std::string::npos) << stats.error;
  EXPECT_EQ(stats.frames_recorded, 0);
  EXPECT_EQ(stats.frames_dropped, 6) << "the failed frame and every later one";
}

TEST(Recorder, AFolderThatCannotBeWrittenIsAnErrorNamingTheFile) {
  ScratchDir dir("recorder");
  const std::string path = dir / "missing/sub/x.bag";  // no such folder
  const RecorderStats stats = record_cell(recorder_params(path), 1, {"sim.width=424", "sim.height=240"});
  EXPECT_NE(stats.error.find(path + ": cannot create"), std::string::npos) << stats.error;
}

TEST(Recorder, WithOnErrorStopTheRecordingSourceEndsWithTheError) {
  std::unique_ptr<Source> inner = cell_source(20, {"sim.width=424", "sim.height=240"});
  RecorderParams params = recorder_params("/dev/full");
  Recorder recorder(params);
  RecordingSource source(*inner, recorder, RecordOnError::stop_run);
  Frame frame;
  Source::Status status = Source::Status::frame;
  int frames = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (frames < 20 && (status = source.next(frame)) == Source::Status::frame &&
         std::chrono::steady_clock::now() < deadline) {
    ++frames;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // time for the writer to fail
  }
  EXPECT_EQ(status, Source::Status::error);
  EXPECT_LT(frames, 20);
  EXPECT_NE(source.error().find("recording: /dev/full: write failed"), std::string::npos) << source.error();

  // continue: every frame still arrives; the recorder counts them as dropped.
  std::unique_ptr<Source> inner2 = cell_source(5, {"sim.width=424", "sim.height=240"});
  Recorder recorder2(recorder_params("/dev/full"));
  RecordingSource going_on(*inner2, recorder2, RecordOnError::continue_run);
  int delivered = 0;
  for (int i = 0; i < 10 && going_on.next(frame) == Source::Status::frame; ++i) ++delivered;
  EXPECT_EQ(delivered, 5);
  const RecorderStats stats = recorder2.close();
  EXPECT_EQ(stats.frames_recorded + stats.frames_dropped, 5);
  EXPECT_EQ(stats.frames_recorded, 0);
}

TEST(Recorder, RecordKeysAreReadAndBounded) {
  const Config defaults = load_config("", {});
  EXPECT_EQ(defaults.record.split_mb, 0);  // docs/CONFIG.md: one file
  EXPECT_EQ(defaults.record.on_error, RecordOnError::continue_run);
  EXPECT_EQ(defaults.record.queue_frames, 16);
  const Config set = load_config("", {"record.split_mb=512", "record.on_error=stop", "record.queue_frames=1"});
  EXPECT_EQ(set.record.split_mb, 512);
  EXPECT_EQ(set.record.on_error, RecordOnError::stop_run);
  EXPECT_EQ(set.record.queue_frames, 1);
  for (const std::string bad : {"record.split_mb=-1", "record.split_mb=1048577", "record.split_mb=0.5",
                                "record.on_error=retry", "record.queue_frames=0", "record.queue_frames=1025"}) {
    try {
      load_config("", {bad});
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("key '" + bad.substr(0, bad.find('=')) + "'"), std::string::npos) << e.what();
    }
  }
}

TEST(Recorder, PushNeverWaitsForTheDiskAndCountsDrops) {
  ScratchDir dir("recorder");
  RecorderParams params = recorder_params(dir / "fast.bag");
  params.queue_frames = 1;
  std::unique_ptr<Source> source = cell_source(1);
  Frame frame;
  ASSERT_EQ(source->next(frame), Source::Status::frame);
  Recorder recorder(params);
  int accepted = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 50; ++i) accepted += recorder.push(frame) ? 1 : 0;
  const double push_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const RecorderStats stats = recorder.close();
  EXPECT_EQ(stats.frames_recorded, accepted);
  EXPECT_EQ(stats.frames_dropped, 50 - accepted);
  EXPECT_GT(stats.frames_dropped, 0) << "50 copies outpace writing 50 848x480 frames through a 1-frame queue";
  // 50 copies of 2 MB take milliseconds; writing them would take far longer.
  EXPECT_LT(push_s, 2.0);
}

}  // namespace
}  // namespace hrcsense
