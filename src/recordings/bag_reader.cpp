// SPDX-License-Identifier: Apache-2.0
// hrcsense — ROS bag 2.0 records: header fields, chunks (none / lz4 frame / bz2), the index.
#include "bag_reader.hpp"

#include "hrcsense/io/io.hpp"

#include <bzlib.h>
#include <lz4frame.h>

#include <cstring>
#include <string_view>

namespace hrcsense {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr size_t kMagicBytes = sizeof(kMagic) - 1;
constexpr uint8_t kOpMessage = 0x02, kOpBagHeader = 0x03, kOpIndex = 0x04, kOpChunk = 0x05, kOpChunkInfo = 0x06,
                  kOpConnection = 0x07;
/// LZ4 expands at most ~255 times (one token byte codes up to 255 extra bytes of a match).
constexpr uint64_t kMaxLz4Ratio = 256;

uint32_t le32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}
uint64_t le64(const uint8_t* p) { return static_cast<uint64_t>(le32(p)) | static_cast<uint64_t>(le32(p + 4)) << 32; }

}  // namespace

/// The fields of a record header (or of a connection record's data) that hrcsense uses. Not in
/// the anonymous namespace: BagReader::Record holds one.
struct BagHeaderFields {
  int op = -1;
  uint32_t conn = 0, count = 0, size = 0, conn_count = 0, chunk_count = 0;
  uint64_t index_pos = 0, chunk_pos = 0;
  int64_t time_ns = -1;
  std::string_view compression, topic, type, md5sum;
  bool has_conn = false;
};

namespace {

/// Parses `name=value` fields, each prefixed by its uint32 length; "" or what is wrong.
std::string parse_fields(const uint8_t* p, size_t n, BagHeaderFields& f) {
  size_t pos = 0;
  while (pos < n) {
    if (n - pos < 4) return "header field length cut off";
    const uint32_t len = le32(p + pos);
    pos += 4;
    if (len > n - pos) return "header field of " + std::to_string(len) + " bytes runs past the header";
    const auto* field = reinterpret_cast<const char*>(p + pos);
    const void* eq = std::memchr(field, '=', len);
    if (eq == nullptr) return "header field without '='";
    const std::string_view name(field, static_cast<size_t>(static_cast<const char*>(eq) - field));
    const uint8_t* value = p + pos + name.size() + 1;
    const size_t value_len = len - name.size() - 1;
    pos += len;
    const auto u32 = [&](uint32_t& out) { return value_len == 4 ? (out = le32(value), true) : false; };
    bool ok = true;
    if (name == "op") {
      ok = value_len == 1;
      if (ok) f.op = value[0];
    } else if (name == "conn") {
      ok = f.has_conn = u32(f.conn);
    } else if (name == "count") {
      ok = u32(f.count);
    } else if (name == "size") {
      ok = u32(f.size);
    } else if (name == "conn_count") {
      ok = u32(f.conn_count);
    } else if (name == "chunk_count") {
      ok = u32(f.chunk_count);
    } else if (name == "index_pos" || name == "chunk_pos") {
      ok = value_len == 8;
      if (ok) (name == "index_pos" ? f.index_pos : f.chunk_pos) = le64(value);
    } else if (name == "time") {
      ok = value_len == 8;
      if (ok) f.time_ns = static_cast<int64_t>(le32(value)) * 1000000000LL + le32(value + 4);
    } else {
      const std::string_view text(reinterpret_cast<const char*>(value), value_len);
      if (name == "compression") f.compression = text;
      if (name == "topic") f.topic = text;
      if (name == "type") f.type = text;
      if (name == "md5sum") f.md5sum = text;
    }
    if (!ok) return "header field '" + std::string(name) + "' has " + std::to_string(value_len) + " bytes";
  }
  return {};
}

}  // namespace

/// A record's header, parsed, and where its data lies in the file.
struct BagReader::Record {
  BagHeaderFields fields;
  uint64_t data_offset = 0;
  uint32_t data_len = 0;
  uint64_t end = 0;  ///< offset of the next record
};

