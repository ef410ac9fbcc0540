// SPDX-License-Identifier: Apache-2.0
// Simulator frames written with the test bag writer (tests/support/bag_writer.hpp) and read back
// with BagSource: pixels, intrinsics, depth units and integer-nanosecond timestamps survive, with
// LZ4 or uncompressed chunks, through the index or by a linear scan. Needs no ../shared data.
#include "../support/scenes.hpp"
#include "../support/bag_writer.hpp"
#include "recordings_test_util.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>

namespace hrcsense {
namespace {

constexpr int kFrames = 4;
/// A Unix time (2023-11-14) with odd nanoseconds: a double of seconds would lose them.
constexpr int64_t kFirstStampNs = 1'700'000'000'123'456'789LL;

/// Frames of config/walk.yaml at 640x480 with the person in view, stamped kFirstStampNs + i·33.3 ms.
const std::vector<Frame>& walk_frames() {
  static const std::vector<Frame> frames = [] {
    const Config config = load_config(test::scene_path("walk.yaml"),
                                      {"sim.width=640", "sim.height=480"});
    const Simulator sim = make_simulator(config);
    std::vector<Frame> out(kFrames);
    for (int i = 0; i < kFrames; ++i) {
      sim.render(150 + i, out[static_cast<size_t>(i)]);
      out[static_cast<size_t>(i)].index = i;
      out[static_cast<size_t>(i)].timestamp_ns = kFirstStampNs + i * 33'333'337LL;
    }
    return out;
  }();
  return frames;
}

ColorImage gradient(int width, int height) {
  ColorImage c;
  c.width = width;
  c.height = height;
  c.rgb.resize(static_cast<size_t>(width) * height * 3);
  for (size_t i = 0; i < c.rgb.size(); ++i) c.rgb[i] = static_cast<uint8_t>(i * 7 + i / 3);
  return c;
}

Intrinsics color_intrinsics() {
  Intrinsics in;
  in.width = 32;
  in.height = 24;
  in.fx = 30.5F;
  in.fy = 31.25F;
  in.ppx = 15.75F;
  in.ppy = 11.5F;
  in.model = Distortion::inverse_brown_conrady;
  in.coeffs = {0.125F, -0.25F, 0.001F, 0.002F, 0.0F};
  return in;
}

Pose color_pose() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.015, 0.0005, -0.0002);
  return T;
}

void write_walk_bag(const std::string& path, const test::BagWriterParams& params, bool with_color) {
  test::BagWriter writer(path, params);
  for (const Frame& frame : walk_frames()) {
    writer.add_depth(frame);
    if (with_color && frame.index == 1) {
      writer.add_color(frame.timestamp_ns + 1000, static_cast<uint32_t>(frame.index), gradient(32, 24),
                       color_intrinsics(), color_pose());
    }
  }
  writer.close();
}

void expect_same_intrinsics(const Intrinsics& a, const Intrinsics& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.fx, b.fx);  // float → float64 → float is exact
  EXPECT_EQ(a.fy, b.fy);
  EXPECT_EQ(a.ppx, b.ppx);
  EXPECT_EQ(a.ppy, b.ppy);
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.coeffs, b.coeffs);
}

/// Reads every frame of `path` and compares it with walk_frames().
void expect_walk_frames(const std::string& path, float expected_units_m) {
  BagSource source(RecordingParams{path});
  Frame frame;
  for (const Frame& written : walk_frames()) {
    ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
    EXPECT_EQ(frame.index, written.index);
    EXPECT_EQ(frame.timestamp_ns, written.timestamp_ns);
    ASSERT_EQ(frame.depth.width, written.depth.width);
    ASSERT_EQ(frame.depth.height, written.depth.height);
    EXPECT_TRUE(frame.depth.pixels == written.depth.pixels) << "frame " << written.index;
    EXPECT_EQ(frame.depth.depth_scale_m, expected_units_m);
    expect_same_intrinsics(frame.intrinsics, written.intrinsics);
    EXPECT_FALSE(frame.color.has_value());
  }
  EXPECT_EQ(source.next(frame), Source::Status::end) << source.error();
}

