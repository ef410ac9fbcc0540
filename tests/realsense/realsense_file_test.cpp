// SPDX-License-Identifier: Apache-2.0
// A .bag played through the SDK adapter (issue 31, item 8), on the plain decisions of
// realsense/realsense_plan.hpp, without the SDK: only the streams asked for are enabled, the
// host time is left to run_pipeline as for a bag source (docs/ROBOT.md, "Clocks"), and a looped
// file's timestamps keep rising as BagSource's do, its repeated last frame skipped. The SDK run
// itself is the manual check of docs/CAMERAS.md.
#include "realsense/realsense_plan.hpp"

#include "hrcsense/recordings/bag_writer.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr auto kHw = TimestampDomain::hardware_clock;

/// A file in the temp folder, unique to this process (another build's tests may run meanwhile).
std::filesystem::path scratch_bag(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("hrcsense_rs_file_" + name + "_" + std::to_string(::getpid()) + ".bag");
}

/// What one call of FrameClock::times gives, for comparing whole sequences.
struct Seen {
  bool deliver;
  int64_t timestamp_ns;
  int64_t host_time_ns;
  bool operator==(const Seen& o) const {
    return deliver == o.deliver && timestamp_ns == o.timestamp_ns && host_time_ns == o.host_time_ns;
  }
};
std::ostream& operator<<(std::ostream& os, const Seen& s) {
  return os << "{" << s.deliver << ", " << s.timestamp_ns << ", " << s.host_time_ns << "}";
}

Seen feed(FrameClock& clock, double timestamp_ms, uint64_t number, int64_t arrival_ns) {
  const FrameTimes t = clock.times(timestamp_ms, kHw, number, arrival_ns);
  return {t.deliver, t.timestamp_ns, t.host_time_ns};
}

TEST(RealSenseFile, EnablesOnlyTheStreamsAskedFor) {
  RealSenseParams params;
  params.color = false;
  EXPECT_EQ(file_streams(params), std::vector<StreamKind>{StreamKind::depth});
  params.color = true;
  EXPECT_EQ(file_streams(params), (std::vector<StreamKind>{StreamKind::depth, StreamKind::color}));
}

