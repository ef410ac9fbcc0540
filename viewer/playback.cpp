// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — pause, step and seek in a recording (playback.hpp).
#include "viewer/playback.hpp"

#include <chrono>
#include <utility>

namespace hrcsense::view {
namespace {

// How long next() waits while paused before it says `idle`: short, so that a stop request
// ends the run promptly (Source::next's contract).
constexpr double kPausedWaitS = 0.05;

}  // namespace

void PlaybackControl::set_paused(bool paused) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    paused_ = paused;
    steps_ = 0;
  }
  changed_.notify_all();
}

bool PlaybackControl::paused() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return paused_;
}

void PlaybackControl::step() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (paused_) ++steps_;
  }
  changed_.notify_all();
}

void PlaybackControl::seek(int64_t position) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    seek_to_ = position < 0 ? 0 : position;
    if (paused_) steps_ = 1;  // show the frame sought
  }
  changed_.notify_all();
}

int64_t PlaybackControl::position() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return position_;
}

int64_t PlaybackControl::skipped() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return skipped_;
}

void PlaybackControl::add_skipped(int64_t frames) {
  const std::lock_guard<std::mutex> lock(mutex_);
  skipped_ += frames;
}

int64_t PlaybackControl::frame_count() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return frame_count_;
}

void PlaybackControl::set_frame_count(int64_t count) {
  const std::lock_guard<std::mutex> lock(mutex_);
  frame_count_ = count;
}

bool PlaybackControl::wait_until_go(double wait_s, int64_t& seek_to) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto may_go = [&] { return !paused_ || steps_ > 0; };
  if (!changed_.wait_for(lock, std::chrono::duration<double>(wait_s), may_go)) return false;
  if (paused_) --steps_;
  seek_to = seek_to_;
  seek_to_ = -1;
  return true;
}

void PlaybackControl::delivered(int64_t position) {
  const std::lock_guard<std::mutex> lock(mutex_);
  position_ = position;
}

void PlaybackControl::wake() { changed_.notify_all(); }

PlaybackSource::PlaybackSource(std::unique_ptr<Source> first, std::function<std::unique_ptr<Source>()> open,
                               PlaybackControl& control)
    : first_(std::move(first)), current_(first_.get()), open_(std::move(open)), control_(control),
      info_(first_->info()) {
  control_.set_frame_count(info_.frame_count);
}

Source::Status PlaybackSource::next(Frame& out) {
  int64_t seek_to = -1;
  if (!control_.wait_until_go(kPausedWaitS, seek_to)) return Status::idle;
  if (seek_to >= 0) {
    const Status status = reposition(seek_to, out);
    if (status != Status::frame) return status;
  }
  const Status status = current_->next(out);
  if (status == Status::frame) control_.delivered(next_position_++);
  return status;
}

Source::Status PlaybackSource::reposition(int64_t position, Frame& scratch) {
  const bool back = position < next_position_;
  if (back) {
    reopened_ = open_();
    current_ = reopened_.get();
    next_position_ = 0;
  }
  while (next_position_ < position) {
    const Status status = current_->next(scratch);
    if (status != Status::frame) return status;  // past the end: the recording ends there
    ++next_position_;
    if (!back) control_.add_skipped(1);  // a gap in the processed frames' indices (ViewTap::index_gaps)
  }
  return Status::frame;
}

}  // namespace hrcsense::view
