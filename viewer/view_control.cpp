// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — requests from the panels to the running pipeline (view_control.hpp).
#include "viewer/view_control.hpp"

#include "common/assembly.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/safety.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace hrcsense::view {

std::string relearn_refusal(const Measurement& previous, const SafetyParams& safety) {
  if (!previous.robot_state.valid) return "no valid robot state to judge by: the robot may be moving";
  for (size_t j = 0; j < previous.robot_state.qd_rad_s.size(); ++j) {
    const double speed = std::abs(previous.robot_state.qd_rad_s[j]);
    if (!(speed <= kRobotMovingRadS)) {  // NaN counts as moving
      char text[96];
      std::snprintf(text, sizeof text, "the robot is moving (joint %zu at %.3f rad/s)", j + 1, speed);
      return text;
    }
  }
  if (!previous.valid) return {};  // no contact measured (learning the background, no depth...)
  const ReasonCode code = verdict_for_contact(safety, previous.contact, previous.foreground_points).code;
  if (code == ReasonCode::in_slow_zone || code == ReasonCode::in_stop_zone || code == ReasonCode::inside_robot) {
    char text[96];
    std::snprintf(text, sizeof text, "something is %.2f m from the robot (%s)",
                  static_cast<double>(previous.contact.distance_m), reason_code_name(code));
    return text;
  }
  return {};
}

void ControlInbox::post_tuning(const LiveTuning& tuning) {
  const std::lock_guard<std::mutex> lock(mutex_);
  tuning_ = tuning;
}

void ControlInbox::post_relearn() {
  const std::lock_guard<std::mutex> lock(mutex_);
  relearn_ = true;
}

void ControlInbox::apply(Pipeline& pipeline, const FrameResult& previous) {
  std::optional<LiveTuning> tuning;
  bool relearn = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!tuning_ && !relearn_) return;  // the common case: nothing posted
    tuning.swap(tuning_);
    std::swap(relearn, relearn_);
  }
  const int64_t after_frame = previous.frame;
  std::vector<ControlEvent> events;
  if (tuning) {
    std::string refusal = live_tuning_refusal(configured_, *tuning);
    if (refusal.empty()) {
      try {
        pipeline.retune(*tuning);
      } catch (const std::invalid_argument& e) {
        refusal = e.what();
      }
    }
    if (refusal.empty()) {
      events.push_back({after_frame, false, "parameters applied"});
      spdlog::info("viewer: tuned parameters applied after frame {}", after_frame);
    } else {
      events.push_back({after_frame, true, "parameters refused: " + refusal});
      spdlog::warn("viewer: tuned parameters refused: {}", refusal);
    }
  }
  if (relearn) {
    const std::string refusal = relearn_refusal(previous, pipeline.params().safety);
    if (refusal.empty()) {
      pipeline.relearn_background();
      events.push_back({after_frame, false, "relearning the background"});
      spdlog::warn("viewer: background relearn requested; learning again after frame {} (stops until done)",
                   after_frame);
    } else {
      events.push_back({after_frame, true, "relearn refused: " + refusal});
      spdlog::warn("viewer: background relearn refused: {}", refusal);
    }
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  for (ControlEvent& event : events) events_.push_back(std::move(event));
}

std::vector<ControlEvent> ControlInbox::take_events() {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ControlEvent> out;
  out.swap(events_);
  return out;
}

Config tuned_config(const std::string& config_path, const std::vector<std::string>& sets, const LiveTuning& tuning) {
  std::vector<std::string> all = sets;
  const std::vector<std::string> tuned = tuning_overrides(tuning);
  all.insert(all.end(), tuned.begin(), tuned.end());
  return load_config(config_path, all);
}

void save_tuned_config(const Config& config, const std::string& path) {
  std::ofstream out(path, std::ios::out | std::ios::trunc);
  if (!out) throw IoError(path + ": cannot open for writing");
  out << "# hrcsense: " << config_where(config)
      << " with parameters tuned in hrcsense-view.\n# Every key is spelled out; run it with: hrcsense run --config " << path << "\n"
      << config.canonical_yaml;
  out.flush();
  if (!out) throw IoError(path + ": write failed");
}

std::set<int64_t> parse_frame_list(const std::string& text) {
  std::set<int64_t> frames;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) continue;
    size_t used = 0;
    long long value = -1;
    try {
      value = std::stoll(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || value < 0) {
      throw ConfigError("--snapshot-at: '" + item + "' is not a source frame index (0, 1, ...)");
    }
    frames.insert(value);
  }
  if (frames.empty()) throw ConfigError("--snapshot-at: no frame index given (e.g. --snapshot-at 123,198)");
  return frames;
}

}  // namespace hrcsense::view
