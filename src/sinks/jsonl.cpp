// SPDX-License-Identifier: Apache-2.0
// hrcsense sinks — JSON Lines: a header, one line per frame, a summary (docs/OUTPUT.md).
// Lines are composed by hand into a reused string so that writing a frame does not allocate.
#include "hrcsense/sinks/sinks.hpp"

#include "hrcsense/safety.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/robot_state.hpp"

#include "jsonl_text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string_view>

#ifndef HRCSENSE_VERSION
#define HRCSENSE_VERSION "unknown"
#endif
#ifndef HRCSENSE_COMMIT
#define HRCSENSE_COMMIT "unknown"
#endif

namespace hrcsense {
namespace {

using jsonl_detail::Members;
using jsonl_detail::put_double;
using jsonl_detail::put_float;
using jsonl_detail::put_key;
using jsonl_detail::put_seconds;

// `governing_link` and `links`: per link with a measured contact its distance, speed towards
// the contact, Z_d and S_p at its own speed; [] and null without a contact.
void put_links(Members& m, const FrameResult& result) {
  if (result.governing_link >= 0) {
    m.integer("governing_link", result.governing_link);
  } else {
    m.null("governing_link");
  }
  std::string& line = m.line;
  put_key(line, "links");
  line += '[';
  for (size_t i = 0; i < result.links.size(); ++i) {
    const LinkContact& link = result.links[i];
    if (i > 0) line += ',';
    line += '{';
    m.integer("link", link.link);
    m.number("distance_m", link.contact.distance_m);
    m.number_or_null("speed_towards_mps", std::isfinite(link.speed_towards_mps), link.speed_towards_mps);
    m.number_or_null("distance_uncertainty_m", std::isfinite(link.distance_uncertainty_m),
                     link.distance_uncertainty_m);
    const bool has_sp = i < result.link_protective_distance_m.size();
    m.number_or_null("protective_distance_m", has_sp, has_sp ? result.link_protective_distance_m[i] : 0.0F);
    line += '}';
  }
  line += ']';
}

void put_pinhole(Members& m, const Intrinsics& in) {
  m.integer("width", in.width);
  m.integer("height", in.height);
  m.number("fx", in.fx);
  m.number("fy", in.fy);
  m.number("ppx", in.ppx);
  m.number("ppy", in.ppy);
}

// The filters as they run; the filtered resolution is the one contact pixels and the learnt
// background refer to. Left out when no configuration said (preset empty).
void put_filters(Members& m, const RunHeader::Filters& filters) {
  if (filters.preset.empty()) return;
  m.open("filters");
  m.text("preset", filters.preset);
  m.text("domain", filters.domain);
  if (!filters.note.empty()) m.text("note", filters.note);
  put_pinhole(m, filters.intrinsics);
  m.close();
}

// `source`: what the frames come from; the camera's name, serial and firmware when known.
void put_source(Members& m, const SourceInfo& source) {
  m.open("source");
  m.text("type", source.type);
  m.text("description", source.description);
  m.integer("frame_count", source.frame_count);
  m.number("nominal_fps", source.nominal_fps);
  m.number("stereo_baseline_mm", source.stereo_baseline_mm);
  m.text_or_null("sensor_model", source.sensor_model);
  if (!source.camera_serial.empty() || !source.camera_name.empty()) {
    m.text("name", source.camera_name);
    m.text("serial", source.camera_serial);
    m.text("firmware", source.camera_firmware);
  }
  m.close();
}

// `intrinsics`: the source's pinhole, distortion model and coefficients.
void put_intrinsics(Members& m, const Intrinsics& in) {
  m.open("intrinsics");
  put_pinhole(m, in);
  m.text("model", distortion_name(in.model));
  put_key(m.line, "coeffs");
  m.line += '[';
  for (size_t i = 0; i < in.coeffs.size(); ++i) {
    if (i > 0) m.line += ',';
    put_float(m.line, in.coeffs[i]);
  }
  m.line += ']';
  m.close();
}


// A fused cell's header `cameras`: name, nominal rate, pose (translation and a quaternion
// x, y, z, w, base ← camera optical) and intrinsics (null until the camera reported them).
void put_header_cameras(Members& m, const std::vector<RunHeader::Camera>& cameras) {
  if (cameras.empty()) return;
  std::string& line = m.line;
  put_key(line, "cameras");
  line += '[';
  for (size_t i = 0; i < cameras.size(); ++i) {
    const RunHeader::Camera& c = cameras[i];
    if (i > 0) line += ',';
    line += '{';
    m.text("name", c.name);
    m.number("nominal_fps", c.nominal_fps);
    const Eigen::Vector3d t = c.T_base_camera.translation();
    const Eigen::Quaterniond q(c.T_base_camera.linear());
    put_key(line, "T_base_camera");
    line += "{";
    put_key(line, "translation_m");
    line += '[';
    put_double(line, t.x());
    line += ',';
    put_double(line, t.y());
    line += ',';
    put_double(line, t.z());
    line += ']';
    put_key(line, "quaternion_xyzw");
    line += '[';
    put_double(line, q.x());
    line += ',';
    put_double(line, q.y());
    line += ',';
    put_double(line, q.z());
    line += ',';
    put_double(line, q.w());
    line += "]}";
    if (c.intrinsics.width > 0) {
      put_intrinsics(m, c.intrinsics);
    } else {
      m.null("intrinsics");
    }
    line += '}';
  }
  line += ']';
}

// A fused frame's `cameras` (each camera's age, validity, reason and session at this instant)
// and `closest_camera_name`; nothing for a single camera's frame.
void put_frame_cameras(Members& m, const FrameResult& result) {
  if (result.cameras.empty()) return;
  std::string& line = m.line;
  put_key(line, "cameras");
  line += '[';
  for (size_t i = 0; i < result.cameras.size(); ++i) {
    const CameraStatus& c = result.cameras[i];
    if (i > 0) line += ',';
    line += '{';
    m.text("name", c.name);
    m.number_or_null("age_ms", std::isfinite(c.age_ms), c.age_ms);
    m.boolean("valid", c.valid);
    m.text("reason_code", reason_code_name(c.reason_code));
    m.integer("session", c.session);
    line += '}';
  }
  line += ']';
  m.text_or_null("closest_camera_name", result.closest_camera_name);
}

// A camera of a cell with several, and a fused cell: the shared grid's cubes and how many of
// them no camera saw free this frame (`seen_free`); nothing without a grid.
void put_seen_free(Members& m, const SeenFreeGrid& grid) {
  if (grid.cells == 0) return;
  // Eight bytes at a time: a fused line of a 264 000-cube grid counts 33 000 bytes.
  size_t free_cubes = 0;
  size_t i = 0;
  for (; i + 8 <= grid.bytes.size(); i += 8) {
    uint64_t word = 0;
    std::memcpy(&word, grid.bytes.data() + i, sizeof word);
    free_cubes += static_cast<size_t>(__builtin_popcountll(word));
  }
  for (; i < grid.bytes.size(); ++i) free_cubes += static_cast<size_t>(__builtin_popcount(grid.bytes[i]));
  m.open("seen_free");
  m.integer("cubes", static_cast<int64_t>(grid.cells));
  m.integer("unknown", static_cast<int64_t>(grid.cells - std::min(free_cubes, grid.cells)));
  m.close();
}

// `ssm`: S_p's terms (safety.mode ssm, a frame with a contact); null otherwise.
void put_ssm(Members& m, const std::optional<SsmTerms>& ssm) {
  if (!ssm) {
    m.null("ssm");
    return;
  }
  m.open("ssm");
  m.number("s_h_m", ssm->s_h_m);
  m.number("s_r_m", ssm->s_r_m);
  m.number("s_s_m", ssm->s_s_m);
  m.number("c_m", ssm->c_m);
  m.number("z_d_m", ssm->z_d_m);
  m.number("z_r_m", ssm->z_r_m);
  m.number("z_r_state_m", ssm->z_r_state_m);
  m.number("reaction_time_s", ssm->reaction_time_s);
  // T_r's parts, which add up to reaction_time_s (docs/SAFETY.md, "T_r: every latency").
  m.open("reaction_time_parts");
  m.number("frame_age_s", ssm->frame_age_s);
  m.number("frame_period_s", ssm->frame_period_s);
  m.number("source_latency_s", ssm->source_latency_s);
  m.number("controller_latency_s", ssm->controller_latency_s);
  m.number("receiver_timeout_s", ssm->receiver_timeout_s);
  m.close();
  m.number("stop_time_s", ssm->stop_time_s);
  m.close();
}

// The closest pair in the camera, base and robot base frames; null without a contact.
void put_contact(Members& m, const Contact& contact) {
  m.point_or_null("closest_camera", contact.valid, contact.closest_camera);
  m.point_or_null("closest_base", contact.valid, contact.closest_base);
  m.point_or_null("closest_robot_base", contact.valid, contact.closest_robot_base);
  if (contact.valid) {
    m.integer("robot_link", contact.robot_link);
    m.boolean("inside", contact.inside);  // a foreground point inside (or on) a capsule: distance 0
  } else {
    m.null("robot_link");
    m.null("inside");
  }
}

// `joints_rad`: the joints the robot's capsules were built from; null without a valid robot state.
void put_joints(Members& m, const RobotState& state) {
  put_key(m.line, "joints_rad");
  if (!state.valid) {
    m.line += "null";
    return;
  }
  m.line += '[';
  for (size_t j = 0; j < kJointCount; ++j) {
    if (j > 0) m.line += ',';
    put_double(m.line, state.q_rad[j]);
  }
  m.line += ']';
}

// `robot_status`: the controller's own report (rtde): present where the source has one, null in
// frames without a valid state from such a source (`announced`), absent for sources that have none.
void put_robot_status(Members& m, const RobotStatus& status, bool announced) {
  if (status.known) {
    m.open("robot_status");
    m.integer("robot_mode", status.robot_mode);
    m.text("robot_mode_name", robot_mode_name(status.robot_mode));
    m.integer("safety_mode", status.safety_mode);
    m.text("safety_mode_name", safety_mode_name(status.safety_mode));
    m.number("speed_scaling", status.speed_scaling);
    m.number_or_null("target_speed_fraction", std::isfinite(status.target_speed_fraction),
                     status.target_speed_fraction);
    m.boolean("tcp_pose_mismatch", status.tcp_pose_mismatch);
    m.close();
  } else if (announced) {
    m.null("robot_status");
  }
}

// `truth`: the simulator's exact contact and per-link distances; absent for other sources.
void put_truth(Members& m, const FrameResult& result, const char* contact_label) {
  if (!result.truth) return;
  m.open("truth");
  m.number_or_null("distance_m", result.truth->valid, result.truth->distance_m);
  m.point_or_null("closest_base", result.truth->valid, result.truth->closest_base);
  if (contact_label != nullptr) {
    m.text("contact_label", contact_label);
  } else {
    m.null("contact_label");
  }
  std::string& line = m.line;
  put_key(line, "links");
  line += '[';
  for (const LinkTruth& link : result.truth_links) {
    if (line.back() != '[') line += ',';
    line += '{';
    m.integer("link", link.link);
    m.number("distance_m", link.distance_m);
    m.number("speed_towards_mps", link.speed_towards_mps);
    line += '}';
  }
  line += ']';
  m.close();
}


/// `robot_state`: the robot state source's sample counters and the controller's reports.
void put_robot_state_counters(Members& m, const RobotStateStats& robot, const RobotStatusCounts& status) {
  m.open("robot_state");
  m.integer("accepted", robot.samples.accepted);
  m.integer("rejected_non_finite", robot.samples.rejected_non_finite);
  m.integer("rejected_backwards", robot.samples.rejected_backwards);
  m.integer("rejected_jump", robot.samples.rejected_jump);
  m.integer("rejected_limits", robot.samples.rejected_limits);
  m.integer("connections", robot.connections);
  m.integer("disconnects", robot.disconnects);
  m.integer("malformed", robot.malformed);
  m.integer("frames_with_status", status.frames_reported);
  m.integer("frames_not_running", status.frames_not_running);
  m.integer("frames_protective_stop", status.frames_protective_stop);
  m.integer("mode_changes", status.mode_changes);
  m.integer("frames_tcp_pose_mismatch", status.frames_tcp_pose_mismatch);
  m.text_or_null("last_problem", robot.last_problem);
  m.close();
}

/// `record`: the recorder's counters, null when the run recorded nothing.
void put_record_counters(Members& m, const std::optional<RecordCounters>& record) {
  if (!record) {
    m.null("record");
    return;
  }
  m.open("record");
  m.integer("frames_recorded", record->frames_recorded);
  m.integer("frames_dropped", record->frames_dropped);
  m.texts("files", record->files);
  m.text_or_null("error", record->error);
  m.close();
}

}  // namespace

void JsonLinesSink::header(const RunHeader& header) {
  line_.assign("{");
  Members m{line_};
  m.text("type", "header");
  m.text("version", header.version.empty() ? HRCSENSE_VERSION : header.version);
  m.text("commit", header.commit.empty() ? HRCSENSE_COMMIT : header.commit);
  m.text("config_hash", header.config_hash);
  // The link's datagrams carry the same session: a receiver's log and this file name one process.
  if (header.session != 0) {
    m.integer("session", header.session);
  } else {
    m.null("session");
  }
  // Every output says it, where a reader of the file would otherwise assume it (issue G2).
  m.text("safety_notice", kSafetyNotice);
  if (!header.robot_state.empty()) {
    m.text("robot_state", header.robot_state);
    m.texts("robot_state_reports", header.robot_state_reports);
  }
  m.text_or_null("stopping_data", header.stopping_data);
  robot_status_announced_ = std::find(header.robot_state_reports.begin(), header.robot_state_reports.end(),
                                      "robot_status") != header.robot_state_reports.end();
  m.number_or_null("unknown_background_share", header.unknown_background_share >= 0.0,
                   header.unknown_background_share);
  put_source(m, header.source);
  put_intrinsics(m, header.source.intrinsics);
  put_filters(m, header.filters);
  put_header_cameras(m, header.cameras);
  line_ += "}\n";
  write_line();
}

void JsonLinesSink::frame(const FrameResult& result) {
  const Contact& contact = result.contact;
  line_.assign("{");
  Members m{line_};
  m.text("type", result.source_frame ? "frame" : "verdict");
  m.integer("frame", result.frame);
  m.integer("timestamp_ns", result.timestamp_ns);
  put_key(line_, "timestamp_s");
  put_seconds(line_, result.timestamp_ns);
  m.boolean("valid", result.valid);
  m.text("verdict", verdict_name(result.verdict.state));
  m.text("verdict_reason", result.verdict.reason);
  m.text("reason_code", reason_code_name(result.verdict.code));
  m.number("speed_scale", result.verdict.speed_scale);
  m.number_or_null("distance_m", contact.valid, contact.distance_m);
  m.number("protective_distance_m", result.verdict.protective_distance_m);
  put_ssm(m, result.ssm);
  m.number_or_null("distance_uncertainty_m", std::isfinite(result.distance_uncertainty_m),
                   result.distance_uncertainty_m);
  m.number_or_null("robot_speed_towards_mps", std::isfinite(result.robot_speed_towards_mps),
                   result.robot_speed_towards_mps);
  // The share of the programmed speed the speed scale was computed against (null on stop lines
  // that stand for no frame).
  m.number_or_null("robot_speed_fraction", std::isfinite(result.robot_speed_fraction), result.robot_speed_fraction);
  m.number_or_null("unknown_distance_m", std::isfinite(result.unknown_distance_m), result.unknown_distance_m);
  m.number_or_null("unknown_margin_m", std::isfinite(result.unknown_margin_m), result.unknown_margin_m);
  put_links(m, result);
  put_contact(m, contact);
  // The backend that searched (auto's pick), else the configured one.
  m.text("backend", result.backend != nullptr ? result.backend : backend_.c_str());
  m.integer("foreground_points", static_cast<int64_t>(result.foreground_points));
  m.integer("self_filtered_pixels", static_cast<int64_t>(result.self_filtered_pixels));
  m.integer("invalid_pixels", static_cast<int64_t>(result.invalid_pixels));
  m.number("valid_share", result.valid_share);
  m.integer("host_time_ns", result.host_time_ns);
  m.number("frame_age_s", result.frame_age_s);  // when the monitor decided it: what T_r counted
  put_joints(m, result.robot_state);
  m.number("robot_state_age_ms", result.robot_state_age_ms);
  put_robot_status(m, result.robot_state.status, robot_status_announced_);
  m.number("latency_us", result.latency_us);
  m.open("timings_us");
  for (const StageTiming& timing : result.timings) m.number(timing.stage, timing.us);
  m.close();
  put_frame_cameras(m, result);
  put_seen_free(m, result.seen_free);
  const bool labelled = result.truth && result.contact.valid && extras_.contact_label;
  put_truth(m, result, labelled ? extras_.contact_label(result) : nullptr);
  line_ += "}\n";
  write_line();
}

void JsonLinesSink::summary(const RunSummary& summary) {
  line_.assign("{");
  Members m{line_};
  m.text("type", "summary");
  const AppCounters app = extras_.app_counters ? extras_.app_counters() : AppCounters{};
  m.integer("frames_in", summary.frames_in);
  m.integer("frames_processed", summary.frames_processed);
  m.integer("frames_dropped", summary.frames_dropped);
  m.integer("frames_dropped_camera", summary.frames_dropped_camera);
  if (app.viewer_frames_dropped) {
    m.integer("viewer_frames_dropped", *app.viewer_frames_dropped);
  } else {
    m.null("viewer_frames_dropped");
  }
  m.integer("frames_valid", summary.frames_valid);
  m.integer("verdict_run", summary.verdict_run);
  m.integer("verdict_slow", summary.verdict_slow);
  m.integer("verdict_stop", summary.verdict_stop);
  m.number("wall_s", summary.wall_s);
  m.number("fps", summary.fps);
  m.number("latency_p50_us", summary.latency_p50_us);
  m.number("latency_p99_us", summary.latency_p99_us);
  // Negative when there never was any foreground.
  m.number_or_null("min_distance_m", summary.min_distance_m >= 0.0F, summary.min_distance_m);
  m.text("end_reason", summary.end_reason);
  m.text("end_reason_code", reason_code_name(summary.end_code));
  m.text_or_null("error", summary.error);
  m.integer("timestamps_backwards", summary.timestamps.backwards);
  m.integer("timestamps_repeated", summary.timestamps.repeated);
  m.integer("timestamp_gaps", summary.timestamps.gaps);
  m.integer("frames_skipped_source", summary.timestamps.frames_skipped);
  m.integer("timestamp_jumps", summary.timestamps.jumps);
  m.number_or_null("unknown_background_share", summary.unknown_background_share >= 0.0,
                   summary.unknown_background_share);
  if (!summary.cameras.empty()) {
    put_key(line_, "cameras");
    line_ += '[';
    for (size_t c = 0; c < summary.cameras.size(); ++c) {
      const RunSummary::CameraIntake& in = summary.cameras[c];
      if (c > 0) line_ += ',';
      line_ += '{';
      m.text("name", in.name);
      m.integer("accepted", in.accepted);
      m.integer("malformed", in.malformed);
      m.integer("out_of_order", in.out_of_order);
      m.integer("clock_ahead", in.clock_ahead);
      m.integer("grid_mismatch", in.grid_mismatch);
      m.integer("name_mismatch", in.name_mismatch);
      m.integer("sessions", in.sessions);
      m.text_or_null("last_problem", in.last_problem);
      line_ += '}';
    }
    line_ += ']';
    m.integer("unconfigured_measurement_publishers", summary.unconfigured_measurement_publishers);
    m.text_or_null("last_unconfigured_measurement_topic", summary.last_unconfigured_measurement_topic);
  }
  put_robot_state_counters(m, summary.robot_state, summary.robot_status);
  put_record_counters(m, app.record);
  line_ += "}\n";
  write_line();
}

// Every line is flushed as soon as it is complete: a reader (a pipe to the robot's bridge, a
// terminal) must see each verdict when it is made, not in blocks of a few kilobytes.
// docs/BENCHMARKS.md measures the cost. A failed write is kept: failed() ends the run.
void JsonLinesSink::write_line() {
  out_ << line_;
  out_.flush();
}

}  // namespace hrcsense
