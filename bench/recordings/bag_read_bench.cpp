// SPDX-License-Identifier: Apache-2.0
// BagRead/<variant>/848x480: BagSource reading a bag of simulated 848x480 depth written by the
// test bag writer (tests/support/bag_writer.hpp) into a temp file, one chunk per frame as the
// SDK writes them; frames/s as items_per_second. The file is small enough to stay in the page
// cache, so this measures parsing and decompression, not the disk. Counters rss_start_MiB and
// rss_end_MiB (resident memory after the first 100 frames and at the end) show that memory stays
// flat however many frames are read (loop: true replays the file).

#include "tests/support/bag_writer.hpp"
#include "../common/thesis_scene.hpp"

#include "hrcsense/recordings/recordings.hpp"

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace hrcsense {
namespace {

constexpr int kBagFrames = 300;
constexpr int kDistinctFrames = 30;  // rendered once, written in turn: rendering is the slow part

struct BagKind {
  test::BagCompression compression = test::BagCompression::lz4;
  bool color = false;
};

/// Resident memory now (VmRSS), MiB.
double rss_mib() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kib = 0.0;
      status >> kib;
      return kib / 1024.0;
    }
    status.ignore(1 << 12, '\n');
  }
  return 0.0;
}

/// The bag for `kind`, written on first use into the temp folder and removed at exit.
const std::string& bag_path(const BagKind& kind) {
  struct Files {
    std::map<int, std::string> paths;
    ~Files() {
      for (const auto& [key, path] : paths) std::filesystem::remove(path);
    }
  };
  static Files files;
  const int key = (kind.compression == test::BagCompression::lz4 ? 1 : 0) + (kind.color ? 2 : 0);
  auto found = files.paths.find(key);
  if (found != files.paths.end()) return found->second;
  static std::vector<Frame> frames;
  if (frames.empty()) {
    const Simulator sim = bench::thesis_box_simulator();
    frames.resize(kDistinctFrames);
    for (int i = 0; i < kDistinctFrames; ++i) sim.render(bench::kLearnFrames + i, frames[static_cast<size_t>(i)]);
  }
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("hrcsense_bench_" + std::to_string(getpid()) + "_" + std::to_string(key) + ".bag"))
                               .string();
  test::BagWriterParams params;
  params.compression = kind.compression;
  test::BagWriter writer(path, params);
  ColorImage color{848, 480, std::vector<uint8_t>(848 * 480 * 3)};
  for (int i = 0; i < kBagFrames; ++i) {
    Frame frame = frames[static_cast<size_t>(i % kDistinctFrames)];
    frame.index = i;
    frame.timestamp_ns = i * 33'333'333LL;
    writer.add_depth(frame);
    if (kind.color) {
      // A smooth image, as LZ4 sees a real one: mostly gradients.
      for (size_t p = 0; p < color.rgb.size(); ++p) color.rgb[p] = static_cast<uint8_t>((p / 3 + p % 3 * 50 + i) / 16);
      writer.add_color(frame.timestamp_ns + 1000, static_cast<uint32_t>(frame.index), color, frame.intrinsics);
    }
  }
  writer.close();
  return files.paths.emplace(key, path).first->second;
}

void BM_BagRead(benchmark::State& state, BagKind kind, bool with_color) {
  RecordingParams params{bag_path(kind)};
  params.loop = true;
  params.with_color = with_color;
  BagSource source(params);
  Frame frame;
  for (int i = 0; i < 100; ++i) source.next(frame);  // warm: buffers sized, file in the cache
  const double rss_start = rss_mib();
  for (auto _ : state) {
    if (source.next(frame) != Source::Status::frame) {
      state.SkipWithError(source.error().c_str());
      break;
    }
    benchmark::DoNotOptimize(frame.depth.pixels.data());
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["rss_start_MiB"] = rss_start;
  state.counters["rss_end_MiB"] = rss_mib();
}

BENCHMARK_CAPTURE(BM_BagRead, lz4, BagKind{test::BagCompression::lz4, false}, false)
    ->Name("BagRead/lz4/848x480")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_BagRead, none, BagKind{test::BagCompression::none, false}, false)
    ->Name("BagRead/none/848x480")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_BagRead, lz4_color_skipped, BagKind{test::BagCompression::lz4, true}, false)
    ->Name("BagRead/lz4+color_skipped/848x480")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_BagRead, lz4_color_decoded, BagKind{test::BagCompression::lz4, true}, true)
    ->Name("BagRead/lz4+color_decoded/848x480")->Unit(benchmark::kMicrosecond);
// A long recording: 3000 frames (ten laps of the 300-frame bag) per run; rss_end_MiB must stay
// at rss_start_MiB.
BENCHMARK_CAPTURE(BM_BagRead, lz4_long, BagKind{test::BagCompression::lz4, false}, false)
    ->Name("BagRead/lz4_3000_frames/848x480")->Iterations(3000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense
