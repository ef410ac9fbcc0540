// SPDX-License-Identifier: Apache-2.0
// hrcsense — the per-frame processing path: filters → background and camera checks → robot
// state → self-filter → foreground → proximity → unknown space → per-link v_i and Z_d, into a
// Measurement; the verdict is decided later, by the output thread's SafetyMonitor.

#include "hrcsense/pipeline.hpp"
#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/unknown_space.hpp"

#include "pipeline_detail.hpp"

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

using pipeline_detail::withhold;
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

// Runs `stage` and appends its duration under the static name `name`.
template <typename Stage>
void timed(Measurement& m, const char* name, Stage&& stage) {
  const Clock::time_point start = Clock::now();
  stage();
  m.timings.push_back({name, elapsed_us(start)});
}

// Resets the per-frame fields of `m`, keeping its buffers.
void begin_measurement(const Frame& frame, const RobotState& robot_state, Measurement& m) {
  m.frame = frame.index;
  m.source_frame = true;
  m.clocked = false;  // run_pipeline sets the run-clock times after processing
  m.robot_state = robot_state;
  m.host_time_ns = frame.host_time_ns;
  m.robot_state_age_ms =
      robot_state.sample_time_ns > 0
          ? static_cast<double>(std::max<int64_t>(0, frame.host_time_ns - robot_state.sample_time_ns)) * 1e-6
          : 0.0;
  m.timestamp_ns = frame.timestamp_ns;
  m.valid = false;
  m.withheld_code = ReasonCode::no_valid_depth;
  m.withheld_reason.clear();
  m.contact = Contact{};
  m.links.clear();  // keeps its capacity: one entry per link after the first frames
  m.backend = nullptr;
  m.foreground_points = 0;
  m.self_filtered_pixels = 0;
  m.invalid_pixels = 0;
  m.valid_share = 0.0F;
  m.timings.clear();  // keeps its capacity: one entry per filter block and stage after the first frame
  m.truth.reset();
  m.truth_links.clear();
  if (frame.truth) {
    m.truth = frame.truth->contact;
    m.truth_links.assign(frame.truth->links.begin(), frame.truth->links.end());
  }
  m.unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
}

// v_i: the velocity of a link's closest point projected on the direction from it to its
// contact (positive: towards the person). 0 for fixed capsules (robot.model points); for a
// contact on the capsule's axis (no direction) the full speed.
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

// The withheld measurement of a learning frame, with the learner's last restart message if any.
// Formatted into a stack buffer and assigned, so the reason's buffer is reused.
void set_learning(Measurement& m, int frames_seen, int frames_total, const std::string& message) {
  char text[96];
  std::snprintf(text, sizeof text, "learning background (%d/%d frames)", frames_seen, frames_total);
  withhold(m, ReasonCode::learning_background, text);
  if (!message.empty()) {
    m.withheld_reason.append("; restarted: ");
    m.withheld_reason.append(message);
  }
}

// Adds a frame to the learner and withholds the frame. The frame that completes the model is
// a learning frame too, so it stays withheld like the ones before it.
void learn_background(BackgroundLearner& learner, const Frame& frame, const MotionRegion* region,
                      const RobotPixels* robot, Measurement& m) {
  const int frames_total = learner.params.frames;
  const bool completed = learner.add(frame, region, robot) == BackgroundLearner::Status::ready;
  set_learning(m, completed ? frames_total : learner.frames_seen(), frames_total, learner.message());
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
const Frame& run_filters(FilterChain& chain, const Frame& frame, Frame& filtered, Measurement& m) {
  if (chain.params.order.empty()) return frame;
  chain.start(frame, filtered);
  for (size_t i = 0; i < chain.block_count(); ++i) {
    timed(m, filter_block_name(chain.block(i)), [&] { chain.run_block(i, filtered); });
  }
  return filtered;
}

ProximitySearch make_proximity_search(const PipelineParams& params) {
  return ProximitySearch(params.backend, params.proximity);
}

}  // namespace

