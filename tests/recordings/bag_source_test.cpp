// SPDX-License-Identifier: Apache-2.0
// BagSource and summarize_recording on the real D435 recording in ../shared/data, intact and
// damaged (truncated, corrupted chunk, wrong magic, unknown compression).
#include "recordings_test_util.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

namespace hrcsense {
namespace {

const char* kBag = "librealsense_d435_single_frame";

std::string bag_path() {
  const std::string dir = test::shared_data(kBag);
  return dir.empty() ? dir : dir + "/single_depth_color_640x480.bag";
}

#define REQUIRE_BAG()                                                  \
  const std::string bag = bag_path();                                  \
  if (bag.empty()) GTEST_SKIP() << "../shared/data/" << kBag << " is absent"

TEST(BagSource, SummaryMatchesTheReadme) {
  REQUIRE_BAG();
  const RecordingSummary s = summarize_recording(bag);
  EXPECT_TRUE(s.damage.empty()) << s.damage;
  EXPECT_EQ(s.format, RecordingFormat::bag);
  EXPECT_EQ(recording_format_text(s), "bag");
  EXPECT_EQ(s.compression, "lz4");
  EXPECT_TRUE(s.indexed);
  EXPECT_EQ(s.file_version, 3);
  EXPECT_FLOAT_EQ(s.depth_units_m, 0.001F);
  EXPECT_NEAR(s.stereo_baseline_mm, 50.17, 0.01);
  ASSERT_EQ(s.streams.size(), 2U);
  const RecordingStream& depth = s.streams[0];
  EXPECT_EQ(depth.frames, 2);
  EXPECT_EQ(depth.encoding, "mono16");
  EXPECT_EQ(depth.intrinsics.width, 640);
  EXPECT_EQ(depth.intrinsics.height, 480);
  EXPECT_NEAR(depth.intrinsics.fx, 390.4315, 1e-4);
  EXPECT_NEAR(depth.intrinsics.fy, 390.4315, 1e-4);
  EXPECT_NEAR(depth.intrinsics.ppx, 331.3879, 1e-4);
  EXPECT_NEAR(depth.intrinsics.ppy, 242.1873, 1e-4);
  EXPECT_EQ(depth.intrinsics.model, Distortion::brown_conrady);
  // README: frame stamps are device times of about 360.7-361.0 s.
  EXPECT_GT(depth.first_ns, 360'000'000'000LL);
  EXPECT_LT(depth.last_ns, 361'100'000'000LL);
  EXPECT_GT(depth.last_ns, depth.first_ns);
  const RecordingStream& color = s.streams[1];
  EXPECT_EQ(color.frames, 1);
  EXPECT_EQ(color.encoding, "rgb8");
  EXPECT_NEAR(color.intrinsics.fx, 613.2037, 1e-4);
  EXPECT_NEAR(color.intrinsics.fy, 613.4193, 1e-4);
  EXPECT_NEAR(color.intrinsics.ppx, 319.9388, 1e-4);
  EXPECT_NEAR(color.intrinsics.ppy, 239.1830, 1e-4);
  ASSERT_TRUE(s.T_color_depth.has_value());
  const Eigen::Vector3d t = s.T_color_depth->translation();
  EXPECT_NEAR(t.x(), 0.014311, 1e-6);
  EXPECT_NEAR(t.y(), 0.000602, 1e-6);
  EXPECT_NEAR(t.z(), 0.000611, 1e-6);
  const Eigen::Quaterniond q(s.T_color_depth->linear());
  const double sign = q.w() < 0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * q.x(), -0.0000532, 1e-6);
  EXPECT_NEAR(sign * q.y(), 0.0064634, 1e-6);
  EXPECT_NEAR(sign * q.z(), 0.0051549, 1e-6);
  EXPECT_NEAR(sign * q.w(), 0.9999658, 1e-6);
}

TEST(BagSource, DepthFramesAreIdenticalToTheExtractedPngs) {
  REQUIRE_BAG();
  BagSource source(RecordingParams{bag});
  const SourceInfo info = source.info();
  EXPECT_EQ(info.type, "bag");
  EXPECT_EQ(info.frame_count, 2);  // from the index
  EXPECT_NEAR(info.stereo_baseline_mm, 50.17, 0.01);
  Frame frame;
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
    EXPECT_EQ(frame.index, i);
    DepthImage png;
    read_depth_png(test::shared_data(kBag) + "/depth_" + std::to_string(i) + ".png", png);
    ASSERT_EQ(frame.depth.width, png.width);
    ASSERT_EQ(frame.depth.height, png.height);
    EXPECT_TRUE(frame.depth.pixels == png.pixels) << "frame " << i;
    EXPECT_FLOAT_EQ(frame.depth.depth_scale_m, 0.001F);
    EXPECT_FALSE(frame.color.has_value());  // colour only when asked for
  }
  EXPECT_EQ(source.next(frame), Source::Status::end);
}

TEST(BagSource, ColourFrameMatchesTheExtractedPngWhenAskedFor) {
  REQUIRE_BAG();
  RecordingParams params{bag};
  params.with_color = true;
  BagSource source(params);
  Frame frame;
  bool seen = false;
  while (source.next(frame) == Source::Status::frame) {
    if (!frame.color) continue;
    seen = true;
    EXPECT_EQ(frame.color->width, 640);
    EXPECT_EQ(frame.color->height, 480);
    EXPECT_EQ(frame.color->rgb.size(), 640U * 480U * 3U);
  }
  EXPECT_TRUE(seen);
}

TEST(BagSource, LoopsWithRisingTimestamps) {
  REQUIRE_BAG();
  RecordingParams params{bag};
  params.loop = true;
  BagSource source(params);
  Frame frame;
  int64_t last_ns = -1;
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
    EXPECT_EQ(frame.index, i);
    EXPECT_GT(frame.timestamp_ns, last_ns);
    last_ns = frame.timestamp_ns;
  }
}

/// Plays `path` to the end; returns the frames delivered and the error (or "" at a clean end).
std::pair<int, std::string> play(const std::string& path) {
  std::unique_ptr<BagSource> source;
  try {
    source = std::make_unique<BagSource>(RecordingParams{path});
  } catch (const IoError& e) {
    return {0, e.what()};
  }
  Frame frame;
  int frames = 0;
  Source::Status status = Source::Status::frame;
  while ((status = source->next(frame)) == Source::Status::frame) ++frames;
  if (status == Source::Status::end) return {frames, ""};
  EXPECT_EQ(source->next(frame), Source::Status::error);  // it stays failed
  return {frames, source->error()};
}

void expect_names_file_and_offset(const std::string& error, const std::string& file) {
  EXPECT_NE(error.find(file), std::string::npos) << error;
  EXPECT_NE(error.find("byte offset"), std::string::npos) << error;
}

TEST(BagSource, TruncatedAtEveryTenthGivesTheGoodFramesThenOneError) {
  REQUIRE_BAG();
  const std::vector<char> bytes = test::read_bytes(bag);
  ASSERT_EQ(bytes.size(), 1034082U);
  // The file's layout (read with an independent script): bag header, chunk 1 at byte 4117
  // (depth frame 0 + the colour frame, up to byte 756751), chunk 2 (depth frame 1, up to byte
  // 996797), connections and chunk infos up to the end. A cut delivers the depth frames of the
  // chunks wholly before it; 97 % cuts only the index.
  test::ScratchDir dir("bag");
  for (int percent : {10, 20, 30, 40, 50, 60, 70, 80, 90, 97}) {
    const size_t size = bytes.size() * static_cast<size_t>(percent) / 100;
    const int expected_frames = size >= 996797 ? 2 : size >= 756751 ? 1 : 0;
    std::vector<char> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size));
    const std::string path = dir / ("cut" + std::to_string(percent) + ".bag");
    test::write_bytes(path, cut);
    const auto [frames, error] = play(path);
    EXPECT_EQ(frames, expected_frames) << percent << " %";
    EXPECT_FALSE(error.empty()) << percent << " %: truncation went unnoticed";
    expect_names_file_and_offset(error, path);
  }
}

