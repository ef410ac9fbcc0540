// SPDX-License-Identifier: Apache-2.0
// Colour frames in folders: JPEG (libturbojpeg) and PNG decoding to rgb8, damaged images, and
// how FolderSource finds each depth frame's colour image (frames.txt, rgb/, TUM rgb.txt).
#include "recordings_test_util.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace hrcsense {
namespace {

using test::ScratchDir;
using test::write_text;

#define REQUIRE_JPEG() \
  if (!jpeg_supported()) GTEST_SKIP() << "built without libturbojpeg"

/// 32x24 in four flat quadrants: red, green / blue, white.
ColorImage quadrants() {
  ColorImage c{32, 24, std::vector<uint8_t>(32 * 24 * 3)};
  for (int v = 0; v < 24; ++v) {
    for (int u = 0; u < 32; ++u) {
      const int q = (v < 12 ? 0 : 2) + (u < 16 ? 0 : 1);
      const uint8_t rgb[4][3] = {{220, 30, 20}, {25, 200, 40}, {30, 40, 210}, {250, 250, 250}};
      for (int k = 0; k < 3; ++k) c.rgb[static_cast<size_t>((v * 32 + u) * 3 + k)] = rgb[q][k];
    }
  }
  return c;
}

void expect_colour_near(const ColorImage& c, int u, int v, int r, int g, int b) {
  const size_t at = static_cast<size_t>((v * c.width + u) * 3);
  EXPECT_NEAR(c.rgb[at], r, 12) << "at " << u << "," << v;
  EXPECT_NEAR(c.rgb[at + 1], g, 12) << "at " << u << "," << v;
  EXPECT_NEAR(c.rgb[at + 2], b, 12) << "at " << u << "," << v;
}

TEST(Jpeg, EncodedQuadrantsDecodeToTheirSizeAndApproximateColours) {
  REQUIRE_JPEG();
  ScratchDir dir("jpeg");
  write_color_jpeg(dir / "q.jpg", quadrants(), 95);
  ColorImage back;
  read_color_jpeg(dir / "q.jpg", back);
  ASSERT_EQ(back.width, 32);
  ASSERT_EQ(back.height, 24);
  ASSERT_EQ(back.rgb.size(), 32U * 24U * 3U);
  // Quadrant centres, away from the 4:2:0 chroma blur at the borders.
  expect_colour_near(back, 8, 6, 220, 30, 20);
  expect_colour_near(back, 24, 6, 25, 200, 40);
  expect_colour_near(back, 8, 18, 30, 40, 210);
  expect_colour_near(back, 24, 18, 250, 250, 250);
}

TEST(Jpeg, DamagedOrForeignFilesAreErrorsNamingTheFile) {
  ScratchDir dir("jpeg");
  const std::string garbage = dir / "garbage.jpg";
  write_text(garbage, "this is not a JPEG at all");
  try {
    ColorImage out;
    read_color_jpeg(garbage, out);
    FAIL() << "garbage decoded";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(garbage), std::string::npos) << e.what();
  }
  EXPECT_THROW(
      {
        ColorImage out;
        read_color_jpeg(dir / "missing.jpg", out);
      },
      IoError);
  REQUIRE_JPEG();
  write_color_jpeg(dir / "q.jpg", quadrants(), 95);
  std::vector<char> bytes = test::read_bytes(dir / "q.jpg");
  bytes.resize(bytes.size() / 2);  // cut in the middle of the entropy-coded data
  const std::string cut = dir / "cut.jpg";
  test::write_bytes(cut, bytes);
  try {
    ColorImage out;
    read_color_jpeg(cut, out);
    FAIL() << "a truncated JPEG decoded";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(cut), std::string::npos) << e.what();
  }
}