Pipeline::Pipeline(PipelineParams params)
    : params_(std::move(params)), proximity_(make_proximity_search(params_)) {
  learner_.params = params_.background;
  learner_.min_object_mm = params_.foreground.min_object_mm;  // motion is what the foreground would keep
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
  ProximitySearch search = make_proximity_search(next);
  params_ = std::move(next);
  proximity_ = std::move(search);
  filters_.params = params_.filters;
  extractor_.params = params_.foreground;  // prepared_for() sees the change and re-prepares
  learner_.min_object_mm = params_.foreground.min_object_mm;
  check_.k_sigma = params_.foreground.k_sigma;
  check_.min_margin_m = params_.foreground.min_margin_m;
}

void Pipeline::relearn_background() {
  ++background_changes_;
  moved_reference_ready_ = false;
  not_empty_ = false;  // the reference stays: the new background is compared with it too
  learner_ = BackgroundLearner{};
  learner_.params = params_.background;
  learner_.min_object_mm = params_.foreground.min_object_mm;
  preset_background_ = false;
  preset_model_ = BackgroundModel{};
  check_ = BackgroundCheck{};
  extractor_.clear_background();
  filters_.reset();  // the temporal filter's history holds the scene as it was
}

std::optional<RobotPixels> Pipeline::render_robot(const Frame& frame, Measurement& m) {
  if (!params_.robot.arm) return std::nullopt;
  timed(m, "self_filter", [&] {
    self_filter_.add_pose(robot_);
    self_filter_.render(frame, params_.T_base_camera, params_.foreground);
  });
  return self_filter_.robot_pixels();
}

