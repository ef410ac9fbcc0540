// SPDX-License-Identifier: Apache-2.0
// Pause, step and seek in a replay: which frames the capture thread gets, and that a paused
// replay gives no frame at all (the pipeline's watchdog then stops the cell).

#include "viewer/playback.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <thread>
#include <vector>

namespace hrcsense::view {
namespace {

// A recording of `count` frames whose index is their position; counts how often it was opened.
class CountingRecording final : public Source {
 public:
  explicit CountingRecording(int64_t count) : count_(count) {}
  SourceInfo info() const override {
    SourceInfo info;
    info.type = "fake";
    info.frame_count = count_;
    return info;
  }
  Status next(Frame& out) override {
    if (next_ >= count_) return Status::end;
    out.index = next_;
    out.timestamp_ns = next_ * 33'333'333;
    ++next_;
    return Status::frame;
  }

 private:
  int64_t count_;
  int64_t next_ = 0;
};

struct Replay {
  PlaybackControl control;
  int opens = 0;
  std::unique_ptr<PlaybackSource> source;
  explicit Replay(int64_t count) {
    source = std::make_unique<PlaybackSource>(
        std::make_unique<CountingRecording>(count),
        [this, count] {
          ++opens;
          return std::make_unique<CountingRecording>(count);
        },
        control);
  }
  // The index of the next frame, or -1 for idle, -2 for the end.
  int64_t next() {
    Frame frame;
    const Source::Status status = source->next(frame);
    if (status == Source::Status::idle) return -1;
    if (status == Source::Status::end) return -2;
    return frame.index;
  }
};

TEST(Playback, PlaysThroughWhenNotPaused) {
  Replay replay(3);
  EXPECT_EQ(replay.next(), 0);
  EXPECT_EQ(replay.next(), 1);
  EXPECT_EQ(replay.next(), 2);
  EXPECT_EQ(replay.next(), -2);
  EXPECT_EQ(replay.control.position(), 2);
  EXPECT_EQ(replay.source->info().frame_count, 3);
}

TEST(Playback, PausedGivesNoFrameUntilAStep) {
  Replay replay(10);
  EXPECT_EQ(replay.next(), 0);
  replay.control.set_paused(true);
  EXPECT_EQ(replay.next(), -1);
  EXPECT_EQ(replay.next(), -1);
  replay.control.step();
  EXPECT_EQ(replay.next(), 1);
  EXPECT_EQ(replay.next(), -1);  // one step, one frame
  replay.control.step();
  replay.control.step();
  EXPECT_EQ(replay.next(), 2);
  EXPECT_EQ(replay.next(), 3);
  EXPECT_EQ(replay.next(), -1);
  replay.control.set_paused(false);
  EXPECT_EQ(replay.next(), 4);
  replay.control.step();  // not paused: a step means nothing
  replay.control.set_paused(true);
  EXPECT_EQ(replay.next(), -1);
}

TEST(Playback, SeekForwardDropsTheFramesBetweenWithoutReopening) {
  Replay replay(10);
  EXPECT_EQ(replay.next(), 0);
  replay.control.seek(6);
  EXPECT_EQ(replay.next(), 6);
  EXPECT_EQ(replay.next(), 7);
  EXPECT_EQ(replay.opens, 0);
  EXPECT_EQ(replay.control.position(), 7);
  EXPECT_EQ(replay.control.skipped(), 5);  // frames 1-5: a gap the viewer does not count as dropped
}

TEST(Playback, SeekBackReopensAndPausedShowsTheFrameSought) {
  Replay replay(10);
  for (int i = 0; i < 5; ++i) replay.next();
  replay.control.set_paused(true);
  replay.control.seek(2);
  EXPECT_EQ(replay.next(), 2);  // shown once while paused
  EXPECT_EQ(replay.next(), -1);
  EXPECT_EQ(replay.opens, 1);
  replay.control.seek(0);
  EXPECT_EQ(replay.next(), 0);
  EXPECT_EQ(replay.opens, 2);
  EXPECT_EQ(replay.control.skipped(), 0);  // back: the frames read up to the position leave no gap
  replay.control.set_paused(false);
  EXPECT_EQ(replay.next(), 1);
}

TEST(Playback, SeekPastTheEndEndsTheReplay) {
  Replay replay(4);
  replay.control.seek(99);
  EXPECT_EQ(replay.next(), -2);
}

TEST(Playback, APausedWaitIsShortAndAStepFromAnotherThreadEndsIt) {
  Replay replay(3);
  replay.control.set_paused(true);
  std::thread viewer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    replay.control.step();
  });
  // The capture thread asks until the step comes; each paused call returns within its wait.
  int64_t index = -1;
  for (int tries = 0; tries < 200 && index == -1; ++tries) index = replay.next();
  viewer.join();
  EXPECT_EQ(index, 0);
}

}  // namespace
}  // namespace hrcsense::view