TEST(BagRoundTrip, Lz4IndexedKeepsPixelsIntrinsicsUnitsAndTimestamps) {
  test::ScratchDir dir("bagrt");
  const std::string path = dir / "walk.bag";
  test::BagWriterParams params;
  params.stereo_baseline_mm = 50.0F;
  write_walk_bag(path, params, true);
  expect_walk_frames(path, 0.001F);

  const RecordingSummary s = summarize_recording(path);
  EXPECT_TRUE(s.damage.empty()) << s.damage;
  EXPECT_EQ(s.compression, "lz4");
  EXPECT_TRUE(s.indexed);
  EXPECT_EQ(s.file_version, 4);
  EXPECT_EQ(s.stereo_baseline_mm, 50.0F);
  ASSERT_EQ(s.streams.size(), 2U);
  EXPECT_EQ(s.streams[0].frames, kFrames);
  EXPECT_EQ(s.streams[0].first_ns, kFirstStampNs);
  EXPECT_EQ(s.streams[0].last_ns, walk_frames().back().timestamp_ns);
  EXPECT_EQ(s.streams[1].frames, 1);
  expect_same_intrinsics(s.streams[1].intrinsics, color_intrinsics());
  ASSERT_TRUE(s.T_color_depth.has_value());
  EXPECT_TRUE(s.T_color_depth->isApprox(color_pose(), 1e-12));

  BagSource source(RecordingParams{path});
  EXPECT_EQ(source.info().frame_count, kFrames);  // from the index
  EXPECT_EQ(source.info().stereo_baseline_mm, 50.0F);
}

TEST(BagRoundTrip, UncompressedWithoutIndexIsReadByScanning) {
  test::ScratchDir dir("bagrt");
  const std::string path = dir / "walk.bag";
  test::BagWriterParams params;
  params.compression = test::BagCompression::none;
  params.write_index = false;
  write_walk_bag(path, params, false);
  expect_walk_frames(path, 0.001F);
  const RecordingSummary s = summarize_recording(path);
  EXPECT_TRUE(s.damage.empty()) << s.damage;
  EXPECT_EQ(s.compression, "none");
  EXPECT_FALSE(s.indexed);
  EXPECT_EQ(BagSource(RecordingParams{path}).info().frame_count, -1);  // unknown without an index
}

TEST(BagRoundTrip, Lz4WithTheIndexCutOffIsReadByScanning) {
  test::ScratchDir dir("bagrt");
  const std::string whole = dir / "whole.bag";
  write_walk_bag(whole, {}, true);
  // Cut the file where the index starts: index_pos (bag header) then points past the end.
  std::vector<char> bytes = test::read_bytes(whole);
  const std::string key = "index_pos=";
  const auto at = std::search(bytes.begin(), bytes.end(), key.begin(), key.end());
  ASSERT_NE(at, bytes.end());
  uint64_t index_pos = 0;
  std::memcpy(&index_pos, &*(at + static_cast<std::ptrdiff_t>(key.size())), 8);
  ASSERT_GT(index_pos, 4109U);
  ASSERT_LT(index_pos, bytes.size());
  bytes.resize(index_pos);
  const std::string path = dir / "cut.bag";
  test::write_bytes(path, bytes);
  expect_walk_frames(path, 0.001F);
  const RecordingSummary s = summarize_recording(path);
  EXPECT_FALSE(s.indexed);
  EXPECT_TRUE(s.damage.empty()) << s.damage;
  EXPECT_EQ(s.streams.size(), 2U);
}

TEST(BagRoundTrip, UnitsComeFromTheOptionWhenImagesHaveNoTrailingField) {
  test::ScratchDir dir("bagrt");
  const std::string path = dir / "old_sdk.bag";
  test::BagWriterParams params;
  params.trailing_depth_units = false;  // SDK < 2.49
  params.depth_units_option_m = 0.0001F;
  write_walk_bag(path, params, false);
  expect_walk_frames(path, 0.0001F);
}

