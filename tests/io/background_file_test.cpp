// SPDX-License-Identifier: Apache-2.0
// Tests of the background model file: exact round trip, the documented layout, and one test
// per kind of damage, each expecting an IoError that names the file.

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "hrcsense/io/io.hpp"

namespace hrcsense {
namespace {

constexpr int kWidth = 7;
constexpr int kHeight = 5;
constexpr size_t kPixels = kWidth * kHeight;
constexpr size_t kFileBytes = 20 + 12 * kPixels + 4;  // header, three float arrays, CRC

std::string temp_path(const std::string& name) {
  return ::testing::TempDir() + "hrcsense_bg_" + std::to_string(::getpid()) + "_" + name;
}

BackgroundModel sample_model() {
  BackgroundModel model;
  model.width = kWidth;
  model.height = kHeight;
  for (size_t i = 0; i < kPixels; ++i) {
    const bool never_valid = i % 6 == 0;
    model.mean_m.push_back(never_valid ? 0.0F : 0.3F + 0.0731F * static_cast<float>(i));
    model.spread_m.push_back(never_valid ? 0.0F : 1e-3F * static_cast<float>(i % 9) + 1.5e-4F);
    model.valid_ratio.push_back(never_valid ? 0.0F : static_cast<float>(i % 10 + 1) / 10.0F);
  }
  return model;
}

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

uint32_t le_u32(const std::vector<uint8_t>& bytes, size_t offset) {
  return static_cast<uint32_t>(bytes[offset]) | static_cast<uint32_t>(bytes[offset + 1]) << 8 |
         static_cast<uint32_t>(bytes[offset + 2]) << 16 | static_cast<uint32_t>(bytes[offset + 3]) << 24;
}

void set_le_u32(std::vector<uint8_t>& bytes, size_t offset, uint32_t value) {
  for (int i = 0; i < 4; ++i) {
    bytes[offset + i] = static_cast<uint8_t>(value >> (8 * i));
  }
}

/// Re-seals a deliberately edited file with a valid CRC (zlib's, independent of ours), so
/// that the test reaches the check it means to exercise.
void reseal(std::vector<uint8_t>& bytes) {
  const size_t body = bytes.size() - 4;
  set_le_u32(bytes, body, static_cast<uint32_t>(crc32(0L, bytes.data(), static_cast<uInt>(body))));
}

/// Saves a good file, lets `damage` edit its bytes, and returns the load error message.
template <typename Damage>
std::string load_error_after(const std::string& name, Damage damage) {
  const std::string path = temp_path(name);
  save_background(path, sample_model());
  std::vector<uint8_t> bytes = read_bytes(path);
  damage(bytes);
  write_bytes(path, bytes);
  std::string message;
  try {
    load_background(path);
    ADD_FAILURE() << "no IoError for " << name;
  } catch (const IoError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find(path), std::string::npos) << message;
  std::filesystem::remove(path);
  return message;
}

TEST(BackgroundFile, RoundTripIsExact) {
  const std::string path = temp_path("round_trip.bg");
  const BackgroundModel saved = sample_model();
  save_background(path, saved);
  const BackgroundModel loaded = load_background(path);
  EXPECT_EQ(loaded.width, kWidth);
  EXPECT_EQ(loaded.height, kHeight);
  EXPECT_EQ(loaded.mean_m, saved.mean_m);  // bit-exact floats
  EXPECT_EQ(loaded.spread_m, saved.spread_m);
  EXPECT_EQ(loaded.valid_ratio, saved.valid_ratio);
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
  std::filesystem::remove(path);
}

TEST(BackgroundFile, LayoutIsTheDocumentedLittleEndianFormat) {
  const std::string path = temp_path("layout.bg");
  const BackgroundModel model = sample_model();
  save_background(path, model);
  const std::vector<uint8_t> bytes = read_bytes(path);
  ASSERT_EQ(bytes.size(), kFileBytes);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 8), "HRCSBKGD");
  EXPECT_EQ(le_u32(bytes, 8), 1U);  // version
  EXPECT_EQ(le_u32(bytes, 12), static_cast<uint32_t>(kWidth));
  EXPECT_EQ(le_u32(bytes, 16), static_cast<uint32_t>(kHeight));
  // Second pixel of the spread array.
  float spread = 0.0F;
  const uint32_t bits = le_u32(bytes, 20 + 4 * kPixels + 4);
  std::memcpy(&spread, &bits, sizeof(spread));
  EXPECT_EQ(spread, model.spread_m[1]);
  // The trailer is the standard CRC-32 of everything before it (as zlib computes it).
  EXPECT_EQ(le_u32(bytes, kFileBytes - 4), crc32(0L, bytes.data(), static_cast<uInt>(kFileBytes - 4)));
  std::filesystem::remove(path);
}

