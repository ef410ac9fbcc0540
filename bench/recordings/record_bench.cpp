// SPDX-License-Identifier: Apache-2.0
// Record/depth_color_<compression>/848x480: the production bag writer (hrcsense/recordings/bag_writer.hpp)
// writing config/cell-ur5.yaml's simulated 848x480 depth + rgb8 colour, with the SDK's metadata
// and chunking, into a temp file; frames/s as items_per_second (DESIGN.md's budget: LZ4 ≥ 300).
// Thirty distinct frames are rendered once and written in turn (rendering is the slow part);
// a new file every 300 frames keeps the temp file small (its close, with the index, is timed too).

#include "common/assembly.hpp"
#include "hrcsense/recordings/bag_writer.hpp"
#include "hrcsense/config/config.hpp"

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr int kDistinctRecordFrames = 30;
constexpr int kFramesPerFile = 300;

const std::vector<Frame>& cell_frames() {
  static const std::vector<Frame> frames = [] {
    const Config config = load_config(std::string(HRCSENSE_BENCH_SOURCE_DIR) + "/config/cell-ur5.yaml", {});
    const Simulator sim = make_simulator(config);
    std::vector<Frame> out(kDistinctRecordFrames);
    // Frames 150..: the person is in view, so the images are not just the empty cell.
    for (int i = 0; i < kDistinctRecordFrames; ++i) sim.render(150 + i, out[static_cast<size_t>(i)]);
    return out;
  }();
  return frames;
}

void record(benchmark::State& state, BagCompression compression) {
  std::vector<Frame> frames = cell_frames();  // a copy whose index and timestamp are set per write
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("hrcsense_bench_record_" + std::to_string(getpid()) + ".bag")).string();
  BagWriterParams params;
  params.compression = compression;
  std::unique_ptr<BagWriter> writer;
  int64_t written = 0;
  uint64_t bytes = 0;
  for (auto _ : state) {
    if (!writer || written % kFramesPerFile == 0) {
      if (writer) {
        writer->close();
        bytes += writer->bytes_written();
      }
      writer = std::make_unique<BagWriter>(path, params);
    }
    Frame& frame = frames[static_cast<size_t>(written % kDistinctRecordFrames)];
    frame.index = written;
    frame.timestamp_ns = written * 33'333'333LL;
    writer->add_frame(frame);
    ++written;
  }
  writer->close();
  bytes += writer->bytes_written();
  std::filesystem::remove(path);
  state.SetItemsProcessed(written);
  state.counters["MiB_per_frame"] = static_cast<double>(bytes) / static_cast<double>(written) / (1024.0 * 1024.0);
}

void BM_Record_848x480_depth_color_lz4(benchmark::State& state) { record(state, BagCompression::lz4); }
void BM_Record_848x480_depth_color_none(benchmark::State& state) { record(state, BagCompression::none); }

BENCHMARK(BM_Record_848x480_depth_color_lz4)->Name("Record/depth_color_lz4/848x480")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Record_848x480_depth_color_none)->Name("Record/depth_color_none/848x480")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
