// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the tap between the run's processing and output threads and the renderer's
// mailbox (view_tap.hpp).
#include "viewer/view_tap.hpp"

#include <chrono>
#include <cmath>
#include <utility>

namespace hrcsense::view {
namespace {

int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

void fill_view_frame(const Frame& frame, const Pipeline& pipeline, const FrameResult& result, int64_t made_ns,
                     ViewFrame& out) {
  out.frame = result.frame;
  out.timestamp_ns = result.timestamp_ns;
  out.made_ns = made_ns;
  out.depth.width = frame.depth.width;
  out.depth.height = frame.depth.height;
  out.depth.depth_scale_m = frame.depth.depth_scale_m;
  out.depth.pixels.assign(frame.depth.pixels.begin(), frame.depth.pixels.end());
  out.depth_intrinsics = frame.intrinsics;
  if (frame.color) {
    if (!out.color) out.color.emplace();
    out.color->width = frame.color->width;
    out.color->height = frame.color->height;
    out.color->rgb.assign(frame.color->rgb.begin(), frame.color->rgb.end());
  } else {
    out.color.reset();
  }
  out.color_intrinsics = frame.color_intrinsics;
  out.depth_to_color = frame.depth_to_color;
  out.valid = result.valid;
  // The pipeline's foreground and capsules belong to the last frame that got as far as the
  // search: shown only for a frame that did (a valid one), never an older frame's.
  out.foreground_camera.clear();
  out.capsules_base.clear();
  if (result.valid) {
    const PointCloud& points = pipeline.foreground().points_camera;
    out.foreground_camera.reserve(points.size() * 3);
    for (size_t i = 0; i < points.size(); ++i) {
      out.foreground_camera.push_back(points.x[i]);
      out.foreground_camera.push_back(points.y[i]);
      out.foreground_camera.push_back(points.z[i]);
    }
    out.capsules_base = pipeline.robot().capsules;
    const size_t mask_pixels = pipeline.foreground().mask.size();
    const size_t depth_pixels = frame.depth.pixels.size();
    out.foreground_footprint =
        mask_pixels > 0 ? static_cast<float>(std::sqrt(static_cast<double>(depth_pixels) / mask_pixels)) : 1.0F;
  }
  out.T_camera_base = pipeline.params().T_base_camera.inverse();
  out.contact = result.contact;
  out.foreground_points = result.foreground_points;
  out.invalid_pixels = result.invalid_pixels;
  out.latency_us = result.latency_us;
  out.slow_distance_m = pipeline.params().safety.slow_distance_m;
  out.stop_distance_m = pipeline.params().safety.stop_distance_m;
}

ViewTap::ViewTap(std::set<int64_t> snapshot_frames) : snapshots_(std::move(snapshot_frames)) {}

void ViewTap::offer(const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
  fill_view_frame(frame, pipeline, result, steady_now_ns(), offer_scratch_);
  std::lock_guard<std::mutex> lock(mutex_);
  // A free slot, else the oldest: a frame the output has not decided after kPendingFrames
  // newer ones were offered (a paced run drops such measurements undecided).
  Pending* slot = nullptr;
  for (Pending& p : pending_) {
    if (p.offered == 0) {
      slot = &p;
      break;
    }
    if (slot == nullptr || p.offered < slot->offered) slot = &p;
  }
  std::swap(slot->view, offer_scratch_);  // the slot's old buffers are the next offer's
  slot->frame = result.frame;
  slot->delivered_ns = result.delivered_ns;
  slot->offered = ++offered_;
}

void ViewTap::decided(const FrameResult& result) {
  if (!result.source_frame) {
    // A watchdog or end-of-run stop: the last frame published shows it (take()).
    std::lock_guard<std::mutex> lock(mutex_);
    no_frame_ = result.verdict;
    no_frame_after_ = published_;
    return;
  }
  bool publish = false;
  bool snapshot = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Pending* match = nullptr;
    for (Pending& p : pending_) {
      if (p.offered != 0 && p.frame == result.frame && p.delivered_ns == result.delivered_ns &&
          (match == nullptr || p.offered < match->offered)) {
        match = &p;
      }
    }
    TimelinePoint point;
    point.made_ns = steady_now_ns();
    if (match != nullptr) {
      // Views offered before this one were never decided: the pipeline dropped them.
      for (Pending& p : pending_) {
        if (p.offered != 0 && p.offered < match->offered) p.offered = 0;
      }
      std::swap(publish_scratch_, match->view);
      match->offered = 0;
      point.made_ns = publish_scratch_.made_ns;
      publish_scratch_.publication = ++published_;
      publish = true;
    } else {
      ++views_missing_;  // its view was forgotten: better no picture than another frame's
    }
    point.timestamp_ns = result.timestamp_ns;
    point.distance_m = result.contact.valid ? result.contact.distance_m : -1.0F;
    point.state = result.verdict.state;
    point.latency_us = result.latency_us;
    timeline_.add(point);
    // Frames dropped before or after processing (paced: processing or the output behind the
    // source) leave gaps in the decided frames' source indices.
    if (last_index_ >= 0 && result.frame > last_index_ + 1) index_gaps_ += result.frame - last_index_ - 1;
    last_index_ = result.frame;
    snapshot = publish && snapshots_.count(result.frame) > 0;
  }
  if (!publish) return;
  publish_scratch_.verdict = result.verdict;
  if (!mailbox_.put(publish_scratch_)) return;  // the renderer is gone
  if (!snapshot) return;
  std::unique_lock<std::mutex> lock(mutex_);
  drawn_.wait(lock, [&] { return closed_ || snapshots_.count(result.frame) == 0; });
}

bool ViewTap::take(ViewFrame& out, double timeout_s) {
  const bool fresh = mailbox_.take_for(out, timeout_s);
  std::lock_guard<std::mutex> lock(mutex_);
  if (no_frame_ && out.publication > 0 && out.publication == no_frame_after_) out.verdict = *no_frame_;
  return fresh;
}

int64_t ViewTap::index_gaps() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return index_gaps_;
}

int64_t ViewTap::dropped() const {
  const int64_t replaced = mailbox_.dropped();
  std::lock_guard<std::mutex> lock(mutex_);
  return replaced + views_missing_;
}

void ViewTap::rendered(int64_t index) {
  std::lock_guard<std::mutex> lock(mutex_);
  snapshots_.erase(index);
  drawn_.notify_all();
}

void ViewTap::close() {
  mailbox_.close();
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
  drawn_.notify_all();
}

void ViewTap::timeline(std::vector<TimelinePoint>& out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  out = timeline_.points();
}

size_t ViewTap::snapshots_pending() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshots_.size();
}

}  // namespace hrcsense::view