BagReader::BagReader(std::string path, BagLimits limits) : path_(std::move(path)), limits_(limits) {
  require_regular_file(path_, "recording");  // fopen() of a FIFO would block forever
  file_.reset(std::fopen(path_.c_str(), "rb"));
  if (!file_) throw IoError(path_ + ": cannot open");
  if (fseeko(file_.get(), 0, SEEK_END) != 0) fail(0, "cannot seek");
  file_size_ = static_cast<uint64_t>(ftello(file_.get()));
  char magic[kMagicBytes] = {};
  if (fseeko(file_.get(), 0, SEEK_SET) != 0 || std::fread(magic, 1, kMagicBytes, file_.get()) != kMagicBytes ||
      std::memcmp(magic, kMagic, kMagicBytes) != 0) {
    const bool other_version = std::memcmp(magic, kMagic, 9) == 0;  // "#ROSBAG V"
    fail(0, other_version ? "unsupported ROS bag version (only 2.0 is read)" : "not a ROS bag (wrong magic)");
  }
  LZ4F_dctx* context = nullptr;
  const bool created = !LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION));
  lz4_.reset(context);
  if (!created) fail(0, "cannot create an lz4 context");
  Record header;
  if (!read_record(kMagicBytes, header, false) || header.fields.op != kOpBagHeader) {
    fail(kMagicBytes, "expected the bag header record");
  }
  data_start_ = header.end;
  scan_pos_ = data_start_;
  const BagHeaderFields& f = header.fields;
  if (f.index_pos == 0) {
    index_problem_ = "no index (the recording was not closed)";
  } else if (f.index_pos < data_start_ || f.index_pos >= file_size_) {
    index_problem_ = "index position " + std::to_string(f.index_pos) + " lies outside the file (" +
                     std::to_string(file_size_) + " bytes; truncated?)";
  } else {
    try {
      read_index(f.index_pos, f.conn_count, f.chunk_count);
      indexed_ = true;
    } catch (const IoError& e) {
      index_problem_ = e.what();
      connections_.clear();
      indexed_counts_.clear();
      chunk_positions_.clear();
      chunk_connections_.clear();
    }
  }
}

BagReader::~BagReader() = default;

void BagReader::FileCloser::operator()(std::FILE* file) const { std::fclose(file); }
void BagReader::Lz4Freer::operator()(LZ4F_dctx_s* context) const { LZ4F_freeDecompressionContext(context); }

void BagReader::fail(uint64_t offset, const std::string& problem) const {
  throw IoError(path_ + ": byte offset " + std::to_string(offset) + ": " + problem);
}

bool BagReader::read_record(uint64_t offset, Record& record, bool whole_data) {
  if (offset == file_size_) return false;
  uint8_t len[4];
  if (file_size_ - offset < 8 || fseeko(file_.get(), static_cast<off_t>(offset), SEEK_SET) != 0 ||
      std::fread(len, 1, 4, file_.get()) != 4) {
    fail(offset, "truncated record (the file ends at " + std::to_string(file_size_) + ")");
  }
  const uint32_t header_len = le32(len);
  if (header_len > limits_.max_header_bytes || header_len > file_size_ - offset - 8) {
    fail(offset, "record header of " + std::to_string(header_len) + " bytes runs past the end of the file or limit");
  }
  header_.resize(header_len);
  if (std::fread(header_.data(), 1, header_len, file_.get()) != header_len || std::fread(len, 1, 4, file_.get()) != 4) {
    fail(offset, "cannot read the record header");
  }
  record.fields = BagHeaderFields{};
  const std::string problem = parse_fields(header_.data(), header_len, record.fields);
  if (!problem.empty()) fail(offset, problem);
  record.data_len = le32(len);
  record.data_offset = offset + 8 + header_len;
  if (record.data_len > file_size_ - record.data_offset) {
    fail(offset, "record data of " + std::to_string(record.data_len) + " bytes runs past the end of the file (" +
                     std::to_string(file_size_) + " bytes; truncated?)");
  }
  record.end = record.data_offset + record.data_len;
  if (whole_data) {
    if (record.data_len > limits_.max_header_bytes) fail(offset, "record data larger than expected");
    packed_.resize(record.data_len);
    if (std::fread(packed_.data(), 1, record.data_len, file_.get()) != record.data_len) fail(offset, "cannot read record data");
  }
  return true;
}

