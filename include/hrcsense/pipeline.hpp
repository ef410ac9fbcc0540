// SPDX-License-Identifier: Apache-2.0
// hrcsense — the per-frame processing path and the threads around it (run_pipeline). The
// interfaces it joins are in source.hpp, sink.hpp, robot_state.hpp and clock.hpp, its
// mailboxes in mailbox.hpp.
#pragma once

#include "hrcsense/cell_checks.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/filters.hpp"
#include "hrcsense/mailbox.hpp"
#include "hrcsense/pipeline_params.hpp"
#include "hrcsense/proximity.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/safety.hpp"
#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/segmentation.hpp"
#include "hrcsense/self_filter.hpp"
#include "hrcsense/sink.hpp"
#include "hrcsense/source.hpp"
#include "hrcsense/types.hpp"
#include "hrcsense/unknown_space.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

namespace hrcsense {

/// A background loaded from a file contradicts the live scene (Pipeline::set_background).
class BackgroundMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The per-frame processing path: depth filters → background (and the camera checks) → robot
/// capsules → self-filter → foreground → per-link proximity → unknown space → per-link v_i and
/// Z_d: a measurement, no verdict (a SafetyMonitor decides it). Runs on the caller's thread
/// (run_pipeline gives it a thread of its own; the brute-force search may use a second one,
/// `proximity.threads`). Owns the stages' state and scratch buffers.
class Pipeline {
 public:
  explicit Pipeline(PipelineParams params);
  /// The parameters the pipeline was built with (e.g. safety.max_frame_age_s for the watchdog).
  const PipelineParams& params() const { return params_; }
  /// Uses a background learnt earlier instead of learning from the first frames. The first
  /// BackgroundCheck::frames frames are compared with it first (stops); when they contradict
  /// it, process() throws BackgroundMismatch, naming `origin` (e.g. the file it came from).
  void set_background(BackgroundModel model, std::string origin = "the loaded background");
  /// `background.reference`: every background learnt from now on is compared with `reference`
  /// (taught with the cell empty, of the filtered frames' size) when its batch completes
  /// (ReferenceCheck). A batch that holds a blob of at least safety.ssm.detection_mm nearer than
  /// the reference within reference_distance_m() of the robot is refused and learning goes on;
  /// until a batch is accepted, every frame is withheld with `background_not_empty`, naming the
  /// blob. `origin` names the reference in those reasons (e.g. its file). Not for a background
  /// given to set_background(), which is not learnt.
  void set_reference(BackgroundModel reference, std::string origin = "the reference background");
  bool has_reference() const { return reference_check_.has_reference(); }
  /// How near the robot a blob in the learnt background refuses it: S_p at rest in `ssm` mode
  /// (a person at walking speed, frame age 0 so T_r is the controller's latency, Z_d 0: the
  /// protective_distance_m of a frame without foreground), safety.slow_distance_m in `zones`.
  float reference_distance_m() const;
  /// What the last comparison with the reference found (nothing before one).
  const ReferenceFinding& reference_finding() const { return reference_finding_; }
  bool background_ready() const { return learner_.ready() || preset_background_; }
  const BackgroundModel& background() const;
  /// Measures one frame into `m`, reusing its buffers: validity (or why it is withheld), per
  /// robot link the closest foreground point with its distance, the link point's speed towards
  /// it and Z_d, the overall closest pair, unknown space, counts and timings. It decides
  /// nothing: a SafetyMonitor turns `m` into the verdict. The robot's capsules are built from
  /// `robot_state` (the arm's joints at the frame's time; ignored by robot.model points, but an
  /// invalid state withholds the frame for every model), without allocating once sized.
  void process(const Frame& frame, const RobotState& robot_state, Measurement& m);
  /// The tunable part of params() (LiveTuning).
  LiveTuning tuning() const;
  /// Takes `tuning` from the next frame on (call it between frames, on the processing thread).
  /// Throws std::invalid_argument, naming the field, when it changes the filter order or the
  /// decimation; the pipeline is then unchanged.
  void retune(const LiveTuning& tuning);
  /// Forgets the background (learnt or loaded) and learns a new one from the next frames,
  /// which are stops (`learning_background`) until it is ready.
  void relearn_background();
  /// The robot's capsules of the last frame that got as far as the search (base frame).
  const RobotModel& robot() const { return robot_; }
  /// The self-filter with the last frame's rendered robot (empty for robot.model points).
  const SelfFilter& self_filter() const { return self_filter_; }
  const Foreground& foreground() const { return foreground_; }
  /// Share of the background's pixels whose depth is unknown (never measured, or never settled
  /// while learning: BackgroundLearner::unsettled_pixels), 0..1; -1 before a background exists.
  double unknown_background_share() const;
  /// Why the background learning last restarted; empty if it never did.
  const std::string& background_message() const { return learner_.message(); }
  /// Pixels of the learnt background left unknown because they moved far from the robot while
  /// it was learnt (BackgroundLearner::unsettled_pixels); 0 for a loaded background.
  size_t unsettled_background_pixels() const { return preset_background_ ? 0 : learner_.unsettled_pixels(); }

