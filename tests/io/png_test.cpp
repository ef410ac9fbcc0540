// SPDX-License-Identifier: Apache-2.0
// Tests of the depth/colour PNG reader and writers, checked against libpng's independent
// simplified API and against the real recordings in the shared data folder.

#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "hrcsense/io/io.hpp"

namespace hrcsense {
namespace {

std::string png_temp_path(const std::string& name) {
  return ::testing::TempDir() + "hrcsense_png_" + std::to_string(::getpid()) + "_" + name;
}

/// Reads a PNG through libpng's simplified API as 16-bit gray, independent of our reader.
/// For a 16-bit file without a gAMA chunk this returns the stored samples unchanged.
std::vector<uint16_t> reference_read_gray16(const std::string& path, int& width, int& height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  EXPECT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << image.message;
  image.format = PNG_FORMAT_LINEAR_Y;
  std::vector<uint16_t> pixels(PNG_IMAGE_SIZE(image) / sizeof(uint16_t));
  EXPECT_TRUE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) << image.message;
  width = static_cast<int>(image.width);
  height = static_cast<int>(image.height);
  return pixels;
}

/// Writes a PNG of another kind (8-bit gray, 16-bit RGB ...) with the simplified API.
void write_foreign_png(const std::string& path, uint32_t format, int width, int height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = format;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image), 100);
  ASSERT_TRUE(png_image_write_to_file(&image, path.c_str(), 0, pixels.data(), 0, nullptr)) << image.message;
}

DepthImage test_pattern(int width, int height) {
  DepthImage depth;
  depth.resize(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      // Covers 0, both bytes varying, and values above 32767 (which a signed reader breaks).
      depth.pixels[static_cast<size_t>(v) * width + u] =
          static_cast<uint16_t>((u * 2311 + v * 40503) % 65536);
    }
  }
  depth.pixels[0] = 0;
  depth.pixels[1] = 65535;
  depth.pixels[2] = 32768;
  depth.pixels[3] = 32767;
  depth.pixels[4] = 0x0102;  // byte order shows
  return depth;
}

std::string expect_io_error(const std::string& path) {
  DepthImage depth;
  try {
    read_depth_png(path, depth);
  } catch (const IoError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no IoError reading " << path;
  return {};
}

TEST(DepthPng, RoundTripKeepsEveryValue) {
  const std::string path = png_temp_path("round_trip.png");
  const DepthImage written = test_pattern(37, 23);  // odd sizes catch stride mistakes
  write_depth_png(path, written);

  DepthImage read;
  read.depth_scale_m = 0.0001F;
  read_depth_png(path, read);
  EXPECT_EQ(read.width, 37);
  EXPECT_EQ(read.height, 23);
  EXPECT_EQ(read.pixels, written.pixels);
  EXPECT_EQ(read.depth_scale_m, 0.0001F);  // the file does not carry it; left unchanged
  EXPECT_EQ(*std::max_element(read.pixels.begin(), read.pixels.end()), 65535);

  // An independent decoder sees the same samples: the file is a standard 16-bit PNG.
  int width = 0;
  int height = 0;
  EXPECT_EQ(reference_read_gray16(path, width, height), written.pixels);
  EXPECT_EQ(width, 37);
  EXPECT_EQ(height, 23);
  std::filesystem::remove(path);
}

TEST(DepthPng, ReadingASmallerImageReusesTheBuffer) {
  const std::string big = png_temp_path("big.png");
  const std::string small = png_temp_path("small.png");
  write_depth_png(big, test_pattern(64, 48));
  write_depth_png(small, test_pattern(8, 6));
  DepthImage depth;
  read_depth_png(big, depth);
  const uint16_t* buffer = depth.pixels.data();
  read_depth_png(small, depth);
  EXPECT_EQ(depth.pixels.data(), buffer);
  EXPECT_EQ(depth.pixels, test_pattern(8, 6).pixels);
  std::filesystem::remove(big);
  std::filesystem::remove(small);
}

TEST(DepthPng, RejectsEightBitWithTheFileName) {
  const std::string path = png_temp_path("eight_bit_gray.png");
  write_foreign_png(path, PNG_FORMAT_GRAY, 5, 4);
  const std::string message = expect_io_error(path);
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("8-bit"), std::string::npos) << message;

  const std::string rgb_path = png_temp_path("eight_bit_rgb.png");
  ColorImage color;
  color.width = 5;
  color.height = 4;
  color.rgb.assign(5 * 4 * 3, 7);
  write_color_png(rgb_path, color);
  const std::string rgb_message = expect_io_error(rgb_path);
  EXPECT_NE(rgb_message.find(rgb_path), std::string::npos) << rgb_message;
  EXPECT_NE(rgb_message.find("RGB"), std::string::npos) << rgb_message;
  std::filesystem::remove(path);
  std::filesystem::remove(rgb_path);
}

TEST(DepthPng, RejectsSixteenBitColour) {
  const std::string path = png_temp_path("sixteen_bit_rgb.png");
  write_foreign_png(path, PNG_FORMAT_LINEAR_RGB, 5, 4);
  const std::string message = expect_io_error(path);
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("16-bit RGB"), std::string::npos) << message;
  std::filesystem::remove(path);
}