void BagReader::add_connection(const Record& record, uint64_t offset) {
  // Called with the connection's data in packed_ (file records) or chunk_ (inside chunks).
  if (!record.fields.has_conn) fail(offset, "connection record without 'conn'");
  BagConnection connection;
  connection.id = record.fields.conn;
  connection.topic = std::string(record.fields.topic);
  connections_[connection.id] = std::move(connection);
}

void BagReader::read_index(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count) {
  uint64_t pos = index_pos;
  Record record;
  for (uint32_t i = 0; i < conn_count; ++i) {
    if (!read_record(pos, record, true) || record.fields.op != kOpConnection) fail(pos, "expected a connection record");
    add_connection(record, pos);
    BagHeaderFields data;
    const std::string problem = parse_fields(packed_.data(), packed_.size(), data);
    if (!problem.empty()) fail(pos, "connection data: " + problem);
    connections_[record.fields.conn].type = std::string(data.type);
    connections_[record.fields.conn].md5sum = std::string(data.md5sum);
    pos = record.end;
  }
  for (uint32_t i = 0; i < chunk_count; ++i) {
    if (!read_record(pos, record, true) || record.fields.op != kOpChunkInfo) fail(pos, "expected a chunk info record");
    const uint64_t chunk_pos = record.fields.chunk_pos;
    if (chunk_pos < data_start_ || chunk_pos >= index_pos) fail(pos, "chunk position outside the chunk area");
    if (!chunk_positions_.empty() && chunk_pos <= chunk_positions_.back()) fail(pos, "chunk positions out of order");
    if (packed_.size() != static_cast<size_t>(record.fields.count) * 8) fail(pos, "chunk info size mismatch");
    std::vector<uint32_t> in_chunk;
    for (size_t k = 0; k < packed_.size(); k += 8) {
      indexed_counts_[le32(&packed_[k])] += le32(&packed_[k + 4]);
      in_chunk.push_back(le32(&packed_[k]));
    }
    chunk_positions_.push_back(chunk_pos);
    chunk_connections_.push_back(std::move(in_chunk));
    pos = record.end;
  }
}

void BagReader::load_chunk(uint64_t offset, const Record& record) {
  const BagHeaderFields& f = record.fields;
  const std::string_view compression = f.compression;
  if (compression != "none" && compression != "lz4" && compression != "bz2") {
    fail(offset, "unknown chunk compression '" + std::string(compression) + "'");
  }
  if (record.data_len > limits_.max_chunk_bytes || f.size > limits_.max_chunk_bytes) {
    fail(offset, "chunk of " + std::to_string(f.size) + " bytes exceeds the limit of " +
                     std::to_string(limits_.max_chunk_bytes));
  }
  if (compression == "lz4" && f.size > static_cast<uint64_t>(record.data_len) * kMaxLz4Ratio + 64) {
    fail(offset, "lz4 chunk claims " + std::to_string(f.size) + " bytes from " + std::to_string(record.data_len));
  }
  if (compression == "none" && f.size != record.data_len) fail(offset, "uncompressed chunk size mismatch");
  if (compressions_.find(compression) == std::string::npos) {
    compressions_ += (compressions_.empty() ? "" : "+") + std::string(compression);
  }
  std::vector<uint8_t>& target = compression == "none" ? chunk_ : packed_;
  target.resize(record.data_len);
  if (fseeko(file_.get(), static_cast<off_t>(record.data_offset), SEEK_SET) != 0 ||
      std::fread(target.data(), 1, record.data_len, file_.get()) != record.data_len) {
    fail(offset, "cannot read the chunk data");
  }
  chunk_pos_ = 0;
  chunk_offset_ = offset;
  if (compression == "none") return;
  chunk_.resize(f.size);
  if (compression == "bz2") {
    auto produced = static_cast<unsigned int>(f.size);
    const int rc = BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(chunk_.data()), &produced,
                                              reinterpret_cast<char*>(packed_.data()), record.data_len, 0, 0);
    if (rc != BZ_OK || produced != f.size) fail(offset, "bz2 chunk does not decompress (code " + std::to_string(rc) + ")");
    return;
  }
  LZ4F_resetDecompressionContext(lz4_.get());
  size_t in = 0, out = 0;
  for (;;) {
    size_t in_n = packed_.size() - in, out_n = chunk_.size() - out;
    LZ4F_decompressOptions_t options{};
    options.stableDst = 1;  // chunk_ stays put while one chunk is decompressed: no internal copies
    const size_t hint = LZ4F_decompress(lz4_.get(), chunk_.data() + out, &out_n, packed_.data() + in, &in_n, &options);
    if (LZ4F_isError(hint)) fail(offset, std::string("lz4 chunk is corrupt: ") + LZ4F_getErrorName(hint));
    in += in_n;
    out += out_n;
    if (hint == 0) break;  // the frame is complete (and its checksum verified)
    if (in_n == 0 && out_n == 0) fail(offset, "lz4 chunk ends early or holds more than its declared size");
  }
  if (out != chunk_.size()) {
    fail(offset, "lz4 chunk holds " + std::to_string(out) + " bytes, its header says " + std::to_string(f.size));
  }
}

