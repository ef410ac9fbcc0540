// SPDX-License-Identifier: Apache-2.0
// FolderSource's list files (frames.txt, depth.txt): a malformed line lets the frames listed
// before it play, then ends the recording with an error naming the file, the line and what the
// line holds; timestamps that are not plain seconds are malformed lines too.
#include "recordings_test_util.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::ScratchDir;
using test::write_text;

/// Four 4x3 depth PNGs (pixel (0, 0) = 100, 200, 300, 400) and the datasets' intrinsics.
void make_frames(const ScratchDir& dir) {
  std::filesystem::create_directories(dir.path / "depth");
  for (int i = 0; i < 4; ++i) {
    DepthImage depth;
    depth.resize(4, 3);
    depth.pixels[0] = static_cast<uint16_t>(100 * (i + 1));
    char name[32];
    std::snprintf(name, sizeof(name), "depth/%06d.png", i);
    write_depth_png(dir / name, depth);
  }
  write_text(dir / "intrinsics.json", R"({"width": 4, "height": 3, "depth_K": [[500, 0, 2], [0, 500, 1.5], [0, 0, 1]]})");
}

/// Plays the folder: the pixel (0, 0) of every frame, and the error it ended with ("" at a clean end).
std::vector<int> play(const std::string& folder, std::string& error, bool loop = false) {
  FolderSource source(RecordingParams{folder, loop});
  std::vector<int> firsts;
  Frame frame;
  Source::Status status = Source::Status::frame;
  while (firsts.size() < 20 && (status = source.next(frame)) == Source::Status::frame) firsts.push_back(frame.depth.pixels[0]);
  error = status == Source::Status::error ? source.error() : std::string();
  if (status == Source::Status::error) {
    EXPECT_EQ(source.next(frame), Source::Status::error);  // it stays failed
  }
  return firsts;
}

TEST(FolderLists, AMalformedFramesTxtLinePlaysTheFramesBeforeItThenNamesFileAndLine) {
  ScratchDir dir("lists");
  make_frames(dir);
  // Line 4 lost its path column (a bad merge); before the fix this played no frame at all.
  write_text(dir / "frames.txt", "# index depth_png\n0 depth/000000.png\n1 depth/000001.png\n2\n3 depth/000003.png\n");
  std::string error;
  EXPECT_EQ(play(dir.path.string(), error), (std::vector<int>{100, 200}));
  EXPECT_EQ(error, "frame 2: " + (dir / "frames.txt") + ":4: expected at least 2 columns, got '2'");
  // Looping does not start a second lap over the damage.
  EXPECT_EQ(play(dir.path.string(), error, true), (std::vector<int>{100, 200}));
  EXPECT_NE(error.find("frames.txt:4"), std::string::npos) << error;
  // `info` counts the good frames and reports the line as the damage.
  const RecordingSummary summary = summarize_recording(dir.path.string());
  ASSERT_FALSE(summary.streams.empty());
  EXPECT_EQ(summary.streams[0].frames, 2);
  EXPECT_NE(summary.damage.find("frames.txt:4"), std::string::npos) << summary.damage;
}

TEST(FolderLists, AFrameNumberThatIsNotANumberIsMalformed) {
  ScratchDir dir("lists");
  make_frames(dir);
  // The index column went missing, so the colour image would have been read as the depth.
  write_text(dir / "frames.txt", "0 depth/000000.png\ndepth/000001.png rgb/000001.jpg\n");
  std::string error;
  EXPECT_EQ(play(dir.path.string(), error), (std::vector<int>{100}));
  EXPECT_EQ(error, "frame 1: " + (dir / "frames.txt") +
                       ":2: expected a frame number in column 1, got 'depth/000001.png rgb/000001.jpg'");
}

TEST(FolderLists, AMalformedFirstLineIsAnErrorAtOnceAndLongLinesAreCut) {
  ScratchDir dir("lists");
  make_frames(dir);
  const std::string garbage(100, 'x');
  write_text(dir / "frames.txt", "# header\n" + garbage + "\x01\n0 depth/000000.png\n");
  try {
    FolderSource source(RecordingParams{dir.path.string()});
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    // 60 characters of the line, then "...".
    EXPECT_EQ(std::string(e.what()),
              (dir / "frames.txt") + ":2: expected at least 2 columns, got '" + garbage.substr(0, 60) + "...'");
  }
}

TEST(FolderLists, TimestampsThatAreNotPlainSecondsAreMalformedLines) {
  ScratchDir dir("lists");
  make_frames(dir);
  Intrinsics in;
  in.width = 4;
  in.height = 3;
  in.fx = in.fy = 500.0F;
  in.ppx = 2.0F;
  in.ppy = 1.5F;
  write_text(dir / "intrinsics.json", intrinsics_to_json(in));
  // NaN, infinities, signs, exponents, and seconds past int64 nanoseconds (year 2262).
  for (const std::string bad : {"nan", "inf", "-inf", "-1.0", "+5", "1e9", "9223372037.0", "99999999999", "1.5.5", "0x10"}) {
    write_text(dir / "depth.txt", "# timestamp filename\n1.0 depth/000000.png\n" + bad + " depth/000001.png\n");
    std::string error;
    EXPECT_EQ(play(dir.path.string(), error), (std::vector<int>{100})) << bad;
    EXPECT_EQ(error, "frame 1: " + (dir / "depth.txt") + ":3: bad timestamp '" + bad +
                         "' (expected seconds like 1305031102.175304, before the year 2262), got '" + bad +
                         " depth/000001.png'")
        << bad;
  }
  write_text(dir / "depth.txt", "9223372035.999999999 depth/000000.png\n");  // the last second that fits
  std::string error;
  EXPECT_EQ(play(dir.path.string(), error), (std::vector<int>{100}));
  EXPECT_EQ(error, "");
}

}  // namespace
}  // namespace hrcsense
