// SPDX-License-Identifier: Apache-2.0
// hrcsense — the background model file: a versioned, checksummed little-endian binary format.
//
// Layout (all integers and floats little-endian):
//   offset 0   8 bytes  magic "HRCSBKGD"
//   offset 8   uint32   format version (1)
//   offset 12  uint32   width, pixels
//   offset 16  uint32   height, pixels
//   offset 20  float32  mean_m[width·height], then spread_m[…], then valid_ratio[…] (row-major)
//   last 4     uint32   CRC-32 (IEEE 802.3, as zlib's crc32) of every byte before it

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "hrcsense/io/io.hpp"
#include "io_fail.hpp"

namespace hrcsense {
namespace {

constexpr std::array<char, 8> kMagic = {'H', 'R', 'C', 'S', 'B', 'K', 'G', 'D'};
constexpr uint32_t kVersion = 1;
constexpr size_t kHeaderBytes = 20;
constexpr size_t kChecksumBytes = 4;
/// Largest side accepted on load, so that a damaged size field cannot request a huge buffer
/// even before it is compared with the file length.
constexpr uint32_t kMaxSidePx = 16384;

using io_detail::fail;

std::array<uint32_t, 256> make_crc_table() {
  std::array<uint32_t, 256> table{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int bit = 0; bit < 8; ++bit) {
      c = (c & 1U) ? 0xEDB88320U ^ (c >> 1) : c >> 1;  // reflected polynomial 0x04C11DB7
    }
    table[i] = c;
  }
  return table;
}

uint32_t crc32(const uint8_t* data, size_t size) {
  static const std::array<uint32_t, 256> table = make_crc_table();
  uint32_t crc = 0xFFFFFFFFU;
  for (size_t i = 0; i < size; ++i) {
    crc = table[(crc ^ data[i]) & 0xFFU] ^ (crc >> 8);
  }
  return crc ^ 0xFFFFFFFFU;
}

void put_u32(std::vector<uint8_t>& bytes, uint32_t value) {
  for (int shift = 0; shift < 32; shift += 8) {
    bytes.push_back(static_cast<uint8_t>(value >> shift));
  }
}

uint32_t get_u32(const uint8_t* bytes) {
  return static_cast<uint32_t>(bytes[0]) | static_cast<uint32_t>(bytes[1]) << 8 |
         static_cast<uint32_t>(bytes[2]) << 16 | static_cast<uint32_t>(bytes[3]) << 24;
}

void put_floats(std::vector<uint8_t>& bytes, const std::vector<float>& values) {
  for (const float value : values) {
    uint32_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));
    put_u32(bytes, bits);
  }
}

void get_floats(const uint8_t* bytes, size_t count, std::vector<float>& values) {
  values.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const uint32_t bits = get_u32(bytes + 4 * i);
    std::memcpy(&values[i], &bits, sizeof(bits));
  }
}

std::string size_text(uint32_t width, uint32_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

/// Reads the whole file after checking that its length matches the header's size fields.
std::vector<uint8_t> read_checked_bytes(const std::string& path, uint32_t& width, uint32_t& height) {
  require_regular_file(path, "background file");  // opening a FIFO would block forever
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) {
    fail(path, std::string("cannot open background file: ") + std::strerror(errno));
  }
  const auto file_bytes = static_cast<uint64_t>(in.tellg());
  in.seekg(0);
  std::array<uint8_t, kHeaderBytes> header{};
  in.read(reinterpret_cast<char*>(header.data()), static_cast<std::streamsize>(header.size()));
  const auto header_read = static_cast<size_t>(in.gcount());
  if (header_read == 0) {
    fail(path, "empty background file");
  }
  if (header_read < kMagic.size() || std::memcmp(header.data(), kMagic.data(), kMagic.size()) != 0) {
    fail(path, "not an hrcsense background file (wrong magic; expected \"HRCSBKGD\")");
  }
  if (header_read < kHeaderBytes) {
    fail(path, "truncated background file: " + std::to_string(file_bytes) + " bytes, shorter than its " +
                   std::to_string(kHeaderBytes) + "-byte header");
  }
  const uint32_t version = get_u32(header.data() + 8);
  if (version != kVersion) {
    fail(path, "unsupported background file version " + std::to_string(version) +
                   " (this build reads version " + std::to_string(kVersion) + ")");
  }
  width = get_u32(header.data() + 12);
  height = get_u32(header.data() + 16);
  if (width == 0 || height == 0 || width > kMaxSidePx || height > kMaxSidePx) {
    fail(path, "implausible size fields " + size_text(width, height) + " in the header (damaged file?)");
  }
  const uint64_t expected = kHeaderBytes + 12ULL * width * height + kChecksumBytes;
  if (file_bytes < expected) {
    fail(path, "truncated background file: " + size_text(width, height) + " needs " +
                   std::to_string(expected) + " bytes, the file has " + std::to_string(file_bytes));
  }
  if (file_bytes > expected) {
    fail(path, "size fields do not match the file length: " + size_text(width, height) + " needs " +
                   std::to_string(expected) + " bytes, the file has " + std::to_string(file_bytes));
  }
  std::vector<uint8_t> bytes(expected);  // allocated only from a size the file length confirms
  in.seekg(0);
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<uint64_t>(in.gcount()) != expected) {
    fail(path,
         "read error: got " + std::to_string(in.gcount()) + " of " + std::to_string(expected) + " bytes");
  }
  return bytes;
}