TEST(RealSenseFile, TheHostTimeIsLeftToTheRunAsForABagSource) {
  // docs/ROBOT.md, "Clocks": only a live camera stamps Frame::host_time_ns; a recording leaves
  // it 0 and run_pipeline sets it (its timestamp with a sim or recorded state).
  FrameClock file;
  file.from_file = true;
  file.nominal_fps = 30.0;
  EXPECT_EQ(feed(file, 1000.0, 1, 5'000'000'000), (Seen{true, 1'000'000'000, 0}));
  EXPECT_EQ(feed(file, 1033.5, 2, 5'100'000'000), (Seen{true, 1'033'500'000, 0}));
  // A live camera's frame arriving at 5 s is on the host clock (the first frame: its arrival).
  FrameClock live;
  EXPECT_EQ(feed(live, 1000.0, 1, 5'000'000'000), (Seen{true, 1'000'000'000, 5'000'000'000}));

  // The bag source itself leaves it 0.
  const std::filesystem::path path = scratch_bag("host");
  {
    BagWriter writer(path.string());
    for (int i = 0; i < 2; ++i) {
      Frame frame;
      frame.index = i;
      frame.depth.resize(4, 3);
      frame.intrinsics = Intrinsics{4, 3, 3.0F, 3.0F, 1.5F, 1.0F};
      frame.timestamp_ns = 1'000'000'000 + i * 33'333'333;
      writer.add_depth(frame);
    }
    writer.close();
  }
  BagSource bag(RecordingParams{path.string()});
  for (int i = 0; i < 2; ++i) {
    Frame frame;
    ASSERT_EQ(bag.next(frame), Source::Status::frame) << bag.error();
    EXPECT_EQ(frame.host_time_ns, 0) << "frame " << i;
  }
  std::filesystem::remove(path);
}

TEST(RealSenseFile, ALoopedFileSkipsItsRepeatedLastFrameAndKeepsTimestampsRising) {
  // The real D435 bag (../shared/data/librealsense_d435_single_frame): 6 frames/s, depth frames
  // 169 and 170. Played looped, the SDK hands on 169, 170, then 170 again, then starts over at
  // 169 with the file's timestamps.
  FrameClock clock;
  clock.from_file = true;
  clock.nominal_fps = 6.0;
  const double t169_ms = 360700.0, t170_ms = 360866.667;
  std::vector<Seen> seen;
  for (const auto& [ms, number] : {std::pair{t169_ms, 169}, {t170_ms, 170}, {t170_ms, 170}, {t169_ms, 169},
                                   {t170_ms, 170}, {t170_ms, 170}, {t169_ms, 169}}) {
    seen.push_back(feed(clock, ms, static_cast<uint64_t>(number), 0));
  }
  // By hand: 1/6 s = 166 666 667 ns; each lap starts that long after the last frame delivered.
  const std::vector<Seen> expected = {{true, 360'700'000'000, 0},
                                      {true, 360'866'667'000, 0},
                                      {false, 0, 0},
                                      {true, 361'033'333'667, 0},  // 360.866667 s + 1/6 s
                                      {true, 361'200'000'667, 0},  // + the file's own step
                                      {false, 0, 0},
                                      {true, 361'366'667'334, 0}};
  EXPECT_EQ(seen, expected);
  EXPECT_EQ(clock.laps, 2);
}

TEST(RealSenseFile, ALapThatRestartsAtZeroStillComesOnePeriodAfterTheLastFrame) {
  FrameClock clock;
  clock.from_file = true;
  clock.nominal_fps = 30.0;
  EXPECT_EQ(feed(clock, 100.0, 3, 0).timestamp_ns, 100'000'000);
  EXPECT_EQ(feed(clock, 200.0, 6, 0).timestamp_ns, 200'000'000);
  // Timestamps start at 0 again: 200 ms + 1/30 s (33 333 333 ns), then the same steps.
  EXPECT_EQ(feed(clock, 0.0, 0, 0).timestamp_ns, 233'333'333);
  EXPECT_EQ(feed(clock, 100.0, 3, 0).timestamp_ns, 333'333'333);
}

TEST(RealSenseFile, AOneFrameFileLoopsOnePeriodApartAndUnnumberedFramesAreNeverSkipped) {
  // One frame, numbered 0 each time: numbers that never change say nothing, so nothing is a
  // repeat; the timestamps still rise by one period of 6 frames/s.
  FrameClock clock;
  clock.from_file = true;
  clock.nominal_fps = 6.0;
  EXPECT_EQ(feed(clock, 1000.0, 0, 0), (Seen{true, 1'000'000'000, 0}));
  EXPECT_EQ(feed(clock, 1000.0, 0, 0), (Seen{true, 1'166'666'667, 0}));
  EXPECT_EQ(feed(clock, 1000.0, 0, 0), (Seen{true, 1'333'333'334, 0}));
}

TEST(RealSenseFile, ALiveCameraIsNeitherSkippedNorShifted) {
  FrameClock live;
  EXPECT_TRUE(feed(live, 100.0, 5, 1'000'000'000).deliver);
  const Seen again = feed(live, 100.0, 5, 1'010'000'000);
  EXPECT_TRUE(again.deliver) << "a live camera's frames are each new";
  EXPECT_EQ(again.timestamp_ns, 100'000'000);
  EXPECT_EQ(feed(live, 50.0, 1, 1'020'000'000).timestamp_ns, 50'000'000) << "a reset camera clock is not a lap";
}

TEST(RealSenseFile, LoopedTimestampsAreTheBagSourcesOnTheSameFile) {
  // Three frames at 6 frames/s, 1/6 s apart, written as a recording and played looped by
  // BagSource; the SDK's sequence of the same file (each lap's last frame repeated) through
  // FrameClock gives the same timestamps.
  const std::vector<int64_t> stamps_ns = {1'000'000'000, 1'166'666'667, 1'333'333'333};
  const std::filesystem::path path = scratch_bag("loop");
  {
    BagWriterParams params;
    params.fps = 6;
    BagWriter writer(path.string(), params);
    for (size_t i = 0; i < stamps_ns.size(); ++i) {
      Frame frame;
      frame.index = static_cast<int64_t>(i);
      frame.depth.resize(4, 3);
      frame.intrinsics = Intrinsics{4, 3, 3.0F, 3.0F, 1.5F, 1.0F};
      frame.timestamp_ns = stamps_ns[i];
      writer.add_depth(frame);
    }
    writer.close();
  }
  RecordingParams params{path.string()};
  params.loop = true;
  BagSource bag(params);
  FrameClock clock;
  clock.from_file = true;
  clock.nominal_fps = bag.info().nominal_fps;
  Frame frame;
  for (int lap = 0; lap < 3; ++lap) {
    for (size_t i = 0; i < stamps_ns.size(); ++i) {
      ASSERT_EQ(bag.next(frame), Source::Status::frame) << bag.error();
      const Seen sdk = feed(clock, static_cast<double>(stamps_ns[i]) / 1e6, 10 + i, 0);
      EXPECT_TRUE(sdk.deliver);
      EXPECT_NEAR(static_cast<double>(sdk.timestamp_ns), static_cast<double>(frame.timestamp_ns), 1.0)
          << "lap " << lap << " frame " << i << " (the SDK's ms round to the ns)";
    }
    EXPECT_FALSE(feed(clock, static_cast<double>(stamps_ns.back()) / 1e6, 10 + stamps_ns.size() - 1, 0).deliver);
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace hrcsense
