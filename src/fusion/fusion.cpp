// SPDX-License-Identifier: Apache-2.0
// hrcsense — the fuser's memory of a cell's cameras and the one measurement it makes of them
// (docs/MULTICAMERA.md): nothing here talks to the network or reads a clock.

#include "hrcsense/fusion.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

namespace hrcsense {
namespace {

constexpr double kNsPerMs = 1e6;

bool finite3(const Eigen::Vector3f& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }

// The codes a measurement may carry: the enum's, no other number (a sender's garbage would
// otherwise print as an empty name and compare as nothing known).
bool known_reason_code(ReasonCode code) {
  const auto n = static_cast<uint16_t>(code);
  return n <= static_cast<uint16_t>(ReasonCode::camera_pose_mismatch);
}

std::string contact_problem(const std::string& field, const Contact& c) {
  if (!c.valid) return {};
  if (!std::isfinite(c.distance_m) || c.distance_m < 0.0F) {
    char text[96];
    std::snprintf(text, sizeof text, "%s.distance_m: %g is not a distance", field.c_str(), static_cast<double>(c.distance_m));
    return text;
  }
  if (!finite3(c.closest_base) || !finite3(c.closest_robot_base) || !finite3(c.closest_camera)) {
    return field + ": a point is not finite";
  }
  return {};
}

// (state, scale, d − S_p) of one link's contact as the monitor would decide it alone, for ranking
// two cameras' contacts of the same link: the stricter one is kept.
struct Rank {
  int strictness = 0;
  float scale = 1.0F;
  float slack_m = 0.0F;
  bool stricter_than(const Rank& o) const {
    if (strictness != o.strictness) return strictness > o.strictness;
    if (scale != o.scale) return scale < o.scale;
    return slack_m < o.slack_m;
  }
};

Rank rank_of(const SafetyParams& params, const CameraMeasurement& m, const LinkContact& link) {
  VerdictInput input;
  input.contact = link.contact;
  input.foreground_points = std::max<size_t>(1, m.foreground_points);
  input.distance_uncertainty_m = link.distance_uncertainty_m;
  input.robot_speed_towards_mps = link.speed_towards_mps;
  const double fraction = m.robot_state.speed_fraction;
  input.robot_speed_scaling = fraction >= 0.0 && fraction <= 1.0 ? fraction : 1.0;
  const Decision d = decide_verdict(params, input);
  Rank r;
  r.strictness = verdict_strictness(d.verdict.state);
  r.scale = d.verdict.speed_scale;
  r.slack_m = link.contact.distance_m - d.verdict.protective_distance_m;
  if (std::isnan(r.slack_m)) r.slack_m = -std::numeric_limits<float>::infinity();
  return r;
}

}  // namespace

bool is_camera_name(const std::string& name) {
  if (name.empty() || std::isalpha(static_cast<unsigned char>(name.front())) == 0) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_'; });
}

void to_camera_measurement(const Measurement& m, int64_t realtime_minus_steady_ns, CameraMeasurement& out) {
  const auto shared = [&](int64_t steady_ns) { return steady_ns == 0 ? 0 : steady_ns + realtime_minus_steady_ns; };
  out.frame = m.frame;
  out.capture_ns = shared(m.clocked ? m.seen_ns : m.host_time_ns);
  out.valid = m.valid;
  out.reason_code = m.valid ? ReasonCode::clear : m.withheld_code;
  out.reason = m.valid ? std::string() : m.withheld_reason;
  out.contact = m.contact;
  out.links = m.links;
  out.unknown_distance_m = m.unknown_distance_m;
  out.seen_free = m.seen_free;
  out.foreground_points = static_cast<uint32_t>(std::min<size_t>(m.foreground_points, UINT32_MAX));
  out.self_filtered_pixels = static_cast<uint32_t>(std::min<size_t>(m.self_filtered_pixels, UINT32_MAX));
  out.invalid_pixels = static_cast<uint32_t>(std::min<size_t>(m.invalid_pixels, UINT32_MAX));
  out.valid_share = m.valid_share;
  out.robot_state = m.robot_state;
  out.robot_state.host_time_ns = shared(m.robot_state.host_time_ns);
  out.robot_state.sample_time_ns = shared(m.robot_state.sample_time_ns);
  out.robot_state_age_ms = m.robot_state_age_ms;
  out.latency_us = m.latency_us;
  out.truth = m.truth;
  out.truth_links = m.truth_links;
}

std::string measurement_problem(const CameraMeasurement& m) {
  if (m.camera_name.empty()) return "camera_name: empty";
  if (m.session == 0) return "session: 0 (a session is never 0)";
  if (m.sequence == 0) return "sequence: 0 (the first is 1)";
  if (!(m.nominal_fps > 0.0) || !std::isfinite(m.nominal_fps) || m.nominal_fps > 10000.0) {
    return "nominal_fps: not a frame rate";
  }
  if (m.capture_ns <= 0) return "capture: not a time";
  if (!known_reason_code(m.reason_code)) return "reason_code: " + std::to_string(static_cast<int>(m.reason_code)) + " is unknown";
  // The fuser reads code 0 as "this camera has no fault": a withheld measurement must say why.
  if (!m.valid && m.reason_code == ReasonCode::clear) return "reason_code: 0 (clear) on a withheld measurement";
  if (m.links.size() > static_cast<size_t>(kMaxFusedLinks)) return "links: more than " + std::to_string(kMaxFusedLinks);
  uint64_t seen_links = 0;
  for (size_t i = 0; i < m.links.size(); ++i) {
    const LinkContact& link = m.links[i];
    const std::string field = "links[" + std::to_string(i) + "]";
    if (link.link < 0 || link.link >= kMaxFusedLinks) return field + ".link: " + std::to_string(link.link) + " is out of range";
    const uint64_t bit = uint64_t{1} << link.link;
    if ((seen_links & bit) != 0U) return field + ".link: " + std::to_string(link.link) + " twice";
    seen_links |= bit;
    if (!m.valid) continue;
    if (!link.contact.valid) return field + ": no contact";
    if (std::string p = contact_problem(field + ".contact", link.contact); !p.empty()) return p;
  }
  if (m.valid) {
    if (std::string p = contact_problem("contact", m.contact); !p.empty()) return p;
    if (m.contact.valid == m.links.empty()) return "contact: a contact needs its links, and links a contact";
  }
  if (!std::isfinite(m.latency_us) || m.latency_us < 0.0) return "latency_us: not a duration";
  return {};
}

const char* fusion_intake_name(FusionIntake intake) {
  switch (intake) {
    case FusionIntake::accepted: return "accepted";
    case FusionIntake::unknown_camera: return "unknown_camera";
    case FusionIntake::malformed: return "malformed";
    case FusionIntake::out_of_order: return "out_of_order";
    case FusionIntake::clock_ahead: return "clock_ahead";
    case FusionIntake::grid_mismatch: return "grid_mismatch";
  }
  return "unknown";
}

CellFusion::CellFusion(std::vector<FusionCamera> cameras, FusionParams params)
    : cameras_(std::move(cameras)), params_(std::move(params)), slots_(cameras_.size()) {}

int CellFusion::camera_index(const std::string& name) const {
  for (size_t i = 0; i < cameras_.size(); ++i) {
    if (cameras_[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

const CameraMeasurement* CellFusion::newest(size_t i) const { return slots_[i].have ? &slots_[i].newest : nullptr; }

FusionIntake CellFusion::add(const CameraMeasurement& m, int64_t now_ns) {
  const int index = camera_index(m.camera_name);
  if (index < 0) {
    ++unknown_camera_;
    return FusionIntake::unknown_camera;
  }
  Slot& slot = slots_[static_cast<size_t>(index)];
  if (std::string problem = measurement_problem(m); !problem.empty()) {
    ++slot.counters.malformed;
    slot.counters.last_problem = std::move(problem);
    return FusionIntake::malformed;
  }
  const size_t cells = params_.grid.enabled ? params_.grid.cell_count() : 0;
  if (m.seen_free.cells != 0 && (m.seen_free.cells != cells || m.seen_free.bytes.size() != (cells + 7) / 8)) {
    ++slot.counters.grid_mismatch;
    return FusionIntake::grid_mismatch;
  }
  if (m.capture_ns - now_ns > params_.max_clock_ahead_ns) {
    ++slot.counters.clock_ahead;
    return FusionIntake::clock_ahead;
  }
  const bool new_session = !slot.have || m.session != slot.newest.session;
  if (!new_session && (m.sequence <= slot.newest.sequence || m.capture_ns <= slot.newest.capture_ns)) {
    ++slot.counters.out_of_order;
    return FusionIntake::out_of_order;
  }
  if (new_session) {
    // A restart: whatever the old session measured says nothing about the new process's view.
    slot.restarted = slot.have;
    slot.previous_session = slot.have ? slot.newest.session : 0;
    slot.have_valid = false;
    ++slot.counters.sessions;
  }
  slot.have = true;
  slot.newest = m;
  if (m.valid) {
    slot.have_valid = true;
    slot.restarted = false;
    slot.newest_valid_capture_ns = m.capture_ns;
  }
  ++slot.counters.accepted;
  return FusionIntake::accepted;
}

const std::string& CellFusion::camera_of_link(int link) const {
  int camera = contact_camera_;
  for (size_t i = 0; link >= 0 && i < link_ids_.size(); ++i) {
    if (link_ids_[i] == link) {
      camera = link_camera_[i];
      break;
    }
  }
  return camera >= 0 ? cameras_[static_cast<size_t>(camera)].name : empty_;
}

void CellFusion::fuse(int64_t instant_ns, int64_t frame, int64_t now_ns, Measurement& out) {
  out.frame = frame;
  out.source_frame = true;
  out.timestamp_ns = instant_ns;
  out.host_time_ns = instant_ns;
  out.clocked = true;
  out.delivered_ns = now_ns;
  out.seen_ns = instant_ns;
  out.valid = false;
  out.withheld_reason.clear();
  out.contact = Contact{};
  out.links.clear();
  out.foreground_points = 0;
  out.self_filtered_pixels = 0;
  out.invalid_pixels = 0;
  out.valid_share = 1.0F;
  out.timings.clear();
  out.robot_state = RobotState{};
  out.robot_state_age_ms = 0.0;
  out.truth.reset();
  out.truth_links.clear();
  out.latency_us = 0.0;
  out.unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
  out.backend = nullptr;
  out.timestamp_warning = nullptr;
  out.closest_camera_name.clear();
  out.cameras.resize(cameras_.size());
  link_camera_.clear();
  link_ids_.clear();
  contact_camera_ = -1;

  // Each camera's state; the first camera at fault gives the code, the reason names them all.
  ReasonCode first_fault = ReasonCode::clear;
  // Ages as the worst clock offset allowed would make them (cell.clock_offset_max_s).
  const int64_t offset_ns = params_.clock_offset_max_ns;
  for (size_t i = 0; i < cameras_.size(); ++i) {
    const Slot& slot = slots_[i];
    CameraStatus& status = out.cameras[i];
    status.name = cameras_[i].name;
    status.session = slot.have ? slot.newest.session : 0;
    status.age_ms = slot.have ? static_cast<double>(now_ns - slot.newest.capture_ns + offset_ns) / kNsPerMs
                              : std::numeric_limits<double>::quiet_NaN();
    status.valid = slot.have && slot.newest.valid;
    const double fps = slot.have ? slot.newest.nominal_fps : cameras_[i].fps;
    const double allowed_ms = params_.safety.max_frame_gap_periods / fps * 1e3;
    char text[192] = {};
    ReasonCode code = ReasonCode::clear;
    const double newest_age_ms =
        slot.have ? static_cast<double>(now_ns - slot.newest.capture_ns + offset_ns) / kNsPerMs : 0.0;
    const double valid_age_ms =
        slot.have_valid ? static_cast<double>(now_ns - slot.newest_valid_capture_ns + offset_ns) / kNsPerMs : 0.0;
    if (!slot.have) {
      code = ReasonCode::camera_stale;
      std::snprintf(text, sizeof text, "camera '%s': no measurement yet", status.name.c_str());
    } else if (newest_age_ms > allowed_ms) {
      // Silent: whatever it said last is no longer news.
      code = ReasonCode::camera_stale;
      std::snprintf(text, sizeof text, "camera '%s': no measurement for %.0f ms (max_frame_gap_periods %g at %g frames/s)",
                    status.name.c_str(), newest_age_ms, params_.safety.max_frame_gap_periods, fps);
    } else if (!slot.newest.valid) {
      // Its own stop, at once and with its own code (the camera knows why better than a
      // timeout); a restarted camera is stale until its new session's first valid measurement.
      const char* why = slot.newest.reason.empty() ? reason_code_name(slot.newest.reason_code) : slot.newest.reason.c_str();
      if (slot.restarted) {
        code = ReasonCode::camera_stale;
        std::snprintf(text, sizeof text, "camera '%s': restarted (session %08x after %08x), no valid measurement yet: %s",
                      status.name.c_str(), slot.newest.session, slot.previous_session, why);
      } else {
        code = slot.newest.reason_code;
        std::snprintf(text, sizeof text, "camera '%s': %s", status.name.c_str(), why);
      }
    } else if (!slot.have_valid || valid_age_ms > allowed_ms) {
      code = ReasonCode::camera_stale;  // not reached: a valid newest is the newest valid
      std::snprintf(text, sizeof text, "camera '%s': no valid measurement", status.name.c_str());
    }
    status.reason_code = code;
    if (code == ReasonCode::clear) continue;
    status.valid = false;
    if (first_fault == ReasonCode::clear) first_fault = code;
    if (!out.withheld_reason.empty()) out.withheld_reason.append("; ");
    out.withheld_reason.append(text);
  }

  // Truth (simulated cameras): the nearest over the cameras, as their truths are each over
  // their own pixels.
  for (size_t i = 0; i < cameras_.size(); ++i) {
    const Slot& slot = slots_[i];
    if (!slot.have || !slot.newest.truth) continue;
    const Contact& t = *slot.newest.truth;
    if (!out.truth || (t.valid && (!out.truth->valid || t.distance_m < out.truth->distance_m))) out.truth = t;
    for (const LinkTruth& lt : slot.newest.truth_links) {
      auto it = std::find_if(out.truth_links.begin(), out.truth_links.end(), [&](const LinkTruth& x) { return x.link == lt.link; });
      if (it == out.truth_links.end()) {
        out.truth_links.push_back(lt);
      } else if (lt.distance_m < it->distance_m) {
        *it = lt;
      }
    }
  }
  std::sort(out.truth_links.begin(), out.truth_links.end(), [](const LinkTruth& a, const LinkTruth& b) { return a.link < b.link; });

  if (first_fault != ReasonCode::clear) {
    out.withheld_code = first_fault;
    // The robot state of the newest camera, for the output's joints.
    int64_t newest_capture_ns = 0;
    for (size_t i = 0; i < cameras_.size(); ++i) {
      if (slots_[i].have && slots_[i].newest.capture_ns > newest_capture_ns) {
        newest_capture_ns = slots_[i].newest.capture_ns;
        out.robot_state = slots_[i].newest.robot_state;
      }
    }
    out.seen_free.reset(0);
    return;
  }

  // Every camera's newest is valid and fresh: fuse them.
  out.valid = true;
  size_t oldest = 0;
  double max_gap_ms = 0.0;
  bool all_grids = params_.grid.enabled;
  // The rank of each out.links entry's contact, computed once per camera's link (a link id is
  // below kMaxFusedLinks, so there are at most that many entries).
  std::array<Rank, kMaxFusedLinks> held_rank;
  for (size_t i = 0; i < cameras_.size(); ++i) {
    const CameraMeasurement& m = slots_[i].newest;
    if (m.capture_ns < slots_[oldest].newest.capture_ns) oldest = i;
    const double gap_ms = m.robot_state_age_ms - static_cast<double>(m.robot_state.extrapolated_ns) / kNsPerMs;
    max_gap_ms = std::max(max_gap_ms, gap_ms);
    out.foreground_points += m.foreground_points;
    out.self_filtered_pixels += m.self_filtered_pixels;
    out.invalid_pixels += m.invalid_pixels;
    out.valid_share = std::min(out.valid_share, m.valid_share);
    out.latency_us = std::max(out.latency_us, m.latency_us);
    if (m.seen_free.cells == 0) all_grids = false;
    if (m.contact.valid && (!out.contact.valid || m.contact.distance_m < out.contact.distance_m)) {
      out.contact = m.contact;
      contact_camera_ = static_cast<int>(i);
    }
    for (const LinkContact& link : m.links) {
      const Rank rank = rank_of(params_.safety, m, link);
      auto it = std::find(link_ids_.begin(), link_ids_.end(), link.link);
      if (it == link_ids_.end()) {
        held_rank[out.links.size()] = rank;
        out.links.push_back(link);
        link_ids_.push_back(link.link);
        link_camera_.push_back(static_cast<int>(i));
        continue;
      }
      const size_t k = static_cast<size_t>(it - link_ids_.begin());
      if (rank.stricter_than(held_rank[k])) {
        held_rank[k] = rank;
        out.links[k] = link;
        link_camera_[k] = static_cast<int>(i);
      }
    }
  }
  // Link order, as a single camera's measurement has it.
  for (size_t a = 1; a < out.links.size(); ++a) {
    for (size_t b = a; b > 0 && out.links[b].link < out.links[b - 1].link; --b) {
      std::swap(out.links[b], out.links[b - 1]);
      std::swap(link_ids_[b], link_ids_[b - 1]);
      std::swap(link_camera_[b], link_camera_[b - 1]);
    }
  }

  // T_r counts from the oldest contributing capture (less the clock offset bound); the robot
  // state is that camera's, aged by
  // the largest gap any camera had (robot_state_gap_s reads age − extrapolation).
  const CameraMeasurement& base = slots_[oldest].newest;
  out.seen_ns = base.capture_ns - offset_ns;
  out.robot_state = base.robot_state;
  out.robot_state_age_ms = max_gap_ms + static_cast<double>(base.robot_state.extrapolated_ns) / kNsPerMs;

  if (all_grids) {
    SeenFreeGrid& seen = out.seen_free;
    seen = slots_[0].newest.seen_free;
    for (size_t i = 1; i < cameras_.size(); ++i) unite(seen, slots_[i].newest.seen_free);
    robot_model_at(params_.robot, base.robot_state.q_rad, robot_model_);
    out.unknown_distance_m = unknown_cells_distance_m(params_.grid, seen, robot_model_, distance_scratch_);
  } else {
    // Without every camera's grid: the largest per-ray distance. Space unknown to the cell is
    // unknown to every camera, so its distance is at least each camera's: this never says more
    // than the union would.
    out.seen_free.reset(0);
    for (size_t i = 0; i < cameras_.size(); ++i) {
      const float d = slots_[i].newest.unknown_distance_m;
      if (std::isnan(d)) continue;
      if (std::isnan(out.unknown_distance_m) || d > out.unknown_distance_m) out.unknown_distance_m = d;
    }
  }
}

}  // namespace hrcsense