TEST(ColorPng, RgbPalettedAndGreyPngsDecodeToRgb8) {
  ScratchDir dir("jpeg");
  write_color_png(dir / "q.png", quadrants());
  ColorImage back;
  read_color_png(dir / "q.png", back);
  EXPECT_EQ(back.width, 32);
  EXPECT_EQ(back.height, 24);
  EXPECT_TRUE(back.rgb == quadrants().rgb);  // PNG is lossless
  DepthImage depth;
  depth.resize(2, 2);
  write_depth_png(dir / "grey16.png", depth);  // 16-bit grey: replicated, scaled to 8 bits
  read_color_png(dir / "grey16.png", back);
  EXPECT_EQ(back.rgb, std::vector<uint8_t>(12, 0));
  write_text(dir / "bad.png", "not a png");
  EXPECT_THROW(read_color_png(dir / "bad.png", back), IoError);
}

constexpr const char* kIntrinsics = R"({"pixel_convention": "1-based", "depth_units_m": 0.001, "width": 4,
  "height": 3, "depth_K": [[500, 0, 2.5], [0, 500, 2], [0, 0, 1]], "rgb_K": [[400, 0, 16.5], [0, 401, 12.5], [0, 0, 1]],
  "depth_to_rgb_R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "depth_to_rgb_T_m": [-0.025, 0.001, 0.002]})";

/// An ist-layout folder with 2 depth frames and frames.txt naming rgb/000000.jpg, rgb/000001.jpg.
void make_folder_with_jpegs(const ScratchDir& dir) {
  std::filesystem::create_directories(dir.path / "depth");
  std::filesystem::create_directories(dir.path / "rgb");
  DepthImage depth;
  depth.resize(4, 3);
  write_depth_png(dir / "depth/000000.png", depth);
  write_depth_png(dir / "depth/000001.png", depth);
  write_color_jpeg(dir / "rgb/000000.jpg", quadrants(), 95);
  write_color_jpeg(dir / "rgb/000001.jpg", quadrants(), 95);
  write_text(dir / "frames.txt", "0 depth/000000.png rgb/000000.jpg\n1 depth/000001.png rgb/000001.jpg\n");
  write_text(dir / "intrinsics.json", kIntrinsics);
}

TEST(FolderColour, JpegColourIsDecodedWithItsCalibrationOnlyWhenAskedFor) {
  REQUIRE_JPEG();
  ScratchDir dir("jpeg");
  make_folder_with_jpegs(dir);
  Frame frame;
  FolderSource depth_only(RecordingParams{dir.path.string()});
  ASSERT_EQ(depth_only.next(frame), Source::Status::frame) << depth_only.error();
  EXPECT_FALSE(frame.color.has_value());
  RecordingParams params{dir.path.string()};
  params.with_color = true;
  FolderSource source(params);
  ASSERT_EQ(source.color_files().size(), 2U);
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
    ASSERT_TRUE(frame.color.has_value());
    EXPECT_EQ(frame.color->width, 32);
    EXPECT_EQ(frame.color->height, 24);
    expect_colour_near(*frame.color, 24, 18, 250, 250, 250);
    EXPECT_EQ(frame.color_intrinsics.width, 32);
    EXPECT_EQ(frame.color_intrinsics.height, 24);
    EXPECT_FLOAT_EQ(frame.color_intrinsics.fx, 400.0F);
    EXPECT_FLOAT_EQ(frame.color_intrinsics.fy, 401.0F);
    EXPECT_FLOAT_EQ(frame.color_intrinsics.ppx, 15.5F);  // 1-based → 0-based
    EXPECT_FLOAT_EQ(frame.color_intrinsics.ppy, 11.5F);
    ASSERT_TRUE(frame.depth_to_color.has_value());
    EXPECT_FLOAT_EQ(frame.depth_to_color->translation_m[0], -0.025F);
    EXPECT_FLOAT_EQ(frame.depth_to_color->translation_m[2], 0.002F);
  }
  EXPECT_EQ(source.next(frame), Source::Status::end);
}

