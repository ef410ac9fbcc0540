// SPDX-License-Identifier: Apache-2.0
// FolderSource: the datasets' layout and TUM's, intrinsics conventions, damaged folders.
#include "recordings_test_util.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace hrcsense {
namespace {

using test::ScratchDir;
using test::write_text;

constexpr int kW = 4, kH = 3;

DepthImage ramp(int first) {
  DepthImage depth;
  depth.resize(kW, kH);
  for (size_t i = 0; i < depth.pixels.size(); ++i) depth.pixels[i] = static_cast<uint16_t>(first + static_cast<int>(i));
  return depth;
}

/// The datasets' intrinsics form, with the 1-based pixel convention of MATLAB calibrations.
const char* kDatasetIntrinsics = R"json({"pixel_convention": "1-based (MATLAB)", "depth_units_m": 0.001,
  "width": 4, "height": 3, "depth_K": [[500.5, 0.0, 2.5], [0.0, 501.25, 2.0], [0.0, 0.0, 1.0]]})json";

/// A dataset-layout folder with `frames` ramps 100, 200, ... and a frames.txt.
void make_dataset_folder(const ScratchDir& dir, int frames) {
  std::filesystem::create_directories(dir.path / "depth");
  std::string list = "# index depth_png rgb_image\n";
  for (int i = 0; i < frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "depth/%06d.png", i);
    write_depth_png(dir / name, ramp(100 * (i + 1)));
    list += std::to_string(i) + " " + name + " rgb/x.jpg\n";
  }
  write_text(dir / "frames.txt", list);
  write_text(dir / "intrinsics.json", kDatasetIntrinsics);
}

TEST(FolderSource, ReadsTheDatasetLayoutAndMakesPixelCentresZeroBased) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 3);
  FolderSource source(RecordingParams{dir.path.string()});
  const SourceInfo info = source.info();
  EXPECT_EQ(info.type, "folder");
  EXPECT_EQ(info.frame_count, 3);
  EXPECT_EQ(info.intrinsics.width, kW);
  EXPECT_FLOAT_EQ(info.intrinsics.fx, 500.5F);
  EXPECT_FLOAT_EQ(info.intrinsics.fy, 501.25F);
  EXPECT_FLOAT_EQ(info.intrinsics.ppx, 1.5F);  // 2.5 in 1-based pixels
  EXPECT_FLOAT_EQ(info.intrinsics.ppy, 1.0F);
  EXPECT_EQ(info.stereo_baseline_mm, 0.0F);     // a folder knows no baseline
  Frame frame;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(source.next(frame), Source::Status::frame);
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.depth.at(0, 0), 100 * (i + 1));
    EXPECT_EQ(frame.depth.at(3, 2), 100 * (i + 1) + 11);
    EXPECT_FLOAT_EQ(frame.depth.depth_scale_m, 0.001F);
    EXPECT_EQ(frame.timestamp_ns, i * 33333333LL);  // no recorded times: nominal 30 frames/s
  }
  EXPECT_EQ(source.next(frame), Source::Status::end);
}

TEST(FolderSource, WithoutFramesTxtPlaysTheDepthFolderInNameOrder) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 2);
  std::filesystem::remove(dir.path / "frames.txt");
  FolderSource source(RecordingParams{dir.path.string()});
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.depth.at(0, 0), 100);
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.depth.at(0, 0), 200);
}

