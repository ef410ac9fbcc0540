// SPDX-License-Identifier: Apache-2.0
// hrcsense — the recorder's writer thread and bounded queue.
#include "hrcsense/recordings/recorder.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace hrcsense {

std::string split_file_name(const std::string& path, int part) {
  const bool has_ext = path.size() > 4 && path.compare(path.size() - 4, 4, ".bag") == 0;
  const std::string stem = has_ext ? path.substr(0, path.size() - 4) : path;
  char number[16];
  std::snprintf(number, sizeof number, "-%03d", part);
  return stem + number + ".bag";
}

Recorder::Recorder(RecorderParams params) : params_(std::move(params)) {
  if (params_.queue_frames < 1) params_.queue_frames = 1;
  thread_ = std::thread([this] { writer_loop(); });
}

Recorder::~Recorder() { close(); }

bool Recorder::push(const Frame& frame, const std::optional<RobotState>& robot_state) {
  return enqueue(frame, robot_state, 0, false);
}

bool Recorder::push_wait(const Frame& frame, int timeout_ms, const std::optional<RobotState>& robot_state) {
  return enqueue(frame, robot_state, timeout_ms, false);
}

bool Recorder::push_awaiting_state(const Frame& frame, const std::optional<RobotState>& fallback) {
  return enqueue(frame, fallback, 0, true);
}

void Recorder::state_used(int64_t frame_index, const RobotState& state) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    processed_index_ = std::max(processed_index_, frame_index);
    for (Item& item : queue_) {
      if (!item.awaiting_state || item.frame.index != frame_index) continue;
      // A state processing could not use (none, non-finite) is recorded as none: a replay then
      // stops on that frame as the run did.
      const bool usable = state.valid && all_finite(state.q_rad) && all_finite(state.qd_rad_s);
      item.robot_state = usable ? std::optional<RobotState>(state) : std::nullopt;
      item.awaiting_state = false;
      break;
    }
  }
  wake_writer_.notify_one();
}

bool Recorder::front_ready() const {
  const Item& front = queue_.front();
  return !front.awaiting_state || closing_ || processed_index_ >= front.frame.index;
}

bool Recorder::enqueue(const Frame& frame, const std::optional<RobotState>& robot_state, int timeout_ms,
                       bool awaiting_state) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto has_room = [this] {
    return closing_ || !stats_.error.empty() || queue_.size() < static_cast<size_t>(params_.queue_frames);
  };
  if (timeout_ms > 0) room_.wait_for(lock, std::chrono::milliseconds(timeout_ms), has_room);
  if (closing_ || !stats_.error.empty() || queue_.size() >= static_cast<size_t>(params_.queue_frames)) {
    ++stats_.frames_dropped;
    return false;
  }
  Item item;
  if (!spare_.empty()) {
    item = std::move(spare_.back());
    spare_.pop_back();
  }
  lock.unlock();
  // The copy outside the lock: the writer thread keeps going meanwhile. Assigning into a
  // spare item reuses its buffers' capacity.
  item.frame = frame;
  item.frame.truth.reset();  // ground truth is not recorded
  item.robot_state = robot_state;
  item.awaiting_state = awaiting_state;
  lock.lock();
  if (writer_exited_) {  // close() finished meanwhile: nobody would write it
    ++stats_.frames_dropped;
    return false;
  }
  queue_.push_back(std::move(item));
  wake_writer_.notify_one();
  return true;
}

bool Recorder::failed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !stats_.error.empty();
}

RecorderStats Recorder::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

RecorderStats Recorder::close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  wake_writer_.notify_all();
  room_.notify_all();
  if (thread_.joinable()) thread_.join();
  return stats();
}

void Recorder::open_next_file(const Frame& first) {
  const std::string path = params_.split_mb > 0 ? split_file_name(params_.path, part_) : params_.path;
  ++part_;
  BagWriterParams bag = params_.bag;
  bag.depth_units_option_m = first.depth.depth_scale_m;
  if (first.stereo_baseline_mm > 0.0F) bag.stereo_baseline_mm = first.stereo_baseline_mm;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.files.push_back(path);
  }
  writer_ = std::make_unique<BagWriter>(path, bag);
}

void Recorder::write_item(const Item& item) {
  // The open chunk counts uncompressed: a file may end up smaller than split_mb, never larger
  // than split_mb plus one frame.
  if (writer_ && params_.split_mb > 0 &&
      writer_->bytes_written() + writer_->pending_bytes() >= static_cast<uint64_t>(params_.split_mb) * 1024ULL * 1024ULL) {
    writer_->close();  // complete and indexed before the next one starts
    writer_.reset();
  }
  if (!writer_) open_next_file(item.frame);
  writer_->add_frame(item.frame, item.robot_state ? &*item.robot_state : nullptr);
}

void Recorder::writer_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_writer_.wait(lock, [this] { return closing_ || !queue_.empty(); });
    if (queue_.empty() && closing_) {
      writer_exited_ = true;
      break;
    }
    // A frame whose state processing reports waits for it; the items behind it keep their
    // order (the recording's joint state precedes its frame, file order is time order).
    if (!front_ready()) {
      wake_writer_.wait_for(lock, std::chrono::milliseconds(kStateWaitMs), [this] { return front_ready(); });
    }
    Item item = std::move(queue_.front());
    queue_.pop_front();
    room_.notify_one();
    const bool write = stats_.error.empty();
    lock.unlock();
    std::string error;
    if (write) {
      try {
        write_item(item);
      } catch (const BagWriteError& e) {
        error = e.what();
      }
    }
    lock.lock();
    if (!write || !error.empty()) {
      ++stats_.frames_dropped;
    } else {
      ++stats_.frames_recorded;
    }
    if (!error.empty() && stats_.error.empty()) stats_.error = error;
    spare_.push_back(std::move(item));
  }
  lock.unlock();
  if (writer_) {
    try {
      writer_->close();
    } catch (const BagWriteError& e) {
      lock.lock();
      if (stats_.error.empty()) stats_.error = e.what();
      lock.unlock();
    }
    writer_.reset();
  }
}

std::optional<RobotState> robot_state_for_recording(const Frame& frame, const RecordStateLookup& lookup) {
  if (lookup.states == nullptr) return std::nullopt;
  // As run_pipeline: a live camera's own host time; else the timestamp or the delivery time.
  // The delivery time is read here, just before the run reads it (a paced run's wait between
  // the two makes the recorded state of a live robot earlier by that wait).
  int64_t host_time_ns = frame.host_time_ns;
  if (host_time_ns == 0) {
    static const SteadyClock steady;
    const RunClock& clock = lookup.clock != nullptr ? *lookup.clock : steady;
    host_time_ns = lookup.host_time_is_source_time ? frame.timestamp_ns : clock.now_ns();
  }
  RobotState state;
  if (!lookup.states->state_at(host_time_ns - lookup.lookup_offset_ns, state) || !state.valid) return std::nullopt;
  return state;
}

Source::Status RecordingSource::next(Frame& out) {
  if (!error_.empty()) return Status::error;
  const Status status = inner_.next(out);
  if (status != Status::frame) return status;
  if (on_error_ == RecordOnError::stop_run && recorder_.failed()) {
    error_ = "recording: " + recorder_.stats().error;
    return Status::error;
  }
  if (lookup_.from_processing) {
    recorder_.push_awaiting_state(out, robot_state_for_recording(out, lookup_));
  } else {
    recorder_.push(out, robot_state_for_recording(out, lookup_));
  }
  return status;
}

}  // namespace hrcsense