TEST(BagRoundTrip, ColourIsDecodedWithItsCalibrationWhenAskedFor) {
  test::ScratchDir dir("bagrt");
  const std::string path = dir / "walk.bag";
  write_walk_bag(path, {}, true);
  RecordingParams params{path};
  params.with_color = true;
  BagSource source(params);
  Frame frame;
  std::vector<bool> has_color;
  while (source.next(frame) == Source::Status::frame) {
    has_color.push_back(frame.color.has_value());
    if (!frame.color) continue;
    EXPECT_EQ(frame.color->width, 32);
    EXPECT_EQ(frame.color->height, 24);
    EXPECT_TRUE(frame.color->rgb == gradient(32, 24).rgb);
    expect_same_intrinsics(frame.color_intrinsics, color_intrinsics());
    ASSERT_TRUE(frame.depth_to_color.has_value());
    const Pose expected = color_pose();
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(frame.depth_to_color->translation_m[static_cast<size_t>(i)], expected.translation()(i), 1e-7);
      for (int j = 0; j < 3; ++j) {
        EXPECT_NEAR(frame.depth_to_color->rotation[static_cast<size_t>(3 * j + i)], expected.linear()(i, j), 1e-7);
      }
    }
  }
  EXPECT_EQ(source.error(), "");
  // The colour frame follows depth frame 1; it stays attached to the later depth frames.
  EXPECT_EQ(has_color, (std::vector<bool>{false, false, true, true}));
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// R1: a camera_info whose focal length is absurd (1e30 px) is refused naming K[0], as a
// folder's intrinsics.json is, instead of putting every point at the camera.
TEST(BagRoundTrip, ImplausibleCameraInfoIsRefusedNamingTheField) {
  test::ScratchDir dir("bag_bad_k");
  const std::string path = dir / "bad_k.bag";
  {
    test::BagWriter writer(path, test::BagWriterParams{});
    Frame frame = walk_frames()[0];
    frame.intrinsics.fx = 1e30F;
    writer.add_depth(frame);
    writer.close();
  }
  std::string error;
  try {
    BagSource source(RecordingParams{path});
    Frame frame;
    if (source.next(frame) == Source::Status::error) error = source.error();
  } catch (const std::exception& e) {
    error = e.what();
  }
  EXPECT_NE(error.find("K[0]"), std::string::npos) << "error: '" << error << "'";
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// Issue 31 item 7: the rate a bag's depth StreamInfo states is the source's nominal rate, and a
// loop's next lap starts one period of it after the lap's last frame.
TEST(BagRoundTrip, TheStatedRateIsTheNominalRateAndPacesTheLoop) {
  test::ScratchDir dir("bagrt");
  const std::string path = dir / "six.bag";
  test::BagWriterParams params;
  params.fps = 6;
  write_walk_bag(path, params, false);
  RecordingParams loop{path};
  loop.loop = true;
  BagSource source(loop);
  EXPECT_EQ(source.info().nominal_fps, 6.0);
  Frame frame;
  std::vector<int64_t> stamps_ns;
  for (int i = 0; i <= kFrames; ++i) {
    ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
    stamps_ns.push_back(frame.timestamp_ns);
  }
  // The second lap's first frame: 1/6 s (166 666 666.7 ns, rounded) after the first lap's last.
  EXPECT_EQ(stamps_ns[kFrames] - stamps_ns[kFrames - 1], 166'666'667);
}

TEST(BagRoundTrip, ABagThatStatesNoRateIsNominallyAt30FramesPerSecond) {
  test::ScratchDir dir("bagrt");
  const std::string path = dir / "bare.bag";
  test::BagWriterParams params;
  params.sdk_metadata = false;  // no StreamInfo at all
  write_walk_bag(path, params, false);
  EXPECT_EQ(BagSource(RecordingParams{path}).info().nominal_fps, 30.0) << "the D435's default rate";
}

TEST(BagRoundTrip, AStatedDepthRateOfZeroIsRefusedNamingFileTopicAndField) {
  test::ScratchDir dir("bagrt");
  const std::string path = dir / "zero.bag";
  test::BagWriterParams params;
  params.fps = 0;
  write_walk_bag(path, params, false);
  std::string error;
  try {
    BagSource source(RecordingParams{path});
  } catch (const IoError& e) {
    error = e.what();
  }
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("/device_0/sensor_0/Depth_0/info"), std::string::npos) << error;
  EXPECT_NE(error.find("fps is 0"), std::string::npos) << error;
}

}  // namespace
}  // namespace hrcsense