TEST(FolderSource, ReadsTheTumLayoutWithExactTimestampsAndScale5000) {
  ScratchDir dir("folder");
  std::filesystem::create_directories(dir.path / "depth");
  write_depth_png(dir / "depth/1305031102.160407.png", ramp(5000));
  write_depth_png(dir / "depth/1305031102.194330.png", ramp(10000));
  write_text(dir / "depth.txt",
             "# depth maps\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n"
             "1305031102.160407 depth/1305031102.160407.png\n1305031102.194330 depth/1305031102.194330.png\n");
  Intrinsics in;
  in.width = kW;
  in.height = kH;
  in.fx = 517.3F;
  in.fy = 516.5F;
  in.ppx = 1.5F;
  in.ppy = 1.0F;
  write_text(dir / "intrinsics.json", intrinsics_to_json(in));
  FolderSource source(RecordingParams{dir.path.string()});
  EXPECT_EQ(source.layout(), "tum");
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.timestamp_ns, 1305031102160407000LL);
  EXPECT_FLOAT_EQ(frame.depth.depth_scale_m, 0.0002F);
  EXPECT_FLOAT_EQ(frame.depth.at(0, 0) * frame.depth.depth_scale_m, 1.0F);  // 5000 units = 1 m
  EXPECT_FLOAT_EQ(frame.intrinsics.ppx, 1.5F);  // hrcsense's own file is 0-based already
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.timestamp_ns, 1305031102194330000LL);
  EXPECT_EQ(source.next(frame), Source::Status::end);
}

TEST(FolderSource, LoopsWithRisingIndicesAndTimestamps) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 2);
  FolderSource source(RecordingParams{dir.path.string(), true});
  Frame frame;
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(source.next(frame), Source::Status::frame);
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.timestamp_ns, i * 33333333LL);
    EXPECT_EQ(frame.depth.at(0, 0), 100 * (i % 2 + 1));
  }
}

TEST(FolderSource, MissingIntrinsicsIsAnErrorNamingTheFile) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 1);
  std::filesystem::remove(dir.path / "intrinsics.json");
  try {
    FolderSource source(RecordingParams{dir.path.string()});
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("intrinsics.json"), std::string::npos) << e.what();
  }
}

TEST(FolderSource, NotARecordingIsAnError) {
  ScratchDir dir("folder");
  EXPECT_THROW(FolderSource(RecordingParams{dir.path.string()}), IoError);
  EXPECT_THROW(FolderSource(RecordingParams{dir / "missing"}), IoError);
  write_text(dir / "frames.txt", "0 depth/000000.png\n");
  write_text(dir / "intrinsics.json", R"({"width": 4, "height": 3, "depth_K": [[1, 0, 0], [0, 1, 0]]})");
  EXPECT_THROW(FolderSource(RecordingParams{dir.path.string()}), IoError);  // K is 2x3
}

/// Replaces frame 2 by `damage` and checks: frames 0, 1, then one error naming file and frame.
void expect_damage_at_frame_2(const ScratchDir& dir, const std::string& what) {
  FolderSource source(RecordingParams{dir.path.string()});
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  EXPECT_EQ(frame.depth.at(0, 0), 200);
  ASSERT_EQ(source.next(frame), Source::Status::error) << what;
  const std::string error = source.error();
  EXPECT_NE(error.find("frame 2"), std::string::npos) << error;
  EXPECT_NE(error.find("000002.png"), std::string::npos) << error;
  EXPECT_EQ(source.next(frame), Source::Status::error);  // it stays failed
  EXPECT_EQ(source.error(), error);
}

TEST(FolderSource, PngOfTheWrongBitDepthMidSequenceGivesTheGoodFramesThenAnError) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 4);
  ColorImage color{kW, kH, std::vector<uint8_t>(kW * kH * 3, 7)};
  write_color_png(dir / "depth/000002.png", color);  // 8-bit RGB instead of 16-bit grey
  expect_damage_at_frame_2(dir, "8-bit PNG");
}

TEST(FolderSource, PngOfTheWrongSizeMidSequenceGivesTheGoodFramesThenAnError) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 4);
  DepthImage wide;
  wide.resize(kW + 1, kH);
  write_depth_png(dir / "depth/000002.png", wide);
  expect_damage_at_frame_2(dir, "wrong size");
}

