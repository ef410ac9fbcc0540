// SPDX-License-Identifier: Apache-2.0
// Replays the fuzzers' seed corpus (fuzz/corpus/) and every crash reproducer kept in
// fuzz/regressions/ through the fuzz targets' own entry code (fuzz/fuzz_entries.cpp), built
// with GCC here: no crash, no sanitizer report (asan preset), a clean end or a clean error.
#include "fuzz/fuzz_entries.hpp"
#include "recordings_test_util.hpp"

#include "hrcsense/io/io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> files_under(const std::string& relative) {
  std::vector<fs::path> files;
  const fs::path root = fs::path(HRCSENSE_SOURCE_DIR) / relative;
  if (!fs::is_directory(root)) return files;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(root)) {
    if (entry.is_regular_file() && entry.path().filename().string()[0] != '.') files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// A fuzz target's entry code (fuzz/fuzz_entries.hpp).
using FuzzEntry = fuzz::Outcome (*)(const uint8_t* data, size_t size);

fuzz::Outcome replay(const fs::path& file, FuzzEntry entry) {
  const std::vector<char> bytes = test::read_bytes(file.string());
  return entry(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
}

TEST(FuzzCorpus, SeedBagsAreValidRecordings) {
  const std::vector<fs::path> seeds = files_under("fuzz/corpus/bag");
  ASSERT_GE(seeds.size(), 3U) << "fuzz/corpus/bag is missing";
  for (const fs::path& seed : seeds) {
    const fuzz::Outcome outcome = replay(seed, fuzz::run_bag);
    EXPECT_EQ(outcome.error, "") << seed;
    EXPECT_EQ(outcome.frames, 2) << seed;  // make_corpus.cpp writes 2 depth frames per bag
  }
}

TEST(FuzzCorpus, SeedFolderFilesGiveValidFolders) {
  const std::vector<fs::path> seeds = files_under("fuzz/corpus/folder");
  ASSERT_EQ(seeds.size(), static_cast<size_t>(fuzz::kFolderTargets)) << "one seed per folder file";
  for (const fs::path& seed : seeds) {
    const fuzz::Outcome outcome = replay(seed, fuzz::run_folder);
    if (!jpeg_supported() && outcome.error.find("libturbojpeg") != std::string::npos) continue;
    EXPECT_EQ(outcome.error, "") << seed;
    EXPECT_EQ(outcome.frames, 2) << seed;
  }
}

// The config seeds are the example configurations: each loads, with finite parameters.
TEST(FuzzCorpus, SeedConfigsLoad) {
  const std::vector<fs::path> seeds = files_under("fuzz/corpus/config");
  ASSERT_GE(seeds.size(), 5U) << "fuzz/corpus/config is missing";
  for (const fs::path& seed : seeds) {
    const fuzz::Outcome outcome = replay(seed, fuzz::run_config);
    EXPECT_EQ(outcome.error, "") << seed;
    EXPECT_EQ(outcome.frames, 1) << seed;
  }
}

TEST(FuzzCorpus, SeedsMatchWhatTheEntryCodeStartsFrom) {
  // The folder seeds are the valid files run_folder rebuilds around an input: if the layout in
  // fuzz_entries.cpp changes, rerun hrcsense-fuzz-corpus (docs/FUZZING.md).
  for (int t = 0; t < fuzz::kFolderTargets; ++t) {
    const auto target = static_cast<fuzz::FolderTarget>(t);
    if (target == fuzz::FolderTarget::color_jpeg || target == fuzz::FolderTarget::depth_png ||
        target == fuzz::FolderTarget::color_png) {
      continue;  // encoder output may differ between library versions; the content is checked above
    }
    bool found = false;
    for (const fs::path& seed : files_under("fuzz/corpus/folder")) {
      const std::vector<char> bytes = test::read_bytes(seed.string());
      found = found || std::string(bytes.begin(), bytes.end()) == fuzz::folder_seed(target);
    }
    EXPECT_TRUE(found) << "no seed for folder target " << t;
  }
}

TEST(FuzzCorpus, RegressionsEndCleanly) {
  int replayed = 0;
  // Each target's reproducers are in the folder of its name.
  const std::pair<const char*, FuzzEntry> targets[] = {
      {"bag", fuzz::run_bag}, {"folder", fuzz::run_folder}, {"config", fuzz::run_config}};
  for (const auto& [folder, entry] : targets) {
    for (const fs::path& file : files_under(std::string("fuzz/regressions/") + folder)) {
      // The entry code aborts on a broken error contract and the sanitizers on memory errors;
      // here every reproducer (a damaged input) must end in a clean error, the same every time
      // (no state leaks from one input to the next).
      const fuzz::Outcome first = replay(file, entry);
      const fuzz::Outcome second = replay(file, entry);
      EXPECT_NE(first.error, "") << file << " plays as a valid recording";
      EXPECT_EQ(first.frames, second.frames) << file;
      EXPECT_EQ(first.error, second.error) << file;
      ++replayed;
    }
  }
  EXPECT_GE(replayed, 13) << "fuzz/regressions/ is missing";
  RecordProperty("replayed", replayed);
}

}  // namespace
}  // namespace hrcsense
