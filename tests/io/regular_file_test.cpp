// SPDX-License-Identifier: Apache-2.0
// Tests of the "must be a regular file" check that every reader asks before open(): a FIFO
// with no writer would block open() forever, so each check that could hang runs in a child
// process with a deadline (a missing check fails the test instead of hanging it).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "../support/no_block.hpp"
#include "hrcsense/io/io.hpp"

namespace hrcsense {
namespace {

using test::ChildOutcome;
using test::mentions;
using test::run_with_deadline;

/// A fresh folder in the test temp dir, removed at the end.
struct Folder {
  std::filesystem::path path;
  Folder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = std::filesystem::path(::testing::TempDir()) /
           ("hrcsense_regular_" + std::to_string(::getpid()) + "_" + info->name());
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~Folder() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

TEST(RegularFile, SaysWhatAPathIsInstead) {
  Folder dir;
  std::ofstream(dir / "plain.txt") << "x";
  test::make_fifo(dir / "pipe");
  std::filesystem::create_symlink(dir / "plain.txt", dir.path / "link");
  EXPECT_EQ(not_regular_file(dir / "plain.txt"), "");
  EXPECT_EQ(not_regular_file(dir / "link"), "");  // a link to a file is that file
  EXPECT_EQ(not_regular_file(dir / "missing"), "does not exist");
  EXPECT_EQ(not_regular_file(dir.path.string()), "is a directory, not a file");
  EXPECT_EQ(not_regular_file(dir / "pipe"), "is a FIFO (named pipe), not a regular file");
  EXPECT_EQ(not_regular_file("/dev/null"), "is a character device, not a regular file");
  try {
    require_regular_file(dir / "pipe", "background file");
    FAIL() << "no IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "pipe") + ": background file is a FIFO (named pipe), not a regular file");
  }
}

TEST(RegularFile, BackgroundFileThatIsAFifoOrAFolderIsRefusedWithoutBlocking) {
  Folder dir;
  const std::string pipe = dir / "background.bin";
  test::make_fifo(pipe);
  const auto refused = [](const std::string& path, const std::string& why) {
    return [path, why] {
      try {
        (void)load_background(path);
      } catch (const IoError& e) {
        return mentions(e.what(), {path, why});
      }
      return false;
    };
  };
  EXPECT_EQ(run_with_deadline(refused(pipe, "FIFO")), ChildOutcome::passed);
  EXPECT_EQ(run_with_deadline(refused(dir.path.string(), "directory")), ChildOutcome::passed);
  EXPECT_EQ(run_with_deadline(refused("/dev/zero", "character device")), ChildOutcome::passed);
}

}  // namespace
}  // namespace hrcsense
