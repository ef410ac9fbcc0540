// SPDX-License-Identifier: Apache-2.0
// A bag's stated frame rate (issue 31, item 7) on the real D435 recording in ../shared/data
// (6 frames/s): the source's nominal rate, a loop's laps, a paced replay and a re-recording.
// Expectations come from the recording's README, never from the code under test.
#include "recordings_test_util.hpp"
#include "../support/run_cli.hpp"

#include "hrcsense/recordings/recordings.hpp"
#include "src/recordings/bag_reader.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::cli;
using test::CliResult;
using test::ScratchDir;

#define REQUIRE_D435_BAG()                                       \
  const std::string bag = test::shared_d435_bag();          \
  if (bag.empty()) GTEST_SKIP() << "../shared/data/librealsense_d435_single_frame is absent"

/// The fps field (the first uint32, spec §4) of `topic`'s first StreamInfo in `bag`; -1 without one.
int64_t stated_fps(const std::string& bag, const std::string& topic) {
  BagReader reader(bag);
  BagMessage m;
  for (int guard = 0; guard < 100000 && reader.next(m); ++guard) {
    if (reader.connections().at(m.conn).topic != topic || m.size < 4) continue;
    uint32_t fps = 0;
    std::memcpy(&fps, m.data, 4);
    return fps;
  }
  return -1;
}

TEST(BagRate, TheRealBagsStatedRateIsTheSourcesNominalRate) {
  REQUIRE_D435_BAG();
  BagSource source(RecordingParams{bag});
  EXPECT_EQ(source.info().nominal_fps, 6.0) << "README: depth 640x480 Z16 at 6 fps";
  const RecordingSummary summary = summarize_recording(bag);
  ASSERT_EQ(summary.streams.size(), 2U);
  EXPECT_EQ(summary.streams[0].fps, 6U) << "depth";
  EXPECT_EQ(summary.streams[1].fps, 6U) << "color";
}

TEST(BagRate, ALoopedLapStartsOnePeriodOfTheStatedRateAfterTheLastFrame) {
  REQUIRE_D435_BAG();
  RecordingParams params{bag};
  params.loop = true;
  BagSource source(params);
  Frame frame;
  std::vector<int64_t> stamps_ns;
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(source.next(frame), Source::Status::frame) << source.error();
    stamps_ns.push_back(frame.timestamp_ns);
  }
  // Two frames a lap (README); 1/6 s = 166 666 666.7 ns, rounded.
  EXPECT_EQ(stamps_ns[2] - stamps_ns[1], 166'666'667);
  EXPECT_EQ(stamps_ns[3] - stamps_ns[2], stamps_ns[1] - stamps_ns[0]) << "the second lap repeats the first's steps";
}

TEST(BagRate, APacedReplayOfTheRealBagSkipsNoFramesAndNeverStopsForNoFrame) {
  REQUIRE_D435_BAG();
  ScratchDir out("bagrate");
  // Six frames (three laps) paced at the bag's own 6 frames/s: about one second.
  const CliResult r = cli("run --set source.type=bag --set source.path=" + bag +
                          " --set source.pace=true --set source.loop=true --set background.frames=1 --frames 6 --out " +
                          (out / "paced.jsonl"));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const std::vector<char> bytes = test::read_bytes(out / "paced.jsonl");
  const std::string jsonl(bytes.begin(), bytes.end());
  EXPECT_NE(jsonl.find("\"frames_skipped_source\":0"), std::string::npos) << jsonl.substr(jsonl.rfind('{'));
  EXPECT_EQ(jsonl.find("\"reason_code\":\"no_frame\""), std::string::npos) << "a frame every 1/6 s is on time";
}

TEST(BagRate, ARecordingOfTheRealBagStatesItsRate) {
  REQUIRE_D435_BAG();
  ScratchDir out("bagrate");
  const std::string copy = out / "again.bag";
  const CliResult r = cli("record --set source.type=bag --set source.path=" + bag + " --out " + copy);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(stated_fps(copy, "/device_0/sensor_0/Depth_0/info"), 6);
  EXPECT_EQ(stated_fps(copy, "/device_0/sensor_1/Color_0/info"), 6);
  EXPECT_EQ(BagSource(RecordingParams{copy}).info().nominal_fps, 6.0);
}

}  // namespace
}  // namespace hrcsense