 private:
  PipelineParams params_;
  BackgroundLearner learner_;
  bool preset_background_ = false;
  BackgroundModel preset_model_;
  std::string preset_origin_;  ///< where preset_model_ came from, for the mismatch error
  ForegroundExtractor extractor_;
  Foreground foreground_;
  FilterChain filters_;  ///< params_.filters; its temporal state spans frames
  ProximitySearch proximity_;  ///< params_.backend with its reusable search buffers
  Frame filtered_;       ///< the filtered copy of the current frame (buffers reused)
  RobotModel robot_;     ///< params_.robot at the current frame's robot state (buffer reused)
  SelfFilter self_filter_;  ///< the arm's remembered poses rendered into the filtered frame
  BackgroundCheck check_;  ///< of a loaded background against the first frames
  // background.reference: the check of each learnt batch, the robot's distinct poses while the
  // batch was learnt (their capsules one after another), and whether the last completed batch
  // was refused as not empty (then every learning frame says so, with not_empty_reason_).
  ReferenceCheck reference_check_;
  std::string reference_origin_;
  RobotModel learning_poses_;
  size_t last_pose_begin_ = 0;  ///< where the newest pose starts in learning_poses_
  ReferenceFinding reference_finding_;
  bool not_empty_ = false;
  std::string not_empty_reason_;

  // The previous frame, for the filters' lag, and per link its previous contact, for the
  // contact's speed (Z_d).
  struct PreviousContact {
    bool seen = false;
    int64_t timestamp_ns = 0;
    float depth_m = 0.0F;
  };
  bool have_previous_frame_ = false;
  int64_t previous_timestamp_ns_ = 0;
  std::vector<PreviousContact> previous_contacts_;  ///< by link index
  std::vector<RobotModel> link_models_;  ///< robot_ split by link (buffers reused)

  std::vector<uint8_t> no_depth_frames_;  ///< per filtered pixel: frames in a row without depth
  // The background in use changes with each learning frame, a relearn and set_background();
  // reliable_ is unknown space's view of it, prepared again when the two counts differ.
  int64_t background_changes_ = 0;
  int64_t reliable_prepared_at_ = -1;
  ReliableBackground reliable_;
  SeenFreeProjection seen_free_projection_;  ///< the grid's cubes in this camera (seen_free_grid.enabled)
  std::vector<uint32_t> moved_reference_;  ///< moved_reference_pixels of the background in use
  bool moved_reference_ready_ = false;
  // The camera pose check: its window, the arm's visual shapes at the frame's joints and their
  // camera-frame scratch (buffers reused).
  PoseCheck pose_check_;
  RobotModel visual_;
  std::vector<ShapeInCamera> pose_shapes_;

