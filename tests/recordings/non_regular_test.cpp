// SPDX-License-Identifier: Apache-2.0
// Recordings and their files given as a FIFO, a device or a folder: refused with an error
// naming the path instead of blocking forever in open(). Anything that could block runs in a
// child process with a deadline (library calls) or under `timeout 10` (the CLI).
#include "recordings_test_util.hpp"
#include "../support/no_block.hpp"
#include "../support/run_cli.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

using test::ChildOutcome;
using test::mentions;
using test::run_with_deadline;
using test::ScratchDir;
using test::write_text;

/// Expects `make` (which builds a source) to throw an IoError mentioning every needle, in time.
template <typename Make>
void expect_refused(Make make, std::initializer_list<std::string> needles) {
  const std::vector<std::string> wanted(needles);
  const ChildOutcome outcome = run_with_deadline([&] {
    try {
      make();
    } catch (const IoError& e) {
      for (const std::string& needle : wanted) {
        if (!mentions(e.what(), {needle})) return false;
      }
      return true;
    }
    std::fprintf(stderr, "no IoError\n");
    return false;
  });
  EXPECT_EQ(outcome, ChildOutcome::passed) << (outcome == ChildOutcome::timed_out ? "blocked" : "wrong error");
}

void make_one_frame_folder(const ScratchDir& dir) {
  std::filesystem::create_directories(dir.path / "depth");
  DepthImage depth;
  depth.resize(4, 3);
  write_depth_png(dir / "depth/000000.png", depth);
  write_text(dir / "intrinsics.json", R"({"width": 4, "height": 3, "depth_K": [[500, 0, 2], [0, 500, 1.5], [0, 0, 1]]})");
  write_text(dir / "frames.txt", "0 depth/000000.png\n");
}

TEST(NonRegularFiles, ABagThatIsAFifoOrADeviceIsRefused) {
  ScratchDir dir("nonregular");
  test::make_fifo(dir / "live.bag");
  expect_refused([&] { BagSource source(RecordingParams{dir / "live.bag"}); }, {dir / "live.bag", "FIFO"});
  expect_refused([&] { (void)summarize_recording(dir / "live.bag"); }, {dir / "live.bag", "FIFO"});
  expect_refused([&] { BagSource source(RecordingParams{"/dev/zero"}); }, {"/dev/zero", "character device"});
}

TEST(NonRegularFiles, AFolderWhoseListOrIntrinsicsIsAFifoIsRefused) {
  ScratchDir dir("nonregular");
  make_one_frame_folder(dir);
  std::filesystem::remove(dir.path / "frames.txt");
  test::make_fifo(dir / "frames.txt");
  // Before, a FIFO frames.txt was passed over for depth/ (it is no regular file); now it is named.
  expect_refused([&] { FolderSource source(RecordingParams{dir.path.string()}); }, {dir / "frames.txt", "FIFO"});
  std::filesystem::remove(dir.path / "frames.txt");
  write_text(dir / "frames.txt", "0 depth/000000.png\n");
  std::filesystem::remove(dir.path / "intrinsics.json");
  test::make_fifo(dir / "intrinsics.json");
  expect_refused([&] { FolderSource source(RecordingParams{dir.path.string()}); }, {dir / "intrinsics.json", "FIFO"});
}

TEST(NonRegularFiles, AListedDepthImageThatIsAFifoEndsThePlayWithAnError) {
  ScratchDir dir("nonregular");
  make_one_frame_folder(dir);
  test::make_fifo(dir / "depth/000001.png");
  write_text(dir / "frames.txt", "0 depth/000000.png\n1 depth/000001.png\n");
  const ChildOutcome outcome = run_with_deadline([&] {
    FolderSource source(RecordingParams{dir.path.string()});
    Frame frame;
    if (source.next(frame) != Source::Status::frame) return false;
    if (source.next(frame) != Source::Status::error) return false;
    return mentions(source.error(), {"frame 1", dir / "depth/000001.png", "FIFO"});
  });
  EXPECT_EQ(outcome, ChildOutcome::passed);
}

TEST(NonRegularFiles, InfoAndRunRefuseAFifoWithAMessageNamingIt) {
  ScratchDir dir("nonregular");
  test::make_fifo(dir / "pipe.bag");
  // `timeout 10`: without the check the CLI would block in open() for ever.
  const std::string cli = std::string("timeout 10 ") + HRCSENSE_CLI;
  const auto run = [&](const std::string& arguments) {
    test::CliResult result;
    std::FILE* pipe = popen((cli + " " + arguments + " 2>&1").c_str(), "r");
    char buffer[4096];
    for (size_t n = 0; pipe != nullptr && (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) result.out.append(buffer, n);
    const int status = pipe != nullptr ? pclose(pipe) : -1;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
  };
  test::CliResult r = run("info " + (dir / "pipe.bag"));
  EXPECT_EQ(r.exit_code, 2) << r.out;  // like a missing path: a mistake on the command line
  EXPECT_NE(r.out.find(dir / "pipe.bag" + ": is a FIFO (named pipe), not a regular file"), std::string::npos) << r.out;
  r = run("run --set source.type=bag --set source.path=" + (dir / "pipe.bag") + " --out " + (dir / "out.jsonl"));
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find(dir / "pipe.bag" + ": recording is a FIFO"), std::string::npos) << r.out;
  // A background file that is a FIFO exists, so it is loaded, and refused.
  test::make_fifo(dir / "background.bin");
  r = run("run --set sim.frames=2 --set background.frames=1 --set background.path=" + (dir / "background.bin") +
          " --out " + (dir / "out.jsonl"));
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_NE(r.exit_code, 124) << "blocked: " << r.out;
  EXPECT_NE(r.out.find(dir / "background.bin" + ": background file is a FIFO"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace hrcsense