/// A file that passed its checksum but holds values no learner produces was written by a
/// broken writer; refuse it rather than subtract a nonsense background.
void check_values(const std::string& path, const BackgroundModel& model) {
  for (size_t i = 0; i < model.mean_m.size(); ++i) {
    const bool ok = std::isfinite(model.mean_m[i]) && model.mean_m[i] >= 0.0F &&
                    std::isfinite(model.spread_m[i]) && model.spread_m[i] >= 0.0F &&
                    model.valid_ratio[i] >= 0.0F && model.valid_ratio[i] <= 1.0F;
    if (!ok) {
      fail(path, "value out of range at pixel " + std::to_string(i) + " (mean_m " +
                     std::to_string(model.mean_m[i]) + ", spread_m " + std::to_string(model.spread_m[i]) +
                     ", valid_ratio " + std::to_string(model.valid_ratio[i]) + ")");
    }
  }
}

}  // namespace

void save_background(const std::string& path, const BackgroundModel& model) {
  if (model.width <= 0 || model.height <= 0 || static_cast<uint32_t>(model.width) > kMaxSidePx ||
      static_cast<uint32_t>(model.height) > kMaxSidePx) {
    fail(path, "cannot save a background model of size " + std::to_string(model.width) + "x" +
                   std::to_string(model.height));
  }
  const size_t pixels = static_cast<size_t>(model.width) * static_cast<size_t>(model.height);
  if (model.mean_m.size() != pixels || model.spread_m.size() != pixels ||
      model.valid_ratio.size() != pixels) {
    fail(path, "background model arrays do not match its size " + std::to_string(model.width) + "x" +
                   std::to_string(model.height));
  }
  std::vector<uint8_t> bytes;
  bytes.reserve(kHeaderBytes + 12 * pixels + kChecksumBytes);
  bytes.insert(bytes.end(), kMagic.begin(), kMagic.end());
  put_u32(bytes, kVersion);
  put_u32(bytes, static_cast<uint32_t>(model.width));
  put_u32(bytes, static_cast<uint32_t>(model.height));
  put_floats(bytes, model.mean_m);
  put_floats(bytes, model.spread_m);
  put_floats(bytes, model.valid_ratio);
  put_u32(bytes, crc32(bytes.data(), bytes.size()));

  // Write beside the target and rename, so an interrupted save never leaves a damaged file
  // under the name a later run will load.
  const std::string partial = path + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (!out) {
      fail(path, std::string("cannot open for writing: ") + std::strerror(errno));
    }
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      std::remove(partial.c_str());
      fail(path, "write failed (disk full?)");
    }
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(partial.c_str());
    fail(path, "cannot replace the file: " + reason);
  }
}

BackgroundModel load_background(const std::string& path) {
  uint32_t width = 0;
  uint32_t height = 0;
  const std::vector<uint8_t> bytes = read_checked_bytes(path, width, height);
  const size_t body = bytes.size() - kChecksumBytes;
  const uint32_t stored = get_u32(bytes.data() + body);
  const uint32_t computed = crc32(bytes.data(), body);
  if (stored != computed) {
    char detail[96];
    std::snprintf(detail, sizeof(detail), "checksum mismatch (stored 0x%08X, computed 0x%08X)", stored,
                  computed);
    fail(path, std::string(detail) + ": the file is damaged");
  }
  BackgroundModel model;
  model.width = static_cast<int>(width);
  model.height = static_cast<int>(height);
  const size_t pixels = static_cast<size_t>(width) * height;
  const uint8_t* data = bytes.data() + kHeaderBytes;
  get_floats(data, pixels, model.mean_m);
  get_floats(data + 4 * pixels, pixels, model.spread_m);
  get_floats(data + 8 * pixels, pixels, model.valid_ratio);
  check_values(path, model);
  return model;
}

}  // namespace hrcsense