bool BagReader::next(BagMessage& out) {
  Record record;
  for (;;) {
    if (chunk_pos_ < chunk_.size()) {
      const size_t at = chunk_pos_;
      const size_t left = chunk_.size() - at;
      const uint32_t header_len = left >= 4 ? le32(&chunk_[at]) : 0;
      if (left < 8 || header_len > left - 8 || le32(&chunk_[at + 4 + header_len]) > left - 8 - header_len) {
        fail(chunk_offset_, "record at byte " + std::to_string(at) + " of the decompressed chunk runs past its end");
      }
      const uint32_t data_len = le32(&chunk_[at + 4 + header_len]);
      record.fields = BagHeaderFields{};
      const std::string problem = parse_fields(&chunk_[at + 4], header_len, record.fields);
      if (!problem.empty()) fail(chunk_offset_, "in chunk at byte " + std::to_string(at) + ": " + problem);
      const uint8_t* data = &chunk_[at + 8 + header_len];
      chunk_pos_ = at + 8 + header_len + data_len;
      if (record.fields.op == kOpConnection) {
        add_connection(record, chunk_offset_);
        BagHeaderFields meta;
        if (parse_fields(data, data_len, meta).empty()) {
          connections_[record.fields.conn].type = std::string(meta.type);
          connections_[record.fields.conn].md5sum = std::string(meta.md5sum);
        }
        continue;
      }
      if (record.fields.op != kOpMessage || !record.fields.has_conn || record.fields.time_ns < 0) {
        fail(chunk_offset_, "unexpected record (op " + std::to_string(record.fields.op) + ") at byte " +
                                std::to_string(at) + " of the decompressed chunk");
      }
      out = BagMessage{record.fields.conn, record.fields.time_ns, data, data_len, chunk_offset_};
      return true;
    }
    if (indexed_) {
      if (next_chunk_ >= chunk_positions_.size()) return false;
      const size_t chunk = next_chunk_++;
      if (!chunk_wanted(chunk)) continue;
      const uint64_t offset = chunk_positions_[chunk];
      if (!read_record(offset, record, false) || record.fields.op != kOpChunk) fail(offset, "index points to a non-chunk");
      load_chunk(offset, record);
      continue;
    }
    const uint64_t offset = scan_pos_;
    if (!read_record(offset, record, false)) return false;
    scan_pos_ = record.end;
    const int op = record.fields.op;
    if (op == kOpChunk) {
      load_chunk(offset, record);
    } else if (op == kOpConnection) {
      read_record(offset, record, true);
      add_connection(record, offset);
    } else if (op != kOpIndex && op != kOpChunkInfo) {
      fail(offset, "unexpected record (op " + std::to_string(op) + ")");
    }
  }
}

bool BagReader::chunk_wanted(size_t chunk) const {
  if (!wanted_) return true;
  for (const uint32_t conn : chunk_connections_[chunk]) {
    const auto found = connections_.find(conn);
    if (found == connections_.end() || wanted_(found->second)) return true;  // unknown: read it
  }
  return false;
}

void BagReader::rewind() {
  next_chunk_ = 0;
  scan_pos_ = data_start_;
  chunk_.clear();
  chunk_pos_ = 0;
}

}  // namespace hrcsense
