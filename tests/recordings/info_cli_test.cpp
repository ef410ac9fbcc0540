// SPDX-License-Identifier: Apache-2.0
// `hrcsense info <recording>` and `hrcsense run` on recorded sources, through the real CLI.
#include "recordings_test_util.hpp"
#include "../support/run_cli.hpp"

#include "hrcsense/io/io.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace hrcsense {
namespace {

using test::cli;
using test::CliResult;

void expect_line(const std::string& out, const std::string& line) {
  EXPECT_NE(out.find(line + "\n"), std::string::npos) << "missing line: " << line << "\n" << out;
}

TEST(InfoCli, DescribesTheRealBag) {
  const std::string dir = test::shared_data("librealsense_d435_single_frame");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/librealsense_d435_single_frame is absent";
  const CliResult r = cli("info " + dir + "/single_depth_color_640x480.bag");
  EXPECT_EQ(r.exit_code, 0) << r.out;
  expect_line(r.out, "format: bag (indexed, file version 3)");
  expect_line(r.out, "compression: lz4");
  // README: "Depth 640x480 Z16 (`mono16`) at 6 fps".
  EXPECT_NE(r.out.find("stream depth: 640x480 mono16, 2 frame(s), 0.167 s, stated 6 frames/s, fx=390.4315 "
                       "fy=390.4315 ppx=331.3879 ppy=242.1873 model=Brown Conrady"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("stream color: 640x480 rgb8, 1 frame(s)"), std::string::npos) << r.out;
  expect_line(r.out, "depth units: 0.001 m");
}

TEST(InfoCli, DescribesAFolderAndReportsDamageWithExitCode1) {
  test::ScratchDir dir("info");
  std::filesystem::create_directories(dir.path / "depth");
  DepthImage depth;
  depth.resize(4, 3);
  write_depth_png(dir / "depth/000000.png", depth);
  write_depth_png(dir / "depth/000001.png", depth);
  test::write_text(dir / "intrinsics.json",
                   R"({"width": 4, "height": 3, "depth_K": [[500, 0, 2], [0, 500, 1.5], [0, 0, 1]]})");
  CliResult r = cli("info " + dir.path.string());
  EXPECT_EQ(r.exit_code, 0) << r.out;
  expect_line(r.out, "format: folder (ist layout)");
  EXPECT_NE(r.out.find("stream depth: 4x3 png (16-bit), 2 frame(s), duration unknown, fx=500.0000 fy=500.0000 "
                       "ppx=2.0000 ppy=1.5000"),
            std::string::npos)
      << r.out;
  test::write_text(dir / "depth/000001.png", "not a png");
  r = cli("info " + dir.path.string());
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.out.find("1 frame(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("damaged recording: frame 1: " + (dir / "depth/000001.png")), std::string::npos) << r.out;
}

TEST(InfoCli, MissingRecordingIsAnError) {
  const CliResult r = cli("info /nonexistent/recording.bag");
  EXPECT_EQ(r.exit_code, 2) << r.out;  // a usage error: the path is not there
  EXPECT_NE(r.out.find("/nonexistent/recording.bag"), std::string::npos) << r.out;
}

TEST(RunCli, RunsTheRealBagThroughThePipeline) {
  const std::string dir = test::shared_data("librealsense_d435_single_frame");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/librealsense_d435_single_frame is absent";
  test::ScratchDir out("run");
  const CliResult r = cli("run --set source.type=bag --set source.path=" + dir +
                          "/single_depth_color_640x480.bag --set background.frames=1 --out " + (out / "bag.jsonl"));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const std::vector<char> bytes = test::read_bytes(out / "bag.jsonl");
  const std::string jsonl(bytes.begin(), bytes.end());
  EXPECT_NE(jsonl.find("\"fx\":390.431"), std::string::npos) << jsonl.substr(0, 600);
  EXPECT_NE(jsonl.find("\"frame\":1,"), std::string::npos);
  EXPECT_EQ(jsonl.find("\"frame\":2,"), std::string::npos);  // two depth frames only
}

}  // namespace
}  // namespace hrcsense