void Pipeline::set_background(BackgroundModel model, std::string origin) {
  ++background_changes_;
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

// One call per stage; a stage that cannot go on withholds the measurement with its reason, and
// the stages after it do not run.
void Pipeline::process(const Frame& source_frame, const RobotState& robot_state, Measurement& m) {
  const Clock::time_point start = Clock::now();
  begin_measurement(source_frame, robot_state, m);
  m.seen_free.reset(params_.seen_free_grid.cell_count());  // every cube unknown until marked; 0 cubes when disabled
  const Frame* frame = filter(source_frame, m);
  if (frame != nullptr && !background_ready()) {
    learn(*frame, robot_state, m);
    camera_pose_agrees(source_frame, robot_state, m);  // a wrong pose is the learning frame's reason too
  } else if (frame != nullptr && camera_pose_agrees(source_frame, robot_state, m) && background_usable(*frame, m) &&
             robot_placed(robot_state, m)) {
    const std::optional<RobotPixels> robot_pixels = render_robot(*frame, m);
    const RobotPixels* pixels = robot_pixels ? &*robot_pixels : nullptr;
    if (envelope_seen(*frame, pixels, m) && extract(*frame, pixels, m)) {
      timed(m, "proximity", [&] { search_links(m); });
      timed(m, "unknown_space", [&] { find_unknown_space(*frame, pixels, m); });
      if (params_.seen_free_grid.enabled) timed(m, "seen_free_grid", [&] { mark_seen_free_grid(*frame, pixels, m); });
      timed(m, "safety", [&] { measure_links(*frame, robot_state, m); });
      m.valid = true;
    }
  }
  m.latency_us = elapsed_us(start);
}

const Frame* Pipeline::filter(const Frame& source_frame, Measurement& m) {
  m.invalid_pixels = count_invalid(source_frame.depth);
  if (m.invalid_pixels == source_frame.depth.pixels.size()) {
    withhold(m, ReasonCode::no_valid_depth, "no valid depth");
    return nullptr;
  }
  const Frame& frame = run_filters(filters_, source_frame, filtered_, m);
  count_no_depth_frames(frame.depth, no_depth_frames_);  // for unknown space; every filtered frame counts
  return enough_valid_depth(frame, m) ? &frame : nullptr;
}

// Motion counts near the robot where it is now, and the robot's own pixels are no samples;
// without a usable state, motion counts everywhere.
// With a reference, the batch that completes is compared with it at once (in the same timing),
// and refused when someone stands in it.
void Pipeline::learn(const Frame& frame, const RobotState& robot_state, Measurement& m) {
  ++background_changes_;
  const bool placed = robot_state.valid && all_finite(robot_state.q_rad);
  if (learner_.frames_seen() == 0) {  // this frame starts a batch
    learning_poses_.capsules.clear();
    last_pose_begin_ = 0;
  }
  std::optional<RobotPixels> robot_pixels;
  if (placed) {
    robot_model_at(params_.robot, robot_state.q_rad, robot_);
    robot_pixels = render_robot(frame, m);
    if (has_reference()) remember_learning_pose();
  } else {
    self_filter_.clear_poses();
  }
  const RobotPixels* pixels = robot_pixels ? &*robot_pixels : nullptr;
  timed(m, "background", [&] {
    const MotionRegion region{params_.T_base_camera, placed ? &robot_ : nullptr, params_.foreground.workspace_base};
    learn_background(learner_, frame, &region, pixels, m);
    if (learner_.ready() && has_reference()) check_reference(frame, pixels);
  });
  if (not_empty_) withhold_not_empty(m);
}

void Pipeline::remember_learning_pose() {
  const std::vector<Capsule>& now = robot_.capsules;
  std::vector<Capsule>& poses = learning_poses_.capsules;
  const size_t last_size = poses.size() - last_pose_begin_;
  const bool same = !poses.empty() && last_size == now.size() &&
                    std::equal(now.begin(), now.end(), poses.begin() + static_cast<std::ptrdiff_t>(last_pose_begin_),
                               [](const Capsule& a, const Capsule& b) {
                                 return a.a == b.a && a.b == b.b && a.radius_m == b.radius_m;
                               });
  if (same) return;
  last_pose_begin_ = poses.size();
  poses.insert(poses.end(), now.begin(), now.end());  // grows in the first batches only
}

bool Pipeline::extract(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m) {
  const RobotPixels* self_filter = params_.self_filter.enabled ? robot_pixels : nullptr;
  bool extracted = false;
  timed(m, "foreground", [&] {
    extracted = extract_foreground(extractor_, background(), frame, params_.T_base_camera, self_filter, foreground_);
  });
  m.self_filtered_pixels = foreground_.self_filtered_pixels;
  m.foreground_points = foreground_.points_base.size();
  if (!extracted) withhold(m, ReasonCode::foreground_failed, "foreground extraction failed");
  return extracted;
}

// Per link, the closest pair of the foreground and that link's capsules (each backend is
// exact on any set of capsules); the overall pair is the closest of them, the lower link on a
// tie.
void Pipeline::search_links(Measurement& m) {
  split_by_link(robot_, link_models_);
  for (const RobotModel& link_model : link_models_) {
    const Contact contact = proximity_.closest(foreground_.points_base, foreground_.points_camera, link_model);
    m.backend = proximity_backend_name(proximity_.last_backend());
    if (!contact.valid) continue;
    LinkContact link;
    link.link = link_model.capsules.front().link;
    link.contact = contact;
    m.links.push_back(link);
    // NaN distances never win, so a non-finite contact cannot hide a finite one.
    if (!m.contact.valid || contact.distance_m < m.contact.distance_m) m.contact = contact;
  }
}

void Pipeline::find_unknown_space(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m) {
  const UnknownSpaceParams params;
  if (reliable_prepared_at_ != background_changes_) {  // once per background, in this stage's timing
    reliable_ = reliable_background(background(), params.min_valid_ratio);
    reliable_prepared_at_ = background_changes_;
  }
  const UnknownSpace unknown = unknown_space(frame.depth, frame.intrinsics, background(), reliable_, foreground_.mask,
                                             robot_pixels, params_.T_base_camera, robot_,
                                             frame.stereo_baseline_mm * 1e-3F, no_depth_frames_, params);
  m.unknown_distance_m = unknown.distance_m;
}

// The cubes this camera sees free (docs/SAFETY.md, "Unknown space with several cameras"), with
// unknown space's inputs; the projection is prepared again only when the pose, the image or
// the grid changed (its first frame, a live retune).
void Pipeline::mark_seen_free_grid(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m) {
  const UnknownSpaceParams params;
  if (!seen_free_projection_.matches(params_.seen_free_grid, frame.intrinsics, params_.T_base_camera, params.near_m)) {
    seen_free_projection_ = prepare_seen_free(params_.seen_free_grid, frame.intrinsics, params_.T_base_camera,
                                              params.near_m);
  }
  mark_seen_free(seen_free_projection_, frame.depth, background(), reliable_, foreground_.mask, robot_pixels,
                 frame.stereo_baseline_mm * 1e-3F, no_depth_frames_, params, m.seen_free);
}

// Per link: v_i of its closest point towards its contact and Z_d of that contact.
void Pipeline::measure_links(const Frame& frame, const RobotState& robot_state, Measurement& m) {
  // The period between frames, for the filter's lag; the nominal 30 frames/s until two frames
  // were seen, and never more than a second (a pause in a replay).
  double period_s = 1.0 / 30.0;
  if (have_previous_frame_ && frame.timestamp_ns > previous_timestamp_ns_) {
    period_s = std::min(1.0, static_cast<double>(frame.timestamp_ns - previous_timestamp_ns_) * 1e-9);
  }
  have_previous_frame_ = true;
  previous_timestamp_ns_ = frame.timestamp_ns;
  ContactUncertaintyInput in;
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
  for (LinkContact& link : m.links) {
    const Contact& contact = link.contact;
    if (contact.inside || !contact.closest_base.allFinite()) continue;  // a stop either way
    link.speed_towards_mps = robot_speed_towards(params_.robot, robot_state, contact);
    in.depth_m = contact.closest_camera.z();
    // The filters lag in depth only, so the contact's speed along the camera's axis counts,
    // from this link's contact in the last frame; the contact may jump to another body part,
    // which overstates it, and the cap at the human speed bounds that.
    in.contact_speed_mps = std::numeric_limits<float>::quiet_NaN();
    PreviousContact& previous = previous_link_contact(link.link);
    if (previous.seen && frame.timestamp_ns > previous.timestamp_ns) {
      const double dt_s = static_cast<double>(frame.timestamp_ns - previous.timestamp_ns) * 1e-9;
      in.contact_speed_mps = static_cast<float>(std::abs(contact.closest_camera.z() - previous.depth_m) / dt_s);
    }
    link.distance_uncertainty_m = contact_uncertainty_m(params_.safety.ssm, in);
    previous = {true, frame.timestamp_ns, contact.closest_camera.z()};
  }
  // A link without a contact this frame starts again: its next contact has no speed.
  for (PreviousContact& previous : previous_contacts_) previous.seen = previous.seen && previous.timestamp_ns == frame.timestamp_ns;
}

Pipeline::PreviousContact& Pipeline::previous_link_contact(int link) {
  const size_t i = static_cast<size_t>(std::max(0, link));
  if (i >= previous_contacts_.size()) previous_contacts_.resize(i + 1);  // grows during the first frames only
  return previous_contacts_[i];
}

// The filtered frame must still see the cell: no valid pixel at all, or fewer than
// safety.min_valid_share of them (a covered or blinded camera, a threshold that cuts the
// scene away), is a stop, and such a frame is not learnt from either.
bool Pipeline::enough_valid_depth(const Frame& frame, Measurement& m) const {
  const size_t pixels = frame.depth.pixels.size();
  const size_t invalid = &frame.depth == &filtered_.depth ? count_invalid(frame.depth) : m.invalid_pixels;
  const size_t valid = pixels - invalid;
  if (valid == 0) {
    withhold(m, ReasonCode::no_valid_depth, "no valid depth after filters");
    return false;
  }
  const double share = static_cast<double>(valid) / static_cast<double>(pixels);
  m.valid_share = static_cast<float>(share);
  if (share >= params_.safety.min_valid_share) return true;
  char text[96];
  std::snprintf(text, sizeof text, "valid depth %.4f of pixels after filters, below min_valid_share %.4g", share,
                static_cast<double>(params_.safety.min_valid_share));
  withhold(m, ReasonCode::low_valid_share, text);
  return false;
}

}  // namespace hrcsense