TEST(BackgroundFile, FlippedByteIsAChecksumMismatch) {
  const std::string message = load_error_after("flipped.bg", [](std::vector<uint8_t>& bytes) {
    bytes[20 + 4 * kPixels + 3] ^= 0x10;  // inside the spread array
  });
  EXPECT_NE(message.find("checksum"), std::string::npos) << message;
}

TEST(BackgroundFile, FlippedChecksumByteIsAMismatch) {
  const std::string message =
      load_error_after("flipped_crc.bg", [](std::vector<uint8_t>& bytes) { bytes.back() ^= 0x01; });
  EXPECT_NE(message.find("checksum"), std::string::npos) << message;
}

TEST(BackgroundFile, TruncatedFile) {
  const std::string message =
      load_error_after("truncated.bg", [](std::vector<uint8_t>& bytes) { bytes.resize(bytes.size() - 10); });
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
}

TEST(BackgroundFile, TruncatedInsideTheHeader) {
  const std::string message =
      load_error_after("truncated_header.bg", [](std::vector<uint8_t>& bytes) { bytes.resize(14); });
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
}

TEST(BackgroundFile, WrongMagic) {
  const std::string message = load_error_after("magic.bg", [](std::vector<uint8_t>& bytes) {
    bytes[0] = 'P';
    reseal(bytes);
  });
  EXPECT_NE(message.find("magic"), std::string::npos) << message;
}

TEST(BackgroundFile, UnsupportedVersion) {
  const std::string message = load_error_after("version.bg", [](std::vector<uint8_t>& bytes) {
    set_le_u32(bytes, 8, 2);
    reseal(bytes);
  });
  EXPECT_NE(message.find("version 2"), std::string::npos) << message;
}

TEST(BackgroundFile, SizeFieldsThatDoNotMatchTheLength) {
  const std::string larger = load_error_after("size_larger.bg", [](std::vector<uint8_t>& bytes) {
    set_le_u32(bytes, 12, kWidth + 1);  // needs more bytes than the file has
    reseal(bytes);
  });
  EXPECT_NE(larger.find("needs"), std::string::npos) << larger;
  const std::string smaller = load_error_after("size_smaller.bg", [](std::vector<uint8_t>& bytes) {
    set_le_u32(bytes, 16, kHeight - 1);  // the file has more bytes than the size says
    reseal(bytes);
  });
  EXPECT_NE(smaller.find("do not match"), std::string::npos) << smaller;
  // A huge size must be refused before anything is allocated from it.
  const std::string huge = load_error_after("size_huge.bg", [](std::vector<uint8_t>& bytes) {
    set_le_u32(bytes, 12, 0xFFFFFFFFU);
    set_le_u32(bytes, 16, 0xFFFFFFFFU);
  });
  EXPECT_NE(huge.find("size"), std::string::npos) << huge;
}

TEST(BackgroundFile, ValuesNoLearnerProducesAreRefused) {
  const std::string message = load_error_after("nan.bg", [](std::vector<uint8_t>& bytes) {
    set_le_u32(bytes, 20, 0x7FC00000U);  // mean_m[0] = NaN, correctly checksummed
    reseal(bytes);
  });
  EXPECT_NE(message.find("pixel 0"), std::string::npos) << message;
}

TEST(BackgroundFile, MissingAndEmptyFiles) {
  const std::string missing = temp_path("missing.bg");
  try {
    load_background(missing);
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string empty = load_error_after("empty.bg", [](std::vector<uint8_t>& bytes) { bytes.clear(); });
  EXPECT_NE(empty.find("empty"), std::string::npos) << empty;
}

TEST(BackgroundFile, SaveRefusesInconsistentModels) {
  const std::string path = temp_path("inconsistent.bg");
  BackgroundModel model = sample_model();
  model.spread_m.pop_back();
  EXPECT_THROW(save_background(path, model), IoError);
  EXPECT_THROW(save_background(path, BackgroundModel{}), IoError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace hrcsense