TEST(FolderColour, DamagedJpegGivesTheGoodFramesThenAnErrorNamingFileAndFrame) {
  REQUIRE_JPEG();
  ScratchDir dir("jpeg");
  make_folder_with_jpegs(dir);
  std::vector<char> bytes = test::read_bytes(dir / "rgb/000001.jpg");
  bytes.resize(bytes.size() / 2);
  test::write_bytes(dir / "rgb/000001.jpg", bytes);
  RecordingParams params{dir.path.string()};
  params.with_color = true;
  FolderSource source(params);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
  ASSERT_EQ(source.next(frame), Source::Status::error);
  EXPECT_NE(source.error().find("frame 1"), std::string::npos) << source.error();
  EXPECT_NE(source.error().find("rgb/000001.jpg"), std::string::npos) << source.error();
  EXPECT_EQ(source.next(frame), Source::Status::error);
}

TEST(FolderColour, WithoutFramesTxtColourIsFoundBesideTheDepthByName) {
  ScratchDir dir("jpeg");
  std::filesystem::create_directories(dir.path / "depth");
  std::filesystem::create_directories(dir.path / "rgb");
  DepthImage depth;
  depth.resize(4, 3);
  write_depth_png(dir / "depth/a.png", depth);
  write_depth_png(dir / "depth/b.png", depth);
  write_color_png(dir / "rgb/b.png", quadrants());
  write_text(dir / "intrinsics.json", kIntrinsics);
  RecordingParams params{dir.path.string()};
  params.with_color = true;
  FolderSource source(params);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
  EXPECT_FALSE(frame.color.has_value());  // a.png has no colour
  ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
  ASSERT_TRUE(frame.color.has_value());
  EXPECT_TRUE(frame.color->rgb == quadrants().rgb);
}

TEST(FolderColour, TumPairsEachDepthWithTheNearestColourWithin20Ms) {
  ScratchDir dir("jpeg");
  std::filesystem::create_directories(dir.path / "depth");
  std::filesystem::create_directories(dir.path / "rgb");
  DepthImage depth;
  depth.resize(4, 3);
  for (const char* name : {"depth/1.png", "depth/2.png", "depth/3.png"}) write_depth_png(dir / name, depth);
  for (const char* name : {"rgb/x.png", "rgb/y.png", "rgb/z.png"}) write_color_png(dir / name, quadrants());
  write_text(dir / "depth.txt", "# t file\n100.000 depth/1.png\n100.050 depth/2.png\n100.100 depth/3.png\n");
  // y is nearer to depth 2 than z (listed out of order on purpose); nothing is near depth 3.
  write_text(dir / "rgb.txt", "100.012 rgb/x.png\n100.065 rgb/z.png\n100.041 rgb/y.png\n");
  write_text(dir / "intrinsics.json", R"({"width": 4, "height": 3, "fx": 5, "fy": 5, "ppx": 2, "ppy": 1.5,
    "model": "None", "coeffs": [0, 0, 0, 0, 0]})");
  FolderSource source(RecordingParams{dir.path.string()});
  ASSERT_EQ(source.color_files().size(), 3U);
  EXPECT_EQ(source.color_files()[0], dir / "rgb/x.png");
  EXPECT_EQ(source.color_files()[1], dir / "rgb/y.png");
  EXPECT_EQ(source.color_files()[2], "");
}

TEST(FolderColour, ColourFromTheSharedPeopleRecording) {
  REQUIRE_JPEG();
  const std::string folder = test::shared_data("ist_piv_lab_people");
  if (folder.empty()) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  RecordingParams params{folder};
  params.with_color = true;
  FolderSource source(params);
  Frame frame;
  ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
  ASSERT_TRUE(frame.color.has_value());
  EXPECT_EQ(frame.color->width, 640);  // README: colour, 640x480 JPEG
  EXPECT_EQ(frame.color->height, 480);
  EXPECT_NEAR(frame.color_intrinsics.fx, 534.2856, 1e-3);
  EXPECT_NEAR(frame.color_intrinsics.ppx, 309.5674 - 1.0, 1e-3);
  ASSERT_TRUE(frame.depth_to_color.has_value());
  EXPECT_NEAR(frame.depth_to_color->translation_m[0], -0.02631, 1e-5);
}

}  // namespace
}  // namespace hrcsense