  // The stages of process(), in its order; each that fails withholds `m` with its reason.
  /// Counts the raw invalid pixels and runs the filters; null when too little depth is left.
  const Frame* filter(const Frame& source_frame, Measurement& m);
  /// A learning frame: adds it to the learner (withheld).
  void learn(const Frame& frame, const RobotState& robot_state, Measurement& m);
  /// Adds robot_ to learning_poses_ unless it is the pose added last (a fixed arm adds one).
  void remember_learning_pose();
  /// A completed batch against the reference: refuses it when someone is in it.
  void check_reference(const Frame& frame, const RobotPixels* robot_pixels);
  /// Withholds a learning frame with `background_not_empty` while the last batch was refused.
  void withhold_not_empty(Measurement& m) const;
  /// The arm's pixels agree with its visual shapes seen from the told pose (or the check has
  /// nothing to say this frame); withholds with camera_pose_mismatch when they do not.
  bool camera_pose_agrees(const Frame& frame, const RobotState& robot_state, Measurement& m);
  /// Withholds `m` with camera_pose_mismatch and the window's disagreement; returns false.
  bool withhold_pose(Measurement& m) const;
  /// The background fits the frame, a loaded one is checked, and the camera sees the cell.
  bool background_usable(const Frame& frame, Measurement& m);
  /// The robot's capsules at a valid, finite state.
  bool robot_placed(const RobotState& robot_state, Measurement& m);
  /// The robot's envelope has depth enough (envelope_invalid).
  bool envelope_seen(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m);
  /// The foreground against the background, less the robot's own pixels.
  bool extract(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m);
  /// Measurement::links and the overall contact.
  void search_links(Measurement& m);
  void find_unknown_space(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m);
  void mark_seen_free_grid(const Frame& frame, const RobotPixels* robot_pixels, Measurement& m);
  /// v_i and Z_d of every link's contact.
  void measure_links(const Frame& frame, const RobotState& robot_state, Measurement& m);
  PreviousContact& previous_link_contact(int link);
  /// The image watchdogs that need only the background: camera_blocked, camera_moved.
  bool camera_sees_the_cell(const Frame& frame, Measurement& m);
  bool enough_valid_depth(const Frame& frame, Measurement& m) const;
  /// Remembers robot_ and renders the remembered poses into the filtered `frame`; the robot's
  /// pixels, or none without an arm.
  std::optional<RobotPixels> render_robot(const Frame& frame, Measurement& m);
  bool background_checked(const Frame& frame, Measurement& m);
};

struct RunOptions {
  bool pace = false;         ///< play at the source's timestamps; frames may then be dropped
  int64_t max_frames = -1;   ///< stop after this many source frames; -1: until the source ends
  std::atomic<bool>* stop_requested = nullptr;  ///< set from outside (SIGINT, SIGTERM, SIGHUP, SIGTSTP) to end the run
  /// Decides pacing, frame ages, the watchdog and wall_s; null: the steady clock. Tests pass a
  /// FakeClock. Must outlive the run.
  RunClock* clock = nullptr;
  /// `robot.state.camera_latency_s`: the robot state is looked up this much before the frame's
  /// host time (positive: the camera's image is older than its stamp says).
  double camera_latency_s = 0.0;
  /// Called on the processing thread with each frame, the pipeline and its measurement (the
  /// result before the SafetyMonitor decided it: its verdict is not yet set), before it goes to
  /// the output: the viewer's tap (hrcsense-view), which takes the decided verdict from a sink
  /// on the output thread. It delays the output by what it costs, so it must copy and return,
  /// never wait.
  std::function<void(const Frame&, const Pipeline&, const FrameResult&)> on_processed;
  /// Called on the processing thread before each frame with the pipeline and the previous
  /// frame's result (a default, invalid one before the first): where the viewer's requests
  /// (Pipeline::retune, relearn_background) reach the pipeline between frames, never during
  /// one. Like on_processed it must not wait.
  std::function<void(Pipeline&, const FrameResult& previous)> before_process;
};

/// True when run_pipeline gives a frame without its own host time (Frame::host_time_ns 0) its
/// source timestamp as host time: with a `sim` or `recorded` robot state (they live on the
/// source's timeline, paced or not) and in an unpaced run with a `fixed` one; false: the frame's
/// delivery time on the run's clock (docs/ROBOT.md, "Clocks").
bool host_time_is_source_time(RobotStateOrigin origin, bool paced);

/// How long before a frame's host time its robot state is looked up: camera_latency_s in ns,
/// but 0 for a `recorded` state, which is the state processing used for the frame when it was
/// recorded, the latency already applied.
int64_t robot_state_lookup_offset_ns(RobotStateOrigin origin, double camera_latency_s);

/// Runs capture and processing on two threads of their own and output on the caller's, joined
/// by mailboxes. Processing measures (Pipeline::process); the output thread decides each
/// measurement with one SafetyMonitor immediately before the sinks write it. Unpaced runs of
/// files and the simulator (options.pace false) process every frame the source delivers (the
/// source waits for processing); paced runs and live sources (SourceInfo::live) keep the latest
/// frame, drop and count the rest (frames_dropped), and a dropped measurement's verdict is
/// carried into the next (carry_replaced).
/// Each frame gets the robot state `robot_states` has at the frame's host time minus
/// robot_state_lookup_offset_ns (camera_latency_s). The host time is the source's own (a live
/// camera's capture time) when it sets Frame::host_time_ns; else the source timestamp with a
/// `sim` or `recorded` state and for unpaced runs with a `fixed` one, and the delivery time on
/// the run's clock otherwise (host_time_is_source_time; docs/ROBOT.md, "Clocks").
/// Writes header, every result and the summary to `sink`; returns the summary.
RunSummary run_pipeline(Source& source, RobotStateSource& robot_states, Pipeline& pipeline, Sink& sink,
                        const RunOptions& options, const RunHeader& header);

}  // namespace hrcsense