TEST(BagSource, CorruptedChunkGivesOneErrorNamingTheOffset) {
  REQUIRE_BAG();
  std::vector<char> bytes = test::read_bytes(bag);
  // Flip bytes in the middle of the file: inside an lz4 chunk's compressed data.
  for (size_t i = bytes.size() / 2; i < bytes.size() / 2 + 64; ++i) bytes[i] = static_cast<char>(bytes[i] ^ 0x5A);
  test::ScratchDir dir("bag");
  const std::string path = dir / "corrupt.bag";
  test::write_bytes(path, bytes);
  const auto [frames, error] = play(path);
  EXPECT_LT(frames, 2);
  expect_names_file_and_offset(error, path);
  EXPECT_NE(error.find("lz4"), std::string::npos) << error;
}

TEST(BagSource, WrongMagicIsAnErrorAtOffsetZero) {
  REQUIRE_BAG();
  std::vector<char> bytes = test::read_bytes(bag);
  bytes[1] = 'X';
  test::ScratchDir dir("bag");
  const std::string path = dir / "magic.bag";
  test::write_bytes(path, bytes);
  const auto [frames, error] = play(path);
  EXPECT_EQ(frames, 0);
  EXPECT_NE(error.find("byte offset 0"), std::string::npos) << error;
  EXPECT_NE(error.find("wrong magic"), std::string::npos) << error;
  EXPECT_THROW(summarize_recording(path), IoError);
}

TEST(BagSource, UnknownCompressionIsNamed) {
  REQUIRE_BAG();
  std::vector<char> bytes = test::read_bytes(bag);
  // Rename every chunk's "compression=lz4" to "compression=xz9".
  const std::string field = "compression=lz4";
  int renamed = 0;
  for (auto at = std::search(bytes.begin(), bytes.end(), field.begin(), field.end()); at != bytes.end();
       at = std::search(at + 1, bytes.end(), field.begin(), field.end())) {
    std::memcpy(&*(at + 12), "xz9", 3);
    ++renamed;
  }
  ASSERT_GT(renamed, 0);
  test::ScratchDir dir("bag");
  const std::string path = dir / "xz9.bag";
  test::write_bytes(path, bytes);
  const auto [frames, error] = play(path);
  EXPECT_EQ(frames, 0);
  expect_names_file_and_offset(error, path);
  EXPECT_NE(error.find("unknown chunk compression 'xz9'"), std::string::npos) << error;
}

TEST(BagSource, MissingFileAndFolderAreErrors) {
  test::ScratchDir dir("bag");
  EXPECT_THROW(BagSource(RecordingParams{dir / "none.bag"}), IoError);
  EXPECT_THROW(summarize_recording(dir / "none.bag"), IoError);
  test::write_text(dir / "short.bag", "#ROSBAG V2.0\n");
  const auto [frames, error] = play(dir / "short.bag");
  EXPECT_EQ(frames, 0);
  expect_names_file_and_offset(error, dir / "short.bag");
  test::write_text(dir / "old.bag", "#ROSBAG V1.2\n");
  EXPECT_NE(play(dir / "old.bag").second.find("unsupported ROS bag version"), std::string::npos);
}

}  // namespace
}  // namespace hrcsense
