// SPDX-License-Identifier: Apache-2.0
// hrcsense — the per-frame processing path: background → foreground → proximity → verdict.

#include "hrcsense/pipeline.hpp"
#include "hrcsense/unknown_space.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

namespace hrcsense {
namespace {

using Clock = std::chrono::steady_clock;

double elapsed_us(Clock::time_point since) {
  return std::chrono::duration<double, std::micro>(Clock::now() - since).count();
}

// Raw zeros ("no data") in the source frame, before any filter.
// Counted in 16-bit blocks, which vectorise 8 pixels to an instruction (a size_t counter
// would widen every comparison to 64 bits: three times slower).
size_t count_invalid(const DepthImage& depth) {
  const uint16_t* raw = depth.pixels.data();
  const size_t n = depth.pixels.size();
  size_t invalid = 0;
  size_t i = 0;
  while (i < n) {
    const size_t block_end = std::min(n, i + 65535);  // a block's count fits 16 bits
    uint16_t block = 0;
    for (; i < block_end; ++i) block += raw[i] == 0 ? 1 : 0;
    invalid += block;
  }
  return invalid;
}

// Sets `verdict` to a stop with `code` and `reason`, reusing the reason's buffer.
void set_stop(Verdict& verdict, ReasonCode code, const char* reason) {
  verdict.state = VerdictState::stop;
  verdict.speed_scale = 0.0F;
  verdict.protective_distance_m = 0.0F;
  verdict.code = code;
  verdict.reason.assign(reason);
}

// Runs `stage` and appends its duration under the static name `name`.
template <typename Stage>
void timed(FrameResult& result, const char* name, Stage&& stage) {
  const Clock::time_point start = Clock::now();
  stage();
  result.timings.push_back({name, elapsed_us(start)});
}

// Resets the per-frame fields of `result`, keeping its buffers.
void begin_result(const Frame& frame, const RobotState& robot_state, FrameResult& result) {
  result.frame = frame.index;
  result.robot_state = robot_state;
  result.host_time_ns = frame.host_time_ns;
  result.robot_state_age_ms =
      robot_state.sample_time_ns > 0
          ? static_cast<double>(std::max<int64_t>(0, frame.host_time_ns - robot_state.sample_time_ns)) * 1e-6
          : 0.0;
  result.timestamp_ns = frame.timestamp_ns;
  result.valid = false;
  result.contact = Contact{};
  result.backend = nullptr;
  result.foreground_points = 0;
  result.self_filtered_pixels = 0;
  result.invalid_pixels = 0;
  result.valid_share = 0.0F;
  result.timings.clear();  // keeps its capacity: one entry per filter block and stage after the first frame
  result.truth.reset();
  if (frame.truth) result.truth = frame.truth->contact;
  result.ssm.reset();
  result.distance_uncertainty_m = std::numeric_limits<float>::quiet_NaN();
  result.robot_speed_towards_mps = std::numeric_limits<float>::quiet_NaN();
  result.unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
}

// v_r: the velocity of the arm's closest point projected on the direction from it to the
// contact (positive: towards the person). 0 for fixed capsules (robot.model points) and for a
// contact on the capsule's axis (no direction: the speed along it is then the full speed).
float robot_speed_towards(const RobotParams& robot, const RobotState& state, const Contact& contact) {
  if (!robot.arm) return 0.0F;
  const Eigen::Vector3d robot_point = contact.closest_robot_base.cast<double>();
  const Eigen::Vector3d velocity =
      point_velocity(*robot.arm, state.q_rad, state.qd_rad_s, contact.robot_link, robot_point, robot.base_frame);
  const Eigen::Vector3d towards = contact.closest_base.cast<double>() - robot_point;
  const double length = towards.norm();
  if (!(length > 1e-9)) return static_cast<float>(velocity.norm());
  return static_cast<float>(velocity.dot(towards) / length);
}

// The focal length of the camera's own image from the filtered one's (decimation divides it).
float source_fx_px(float filtered_fx_px, const FilterChainParams& filters) {
  if (!has_block(filters.order, FilterBlock::decimation)) return filtered_fx_px;
  return filtered_fx_px * static_cast<float>(std::max(1, filters.decimation.magnitude));
}

// How long ago, on average, the scene the temporal filter's output shows was seen: its
// exponential smoothing with weight α on the newest frame lags (1 − α) / α frames.
double temporal_lag_s(const FilterChainParams& filters, double frame_period_s) {
  if (!has_block(filters.order, FilterBlock::temporal)) return 0.0;
  const double alpha = std::clamp(static_cast<double>(filters.temporal.alpha), 0.01, 1.0);
  return (1.0 - alpha) / alpha * frame_period_s;
}

// The stop verdict of a learning frame, with the learner's last restart message if any.
// Formatted into a stack buffer and assigned, so the reason's buffer is reused.
void set_learning(Verdict& verdict, int frames_seen, int frames_total, const std::string& message) {
  char text[96];
  std::snprintf(text, sizeof text, "learning background (%d/%d frames)", frames_seen, frames_total);
  set_stop(verdict, ReasonCode::learning_background, text);
  if (!message.empty()) {
    verdict.reason.append("; restarted: ");
    verdict.reason.append(message);
  }
}

// Adds a frame to the learner and sets the learning verdict. The frame that completes the
// model is a learning frame too, so it stays invalid like the ones before it.
void learn_background(BackgroundLearner& learner, const Frame& frame, const MotionRegion* region,
                      const RobotPixels* robot, Verdict& verdict) {
  const int frames_total = learner.params.frames;
  const bool completed = learner.add(frame, region, robot) == BackgroundLearner::Status::ready;
  set_learning(verdict, completed ? frames_total : learner.frames_seen(), frames_total, learner.message());
}

bool same_size(const BackgroundModel& model, const DepthImage& depth) {
  return model.width == depth.width && model.height == depth.height;
}

// The foreground against the background. Prepares the extractor's per-pixel tables first when
// the background or the camera changed: once per background, a few milliseconds at 848x480.
bool extract_foreground(ForegroundExtractor& extractor, const BackgroundModel& background, const Frame& frame,
                        const Pose& T_base_camera, const RobotPixels* robot, Foreground& out) {
  if (!extractor.prepared_for(frame)) {
    extractor.set_background(background, frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
  }
  return extractor.extract(frame, T_base_camera, out, robot);
}

// The depth filters, one timing per block named after it; the source frame itself when the
// chain is empty (no copy).
const Frame& run_filters(FilterChain& chain, const Frame& frame, Frame& filtered, FrameResult& result) {
  if (chain.params.order.empty()) return frame;
  chain.start(frame, filtered);
  for (size_t i = 0; i < chain.block_count(); ++i) {
    timed(result, filter_block_name(chain.block(i)), [&] { chain.run_block(i, filtered); });
  }
  return filtered;
}

// Latency from the frame entering processing to its result.
void finish(FrameResult& result, Clock::time_point start) { result.latency_us = elapsed_us(start); }

void finish_stop(FrameResult& result, ReasonCode code, const char* reason, Clock::time_point start) {
  set_stop(result.verdict, code, reason);
  finish(result, start);
}

// The configured backend; config validates the name first, so a bad one here is a caller's bug.
ProximitySearch make_proximity_search(const PipelineParams& params) {
  const std::optional<ProximityBackend> backend = parse_proximity_backend(params.backend);
  if (!backend) throw std::invalid_argument("proximity.backend '" + params.backend + "' is not a backend");
  return ProximitySearch(*backend, params.proximity);
}

}  // namespace

Pipeline::Pipeline(PipelineParams params)
    : params_(std::move(params)), proximity_(make_proximity_search(params_)) {
  learner_.params = params_.background;
  extractor_.params = params_.foreground;
  filters_.params = params_.filters;
  self_filter_.params = params_.self_filter;
}

LiveTuning tuning_of(const PipelineParams& params) { return LiveTuning{params.filters, params.foreground, params.backend}; }

LiveTuning Pipeline::tuning() const { return tuning_of(params_); }

void Pipeline::retune(const LiveTuning& tuning) {
  if (tuning.filters.order != params_.filters.order) {
    throw std::invalid_argument("filters.order cannot change while the cell runs (the background is learnt after it)");
  }
  if (has_block(params_.filters.order, FilterBlock::decimation) &&
      tuning.filters.decimation.magnitude != params_.filters.decimation.magnitude) {
    throw std::invalid_argument("filters.decimation.magnitude cannot change while the cell runs (it sets the "
                                "background's resolution)");
  }
  PipelineParams next = params_;
  next.filters = tuning.filters;
  next.foreground = tuning.foreground;
  next.backend = tuning.backend;
  ProximitySearch search = make_proximity_search(next);  // throws for a bad name, nothing changed yet
  params_ = std::move(next);
  proximity_ = std::move(search);
  filters_.params = params_.filters;
  extractor_.params = params_.foreground;  // prepared_for() sees the change and re-prepares
  check_.k_sigma = params_.foreground.k_sigma;
  check_.min_margin_m = params_.foreground.min_margin_m;
}

void Pipeline::relearn_background() {
  moved_reference_ready_ = false;
  learner_ = BackgroundLearner{};
  learner_.params = params_.background;
  preset_background_ = false;
  preset_model_ = BackgroundModel{};
  check_ = BackgroundCheck{};
  extractor_.clear_background();
  filters_.reset();  // the temporal filter's history holds the scene as it was
}

std::optional<RobotPixels> Pipeline::render_robot(const Frame& frame, FrameResult& result) {
  if (!params_.robot.arm) return std::nullopt;
  timed(result, "self_filter", [&] {
    self_filter_.add_pose(robot_);
    self_filter_.render(frame, params_.T_base_camera, params_.foreground);
  });
  return self_filter_.robot_pixels();
}

void Pipeline::set_background(BackgroundModel model, std::string origin) {
  preset_model_ = std::move(model);
  preset_origin_ = std::move(origin);
  preset_background_ = true;
  check_ = BackgroundCheck{};
  check_.frames = params_.background.check_frames;
  check_.max_farther_share = params_.background.check_max_farther_share;
  check_.k_sigma = params_.foreground.k_sigma;
  check_.min_margin_m = params_.foreground.min_margin_m;
  check_.min_valid_ratio = params_.background.min_valid_ratio;
  extractor_.clear_background();  // its tables belong to the previous model
  moved_reference_ready_ = false;
}

double Pipeline::unknown_background_share() const {
  if (!background_ready()) return -1.0;
  const std::vector<float>& mean_m = background().mean_m;
  if (mean_m.empty()) return -1.0;
  const auto unknown = std::count_if(mean_m.begin(), mean_m.end(), [](float m) { return !(m > 0.0F); });
  return static_cast<double>(unknown) / static_cast<double>(mean_m.size());
}

const BackgroundModel& Pipeline::background() const {
  return preset_background_ ? preset_model_ : learner_.model();
}

// One line per stage; every early return leaves a stop verdict with its reason.
void Pipeline::process(const Frame& source_frame, const RobotState& robot_state, FrameResult& result) {
  const Clock::time_point start = Clock::now();
  begin_result(source_frame, robot_state, result);
  result.invalid_pixels = count_invalid(source_frame.depth);
  if (result.invalid_pixels == source_frame.depth.pixels.size()) {
    return finish_stop(result, ReasonCode::no_valid_depth, "no valid depth", start);
  }
  const Frame& frame = run_filters(filters_, source_frame, filtered_, result);
  count_no_depth_frames(frame.depth, no_depth_frames_);  // for unknown space; every filtered frame counts
  if (!enough_valid_depth(frame, result)) return finish(result, start);
  if (!background_ready()) {
    // Motion counts near the robot where it is now, and the robot's own pixels are no samples;
    // without a usable state, motion counts everywhere.
    const bool placed = robot_state.valid && all_finite(robot_state.q_rad);
    std::optional<RobotPixels> robot_pixels;
    if (placed) {
      robot_model_at(params_.robot, robot_state.q_rad, robot_);
      robot_pixels = render_robot(frame, result);
    } else {
      self_filter_.clear_poses();
    }
    timed(result, "background", [&] {
      const MotionRegion region{params_.T_base_camera, placed ? &robot_ : nullptr, params_.foreground.workspace_base};
      learn_background(learner_, frame, &region, robot_pixels ? &*robot_pixels : nullptr, result.verdict);
    });
    return finish(result, start);
  }
  if (!same_size(background(), frame.depth)) {
    return finish_stop(result, ReasonCode::background_mismatch, "background size mismatch", start);
  }
  if (!background_checked(frame, result)) return finish(result, start);
  if (!camera_sees_the_cell(frame, result)) return finish(result, start);
  if (!robot_state.valid || !all_finite(robot_state.q_rad)) self_filter_.clear_poses();  // its poses are history
  if (!robot_state.valid) {
    // A state with a sample time had samples that are now too old; one without never had any.
    if (robot_state.sample_time_ns > 0) {
      char text[64];
      std::snprintf(text, sizeof text, "robot state stale (%.1f ms old)", result.robot_state_age_ms);
      return finish_stop(result, ReasonCode::robot_state_stale, text, start);
    }
    return finish_stop(result, ReasonCode::no_robot_state, "no robot state", start);
  }
  if (!all_finite(robot_state.q_rad)) {
    return finish_stop(result, ReasonCode::non_finite_input, "non-finite joint angle in the robot state", start);
  }
  robot_model_at(params_.robot, robot_state.q_rad, robot_);
  if (robot_.capsules.empty()) return finish_stop(result, ReasonCode::no_robot_model, "no robot model", start);
  const std::optional<RobotPixels> robot_pixels = render_robot(frame, result);
  const RobotPixels* self_filter = params_.self_filter.enabled && robot_pixels ? &*robot_pixels : nullptr;
  if (robot_pixels) {
    // A person next to the arm may hide in depth the camera cannot measure there.
    const EnvelopeCount envelope = envelope_invalid(frame.depth, background(), &*robot_pixels);
    if (envelope.share() > params_.checks.max_envelope_invalid_share) {
      char text[96];
      std::snprintf(text, sizeof text, "%.0f %% of the robot's envelope without depth (max_envelope_invalid_share %.2f)",
                    100.0 * envelope.share(), static_cast<double>(params_.checks.max_envelope_invalid_share));
      return finish_stop(result, ReasonCode::envelope_invalid, text, start);
    }
  }
  bool extracted = false;
  timed(result, "foreground", [&] {
    extracted = extract_foreground(extractor_, background(), frame, params_.T_base_camera, self_filter, foreground_);
  });
  result.self_filtered_pixels = foreground_.self_filtered_pixels;
  if (!extracted) {
    return finish_stop(result, ReasonCode::foreground_failed, "foreground extraction failed", start);
  }
  timed(result, "proximity", [&] {
    result.contact = proximity_.closest(foreground_.points_base, foreground_.points_camera, robot_);
    result.backend = proximity_backend_name(proximity_.last_backend());
  });
  result.foreground_points = foreground_.points_base.size();
  timed(result, "unknown_space", [&] {
    const UnknownSpace unknown = unknown_space(frame.depth, frame.intrinsics, background(), foreground_.mask,
                                               robot_pixels ? &*robot_pixels : nullptr, params_.T_base_camera, robot_,
                                               frame.stereo_baseline_mm * 1e-3F, no_depth_frames_);
    result.unknown_distance_m = unknown.distance_m;
  });
  timed(result, "safety", [&] {
    measure_contact(frame, robot_state, result);
    const Decision decision =
        decide_verdict(params_.safety, verdict_input(result, static_cast<double>(elapsed_us(start)) * 1e-6));
    result.verdict = decision.verdict;
    result.ssm = decision.ssm;
  });
  result.valid = true;
  finish(result, start);
}

void Pipeline::measure_contact(const Frame& frame, const RobotState& robot_state, FrameResult& result) {
  const Contact& contact = result.contact;
  // The period between frames, for the filter's lag; the nominal 30 frames/s until two frames
  // were seen, and never more than a second (a pause in a replay).
  double period_s = 1.0 / 30.0;
  if (have_previous_frame_ && frame.timestamp_ns > previous_timestamp_ns_) {
    period_s = std::min(1.0, static_cast<double>(frame.timestamp_ns - previous_timestamp_ns_) * 1e-9);
  }
  have_previous_frame_ = true;
  previous_timestamp_ns_ = frame.timestamp_ns;
  if (!contact.valid || contact.inside || !contact.closest_base.allFinite()) {
    have_previous_contact_ = false;
    return;
  }
  result.robot_speed_towards_mps = robot_speed_towards(params_.robot, robot_state, contact);
  ContactUncertaintyInput in;
  in.depth_m = contact.closest_camera.z();
  in.fx_px = frame.intrinsics.fx;
  const float baseline_m = frame.stereo_baseline_mm * 1e-3F;
  const double learnt = preset_background_ ? 0.0 : learner_.noise_per_z2();
  // The stereo noise is in the camera's own pixels: the source's focal length, not the
  // decimated one (decimation and the spatial filter only lower it).
  const float source_fx = source_fx_px(frame.intrinsics.fx, params_.filters);
  in.noise_per_z2 = baseline_m > 0.0F && source_fx > 0.0F
                        ? params_.foreground.subpixel_rms_px / (source_fx * baseline_m)
                        : static_cast<float>(learnt > 0.0 ? learnt : params_.background.max_noise_per_z2);
  in.filter_lag_s = temporal_lag_s(params_.filters, period_s);
  // The filters lag in depth only, so the contact's speed along the camera's axis counts,
  // from the last frame's contact; the contact may jump to another body part, which
  // overstates it, and the cap at the human speed bounds that.
  if (have_previous_contact_ && frame.timestamp_ns > previous_contact_ns_) {
    const double dt_s = static_cast<double>(frame.timestamp_ns - previous_contact_ns_) * 1e-9;
    in.contact_speed_mps = static_cast<float>(std::abs(contact.closest_camera.z() - previous_contact_depth_m_) / dt_s);
  }
  have_previous_contact_ = true;
  previous_contact_ns_ = frame.timestamp_ns;
  previous_contact_depth_m_ = contact.closest_camera.z();
  result.distance_uncertainty_m = contact_uncertainty_m(params_.safety.ssm, in);
}

// A large surface right in front of the lens, or the static scene seen farther than it was
// learnt at the sparse reference pixels (the camera was knocked or moved): the background no
// longer describes what the camera sees, so nothing it says can be trusted.
bool Pipeline::camera_sees_the_cell(const Frame& frame, FrameResult& result) {
  const CellCheckParams& checks = params_.checks;
  const float blocked = blocked_share(checks, frame.depth, background());
  if (blocked >= checks.blocked_share) {
    char text[96];
    std::snprintf(text, sizeof text, "%.0f %% of the image nearer than %.2f m: camera blocked", 100.0 * blocked,
                  static_cast<double>(checks.blocked_depth_m));
    set_stop(result.verdict, ReasonCode::camera_blocked, text);
    return false;
  }
  if (!moved_reference_ready_) {
    moved_reference_ = moved_reference_pixels(checks, background());
    moved_reference_ready_ = true;
  }
  const MovedCount moved = moved_count(checks, frame.depth, background(), moved_reference_);
  if (moved.valid >= checks.moved_min_valid && moved.share() >= checks.moved_share) {
    char text[112];
    std::snprintf(text, sizeof text, "%.0f %% of %zu reference pixels farther than the background: camera moved",
                  100.0 * moved.share(), moved.valid);
    set_stop(result.verdict, ReasonCode::camera_moved, text);
    return false;
  }
  return true;
}

// The filtered frame must still see the cell: no valid pixel at all, or fewer than
// safety.min_valid_share of them (a covered or blinded camera, a threshold that cuts the
// scene away), is a stop, and such a frame is not learnt from either.
bool Pipeline::enough_valid_depth(const Frame& frame, FrameResult& result) const {
  const size_t pixels = frame.depth.pixels.size();
  const size_t invalid = &frame.depth == &filtered_.depth ? count_invalid(frame.depth) : result.invalid_pixels;
  const size_t valid = pixels - invalid;
  if (valid == 0) {
    set_stop(result.verdict, ReasonCode::no_valid_depth, "no valid depth after filters");
    return false;
  }
  const double share = static_cast<double>(valid) / static_cast<double>(pixels);
  result.valid_share = static_cast<float>(share);
  if (share >= params_.safety.min_valid_share) return true;
  char text[96];
  std::snprintf(text, sizeof text, "valid depth %.4f of pixels after filters, below min_valid_share %.4g", share,
                static_cast<double>(params_.safety.min_valid_share));
  set_stop(result.verdict, ReasonCode::low_valid_share, text);
  return false;
}

// A background loaded from a file is compared with the first frames before it is trusted
// (BackgroundCheck); those frames are stops. A mismatch ends the run with an error.
bool Pipeline::background_checked(const Frame& frame, FrameResult& result) {
  if (!preset_background_ || check_.done()) return true;
  const int seen = check_.add(preset_model_, frame.depth);
  if (check_.done() && check_.mismatch()) {
    char text[256];
    std::snprintf(text, sizeof text,
                  ": does not match the scene: %.1f %% of its reliable pixels are measured farther than it in "
                  "the first %d frames (at most %.1f %% allowed); the camera moved or the file is another "
                  "cell's: delete it to learn a new one",
                  100.0 * check_.farther_share(), seen, 100.0 * static_cast<double>(check_.max_farther_share));
    throw BackgroundMismatch(preset_origin_ + text);
  }
  char text[64];
  std::snprintf(text, sizeof text, "checking loaded background (%d/%d frames)", seen, check_.frames);
  set_stop(result.verdict, ReasonCode::checking_background, text);
  return false;
}

}  // namespace hrcsense
