// SPDX-License-Identifier: Apache-2.0
// hrcsense — the single-slot, latest-value-wins mailbox that joins the pipeline's threads.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <utility>

namespace hrcsense {

/// Single-slot, latest-value-wins mailbox between two threads. put() never blocks: a value
/// not yet taken is replaced and counted as dropped. take() waits for a value or close().
template <typename T>
class Mailbox {
 public:
  /// Stores `value` (swapped in, so buffers circulate without allocation). Never blocks.
  /// False (value kept) once closed: the consumer is gone and the producer should end.
  bool put(T& value) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return false;
    if (full_) ++dropped_;
    std::swap(slot_, value);
    full_ = true;
    ready_.notify_one();
    return true;
  }
  /// Like put(), but a value about to be replaced is first handed to `merge(replaced, value)`
  /// under the lock, so that what it said is carried into the value that replaces it (the
  /// safety monitor's stops are never dropped unseen).
  template <typename Merge>
  bool put(T& value, Merge&& merge) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return false;
    if (full_) {
      ++dropped_;
      merge(static_cast<const T&>(slot_), value);
    }
    std::swap(slot_, value);
    full_ = true;
    ready_.notify_one();
    return true;
  }
  /// Like put(), but first waits until the slot is empty, so nothing is dropped: for unpaced
  /// runs, where the producer must wait for the consumer. False (value kept) once closed.
  bool put_wait(T& value) {
    std::unique_lock<std::mutex> lock(mutex_);
    space_.wait(lock, [&] { return !full_ || closed_; });
    if (closed_) return false;
    std::swap(slot_, value);
    full_ = true;
    ready_.notify_one();
    return true;
  }
  /// Waits for a value and swaps it into `out`; false once closed and empty.
  bool take(T& out) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [&] { return full_ || closed_; });
    if (!full_) return false;
    std::swap(slot_, out);
    full_ = false;
    space_.notify_one();
    return true;
  }
  /// Like take(), but gives up after `timeout_s`; false on timeout or when closed and empty.
  bool take_for(T& out, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return full_ || closed_; });
    if (!full_) return false;
    std::swap(slot_, out);
    full_ = false;
    space_.notify_one();
    return true;
  }
  bool closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_ && !full_;
  }
  void close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    ready_.notify_all();
    space_.notify_all();
  }
  int64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::condition_variable space_;  ///< signalled when the slot empties (put_wait)
  T slot_{};
  bool full_ = false;
  bool closed_ = false;
  int64_t dropped_ = 0;
};

}  // namespace hrcsense