TEST(FolderSource, TruncatedAndMissingPngsMidSequenceGiveTheGoodFramesThenAnError) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 4);
  std::vector<char> bytes = test::read_bytes(dir / "depth/000002.png");
  bytes.resize(bytes.size() / 2);
  test::write_bytes(dir / "depth/000002.png", bytes);
  expect_damage_at_frame_2(dir, "truncated PNG");
  std::filesystem::remove(dir.path / "depth/000002.png");
  expect_damage_at_frame_2(dir, "missing PNG");
}

TEST(FolderSource, DamageMidSequenceTurnsThePipelineVerdictToStop) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 4);
  DepthImage wide;
  wide.resize(kW + 1, kH);
  write_depth_png(dir / "depth/000002.png", wide);
  FolderSource source(RecordingParams{dir.path.string()});
  PipelineParams params;
  params.background.frames = 1;
  Pipeline pipeline(params);
  FixedRobotState robot_states({});  // the default robot is a point: no joints
  test::KeepingSink sink;
  const RunSummary summary = run_pipeline(source, robot_states, pipeline, sink, RunOptions{}, RunHeader{});
  EXPECT_EQ(summary.frames_in, 2);
  ASSERT_FALSE(sink.results.empty());
  const FrameResult& last = sink.results.back();
  EXPECT_EQ(last.verdict.state, VerdictState::stop);
  EXPECT_NE(last.verdict.reason.find("000002.png"), std::string::npos) << last.verdict.reason;
  EXPECT_NE(summary.end_reason.find("frame 2"), std::string::npos) << summary.end_reason;
}

TEST(FolderSource, SummaryCountsFramesAndReportsDamage) {
  ScratchDir dir("folder");
  make_dataset_folder(dir, 3);
  RecordingSummary summary = summarize_recording(dir.path.string());
  EXPECT_EQ(summary.format, RecordingFormat::folder);
  EXPECT_EQ(summary.folder_layout, "ist");
  EXPECT_EQ(recording_format_text(summary), "folder (ist layout)");
  ASSERT_EQ(summary.streams.size(), 1U);
  EXPECT_EQ(summary.streams[0].frames, 3);
  EXPECT_TRUE(summary.damage.empty()) << summary.damage;
  std::filesystem::remove(dir.path / "depth/000001.png");
  summary = summarize_recording(dir.path.string());
  EXPECT_EQ(summary.streams[0].frames, 1);
  EXPECT_NE(summary.damage.find("000001.png"), std::string::npos) << summary.damage;
}

TEST(FolderSource, ReadsTheSharedPeopleRecording) {
  const std::string path = test::shared_data("ist_piv_lab_people");
  if (path.empty()) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  FolderSource source(RecordingParams{path});
  const SourceInfo info = source.info();
  EXPECT_EQ(info.frame_count, 108);
  // README: fx = 567.8956, cx = 312.1240 in 1-based pixels, i.e. 311.1240 0-based.
  EXPECT_NEAR(info.intrinsics.fx, 567.8956, 1e-3);
  EXPECT_NEAR(info.intrinsics.fy, 568.8557, 1e-3);
  EXPECT_NEAR(info.intrinsics.ppx, 311.1240, 1e-3);
  EXPECT_NEAR(info.intrinsics.ppy, 241.5695, 1e-3);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame);
  size_t valid = 0;
  uint16_t min_mm = 65535, max_mm = 0;
  for (uint16_t raw : frame.depth.pixels) {
    if (raw == 0) continue;
    ++valid;
    min_mm = std::min(min_mm, raw);
    max_mm = std::max(max_mm, raw);
  }
  // README: 76-80 % valid, depth 568-9593 mm over the whole sequence.
  const double share = static_cast<double>(valid) / static_cast<double>(frame.depth.pixels.size());
  EXPECT_GT(share, 0.75);
  EXPECT_LT(share, 0.81);
  EXPECT_GE(min_mm, 568);
  EXPECT_LE(max_mm, 9593);
}

}  // namespace
}  // namespace hrcsense
