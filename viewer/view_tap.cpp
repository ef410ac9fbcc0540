// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the processing thread's tap into the renderer's mailbox (view_tap.hpp).
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
  out.verdict = result.verdict;
  out.foreground_points = result.foreground_points;
  out.invalid_pixels = result.invalid_pixels;
  out.latency_us = result.latency_us;
  out.slow_distance_m = pipeline.params().safety.slow_distance_m;
  out.stop_distance_m = pipeline.params().safety.stop_distance_m;
}

ViewTap::ViewTap(std::set<int64_t> snapshot_frames) : pending_(std::move(snapshot_frames)) {}

void ViewTap::offer(const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
  const int64_t now_ns = steady_now_ns();
  fill_view_frame(frame, pipeline, result, now_ns, scratch_);
  TimelinePoint point;
  point.timestamp_ns = result.timestamp_ns;
  point.made_ns = now_ns;
  point.distance_m = result.contact.valid ? result.contact.distance_m : -1.0F;
  point.state = result.verdict.state;
  point.latency_us = result.latency_us;
  const bool snapshot = [&] {
    std::lock_guard<std::mutex> lock(mutex_);
    timeline_.add(point);
    // Frames the pipeline dropped (paced: processing behind the source) leave gaps in the
    // processed frames' source indices.
    if (last_index_ >= 0 && result.frame > last_index_ + 1) index_gaps_ += result.frame - last_index_ - 1;
    last_index_ = result.frame;
    return result.source_frame && pending_.count(result.frame) > 0;
  }();
  if (!mailbox_.put(scratch_)) return;  // the renderer is gone
  if (!snapshot) return;
  std::unique_lock<std::mutex> lock(mutex_);
  drawn_.wait(lock, [&] { return closed_ || pending_.count(result.frame) == 0; });
}

int64_t ViewTap::index_gaps() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return index_gaps_;
}

void ViewTap::rendered(int64_t index) {
  std::lock_guard<std::mutex> lock(mutex_);
  pending_.erase(index);
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
  return pending_.size();
}

}  // namespace hrcsense::view
