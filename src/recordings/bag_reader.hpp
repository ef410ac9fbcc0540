// SPDX-License-Identifier: Apache-2.0
// hrcsense — ROS bag 2.0 records (../shared/specs/realsense-bag-format.md §1–2): the bag header,
// chunks (none / lz4 / bz2), connections, the index; messages in file order.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

struct LZ4F_dctx_s;

namespace hrcsense {

/// Limits that keep a damaged or hostile file from making the reader allocate without bound:
/// every buffer is sized from a length field only after checking it against these and
/// against the bytes actually left in the file.
struct BagLimits {
  uint64_t max_chunk_bytes = 64ULL << 20;   ///< largest chunk, compressed or not (64 MiB)
  uint32_t max_header_bytes = 1U << 20;     ///< largest record header (1 MiB)
};

/// A connection: a topic with its message type.
struct BagConnection {
  uint32_t id = 0;
  std::string topic;
  std::string type;
  std::string md5sum;
};

/// One message, pointing into the reader's chunk buffer: valid until the next call to next().
struct BagMessage {
  uint32_t conn = 0;
  int64_t time_ns = 0;          ///< bag (receive) time
  const uint8_t* data = nullptr;
  size_t size = 0;
  uint64_t chunk_offset = 0;    ///< byte offset of the chunk record in the file (for errors)
};

/// Reads a bag's messages in file order. Every error is an IoError whose message names the
/// file and the byte offset of the damaged record.
class BagReader {
 public:
  /// Opens `path`, checks the magic and the bag header, and reads the index when there is a
  /// usable one (else falls back to scanning the chunks in file order).
  explicit BagReader(std::string path, BagLimits limits = {});
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  /// The next message in file order; false at the end of the bag. Throws IoError on damage.
  bool next(BagMessage& out);
  /// Starts over at the first chunk (connections stay known).
  void rewind();
  /// Indexed bags only: chunks whose messages all belong to connections for which `wanted`
  /// returns false are skipped without being read or decompressed (e.g. colour nobody asked
  /// for). Their messages are then never returned. Unindexed bags are read whole.
  void set_wanted(std::function<bool(const BagConnection&)> wanted) { wanted_ = std::move(wanted); }

  const std::string& path() const { return path_; }
  bool indexed() const { return indexed_; }
  /// Why the index was not used ("" when it was, or when the bag has none).
  const std::string& index_problem() const { return index_problem_; }
  /// Connections seen so far (all of them at once when indexed), by id.
  const std::map<uint32_t, BagConnection>& connections() const { return connections_; }
  /// Compressions of the chunks read so far, e.g. "lz4" or "lz4+none".
  const std::string& compressions() const { return compressions_; }
  /// Messages per connection from the index (empty when not indexed).
  const std::map<uint32_t, uint64_t>& indexed_counts() const { return indexed_counts_; }

 private:
  struct Record;
  bool read_record(uint64_t offset, Record& record, bool whole_data);
  void read_index(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count);
  void load_chunk(uint64_t offset, const Record& record);
  bool chunk_wanted(size_t chunk) const;
  void add_connection(const Record& record, uint64_t offset);
  [[noreturn]] void fail(uint64_t offset, const std::string& problem) const;

  std::string path_;
  BagLimits limits_;
  /// Owned handles, so that a constructor that throws half-way leaks nothing.
  struct FileCloser {
    void operator()(std::FILE* file) const;
  };
  struct Lz4Freer {
    void operator()(LZ4F_dctx_s* context) const;
  };
  std::unique_ptr<std::FILE, FileCloser> file_;
  uint64_t file_size_ = 0;
  uint64_t data_start_ = 0;         ///< first record after the bag header
  bool indexed_ = false;
  std::string index_problem_;
  std::vector<uint64_t> chunk_positions_;  ///< from the index
  std::vector<std::vector<uint32_t>> chunk_connections_;  ///< from the index: connections per chunk
  std::function<bool(const BagConnection&)> wanted_;
  size_t next_chunk_ = 0;           ///< indexed: next entry of chunk_positions_
  uint64_t scan_pos_ = 0;           ///< not indexed: next record in the file
  std::map<uint32_t, BagConnection> connections_;
  std::map<uint32_t, uint64_t> indexed_counts_;
  std::string compressions_;
  std::vector<uint8_t> header_;     ///< the current record's header
  std::vector<uint8_t> packed_;     ///< the current chunk's compressed data
  std::vector<uint8_t> chunk_;      ///< the current chunk, decompressed
  size_t chunk_pos_ = 0;            ///< next record inside chunk_
  uint64_t chunk_offset_ = 0;
  std::unique_ptr<LZ4F_dctx_s, Lz4Freer> lz4_;
};

}  // namespace hrcsense