TEST(DepthPng, RejectsMissingForeignAndTruncatedFiles) {
  const std::string missing = png_temp_path("does_not_exist.png");
  const std::string missing_message = expect_io_error(missing);
  EXPECT_NE(missing_message.find(missing), std::string::npos) << missing_message;
  EXPECT_NE(missing_message.find("cannot open"), std::string::npos) << missing_message;

  const std::string text = png_temp_path("not_a_png.png");
  std::ofstream(text) << "depth,values\n1,2\n";
  const std::string text_message = expect_io_error(text);
  EXPECT_NE(text_message.find(text), std::string::npos) << text_message;
  EXPECT_NE(text_message.find("not a PNG"), std::string::npos) << text_message;

  // A valid file cut in half fails inside libpng: exercises the longjmp error path.
  const std::string cut = png_temp_path("truncated.png");
  write_depth_png(cut, test_pattern(120, 90));
  std::filesystem::resize_file(cut, std::filesystem::file_size(cut) / 2);
  const std::string cut_message = expect_io_error(cut);
  EXPECT_NE(cut_message.find(cut), std::string::npos) << cut_message;
  // Cut inside the header.
  std::filesystem::resize_file(cut, 20);
  const std::string header_message = expect_io_error(cut);
  EXPECT_NE(header_message.find(cut), std::string::npos) << header_message;
  std::filesystem::remove(text);
  std::filesystem::remove(cut);
}

TEST(DepthPng, RejectsImplausibleSizesBeforeAllocating) {
  // 20000 px wide: beyond the reader's limit of 16384 px per side.
  const std::string path = png_temp_path("too_wide.png");
  write_foreign_png(path, PNG_FORMAT_LINEAR_Y, 20000, 1);
  const std::string message = expect_io_error(path);
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("width"), std::string::npos) << message;
  std::filesystem::remove(path);
}

TEST(DepthPng, WriteRejectsInconsistentSizes) {
  const std::string path = png_temp_path("bad_size.png");
  DepthImage depth = test_pattern(10, 10);
  depth.width = 11;  // pixels no longer match width · height
  EXPECT_THROW(write_depth_png(path, depth), IoError);
  EXPECT_FALSE(std::filesystem::exists(path));
  DepthImage empty;
  EXPECT_THROW(write_depth_png(path, empty), IoError);
  ColorImage color;
  color.width = 4;
  color.height = 4;
  color.rgb.assign(4 * 4, 0);  // one byte per pixel instead of three
  EXPECT_THROW(write_color_png(path, color), IoError);
}

TEST(DepthPng, WriteIntoAMissingFolderNamesTheFile) {
  const std::string path = png_temp_path("no_such_folder") + "/depth.png";
  try {
    write_depth_png(path, test_pattern(4, 4));
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(ColorPng, IndependentDecoderReadsTheSameColours) {
  const std::string path = png_temp_path("colour.png");
  ColorImage color;
  color.width = 7;
  color.height = 3;
  for (int i = 0; i < 7 * 3 * 3; ++i) {
    color.rgb.push_back(static_cast<uint8_t>(i * 37 % 256));
  }
  write_color_png(path, color);
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << image.message;
  EXPECT_EQ(image.width, 7U);
  EXPECT_EQ(image.height, 3U);
  EXPECT_EQ(image.format, static_cast<png_uint_32>(PNG_FORMAT_RGB));
  std::vector<uint8_t> rgb(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) << image.message;
  EXPECT_EQ(rgb, color.rgb);
  std::filesystem::remove(path);
}

bool shared_file_present(const std::string& path) { return std::filesystem::exists(path); }

TEST(RealData, D435SingleFrame) {
  const std::string path =
      std::string(HRCSENSE_SHARED_DIR) + "/data/librealsense_d435_single_frame/depth_0.png";
  if (!shared_file_present(path)) {
    GTEST_SKIP() << "shared data not present: " << path;
  }
  DepthImage depth;
  read_depth_png(path, depth);
  ASSERT_EQ(depth.width, 640);
  ASSERT_EQ(depth.height, 480);
  size_t valid = 0;
  uint16_t min_mm = 65535;
  uint16_t max_mm = 0;
  for (const uint16_t raw : depth.pixels) {
    if (raw != 0) {
      ++valid;
      min_mm = std::min(min_mm, raw);
      max_mm = std::max(max_mm, raw);
    }
  }
  // The recording's README: about 93 % valid pixels, depth about 0.34–3.2 m (1 count = 1 mm).
  EXPECT_NEAR(static_cast<double>(valid) / depth.pixels.size(), 0.93, 0.01);
  EXPECT_GE(min_mm, 300);
  EXPECT_LE(max_mm, 3300);
  EXPECT_GT(max_mm, 2500);  // the far wall is in view

  int width = 0;
  int height = 0;
  EXPECT_EQ(reference_read_gray16(path, width, height), depth.pixels);
}

TEST(RealData, IstLabPeopleFrame) {
  const std::string path = std::string(HRCSENSE_SHARED_DIR) + "/data/ist_piv_lab_people/depth/000000.png";
  if (!shared_file_present(path)) {
    GTEST_SKIP() << "shared data not present: " << path;
  }
  DepthImage depth;
  read_depth_png(path, depth);
  EXPECT_EQ(depth.width, 640);
  EXPECT_EQ(depth.height, 480);
  const auto valid =
      std::count_if(depth.pixels.begin(), depth.pixels.end(), [](uint16_t raw) { return raw != 0; });
  EXPECT_GT(valid, static_cast<long>(depth.pixels.size() / 2));  // a lab scene, mostly measured
  int width = 0;
  int height = 0;
  EXPECT_EQ(reference_read_gray16(path, width, height), depth.pixels);
}

}  // namespace
}  // namespace hrcsense
