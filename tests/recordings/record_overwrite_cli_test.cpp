// SPDX-License-Identifier: Apache-2.0
// A recording never destroys a file unasked (issue R2, defect 2): `hrcsense record --out` and
// `hrcsense run --record` refuse an existing output (with record.split_mb, any existing part
// of the set) with exit code 2 before anything is opened, unless --overwrite; an output that is
// the source being played is refused even then.
#include "recordings_test_util.hpp"

#include "../support/run_cli.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace hrcsense {
namespace {

namespace fs = std::filesystem;

std::string small_cell() {
  return "--config " + std::string(HRCSENSE_SOURCE_DIR) +
         "/config/cell-ur5.yaml --set sim.width=424 --set sim.height=240 --set sim.frames=3";
}

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(RecordOverwrite, AnExistingFileIsRefusedUnlessOverwriteIsGiven) {
  test::ScratchDir dir("record_overwrite");
  const std::string bag = dir / "take.bag";
  std::ofstream(bag) << "precious";
  const test::CliResult refused = test::cli("record " + small_cell() + " --out " + bag);
  EXPECT_EQ(refused.exit_code, 2) << refused.out;
  EXPECT_NE(refused.out.find(bag + " exists"), std::string::npos) << refused.out;
  EXPECT_NE(refused.out.find("--overwrite"), std::string::npos) << refused.out;
  EXPECT_EQ(contents(bag), "precious");

  const test::CliResult run = test::cli("run " + small_cell() + " --record " + bag + " --out " + (dir / "out.jsonl"));
  EXPECT_EQ(run.exit_code, 2) << run.out;
  EXPECT_EQ(contents(bag), "precious");
  EXPECT_FALSE(fs::exists(dir / "out.jsonl")) << "refused before anything was opened";

  const test::CliResult replaced = test::cli("record " + small_cell() + " --out " + bag + " --overwrite");
  EXPECT_EQ(replaced.exit_code, 0) << replaced.out;
  EXPECT_EQ(summarize_recording(bag).streams.at(0).frames, 3);
}

// With record.split_mb the set is FILE-000.bag, FILE-001.bag, ...: any existing part counts.
TEST(RecordOverwrite, AnyExistingPartOfASplitSetIsRefused) {
  test::ScratchDir dir("record_overwrite_split");
  std::ofstream(dir / "take-001.bag") << "part";
  const test::CliResult refused =
      test::cli("record " + small_cell() + " --set record.split_mb=1 --out " + (dir / "take.bag"));
  EXPECT_EQ(refused.exit_code, 2) << refused.out;
  EXPECT_NE(refused.out.find("take-001.bag exists"), std::string::npos) << refused.out;
  EXPECT_FALSE(fs::exists(dir / "take-000.bag"));
  // Another name's parts do not count.
  const test::CliResult other =
      test::cli("record " + small_cell() + " --set record.split_mb=1 --out " + (dir / "other.bag"));
  EXPECT_EQ(other.exit_code, 0) << other.out;
}

// An output under a file (not a folder): a usage error naming both (issue R2, defect 6).
TEST(RecordOverwrite, AnOutputUnderAFileNamesIt) {
  test::ScratchDir dir("record_overwrite_under_file");
  std::ofstream(dir / "notes.txt") << "a file";
  const test::CliResult refused = test::cli("record " + small_cell() + " --out " + (dir / "notes.txt") + "/take.bag");
  EXPECT_EQ(refused.exit_code, 2) << refused.out;
  EXPECT_NE(refused.out.find((dir / "notes.txt") + " is a file, not a folder"), std::string::npos) << refused.out;
}

// Recording onto the bag being played would destroy the source: refused, --overwrite or not.
TEST(RecordOverwrite, TheSourceItselfIsRefusedEvenWithOverwrite) {
  test::ScratchDir dir("record_overwrite_source");
  const std::string source = dir / "source.bag";
  ASSERT_EQ(test::cli("record " + small_cell() + " --out " + source).exit_code, 0);
  const std::string before = contents(source);
  const std::string replay = small_cell() + " --set source.type=bag --set source.path=" + source;
  for (const std::string& command : {"record " + replay + " --out " + source + " --overwrite",
                                     "run " + replay + " --record " + source + " --overwrite --out " + (dir / "o.jsonl")}) {
    const test::CliResult refused = test::cli(command);
    EXPECT_EQ(refused.exit_code, 2) << command << "\n" << refused.out;
    EXPECT_NE(refused.out.find("is the source being played"), std::string::npos) << refused.out;
  }
  EXPECT_EQ(contents(source), before);
}

}  // namespace
}  // namespace hrcsense
