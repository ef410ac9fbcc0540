// SPDX-License-Identifier: Apache-2.0
// hrcsense — a consumer of results: one of the four virtual interfaces (source.hpp says which).
// JSON Lines, the console, the UDP and RTDE links to the controller and the viewer's tap
// implement it, and so do the ROS 2 outputs (dds/ros2_outputs.hpp); with what a run says
// before and after its frames.
#pragma once

#include "hrcsense/robot_state.hpp"
#include "hrcsense/source.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {

/// What the run is about, written once before the first frame.
struct RunHeader {
  std::string version;  ///< empty: the JSON Lines sink writes the version it was built as
  std::string commit;   ///< empty: likewise the commit
  std::string config_hash;
  /// The process's session (process_session(), session.hpp), the one the link's datagrams
  /// carry, so a file and a receiver's log can be matched; 0: not known (written as null).
  uint32_t session = 0;
  SourceInfo source;
  std::string robot_state;  ///< `robot.state.source` (fixed, sim, rtde, udp_json, recorded, ros2); empty: not written
  /// `safety.mode: ssm`: where S_s comes from, stopping_data_name() ("default", "table",
  /// "limits"); empty (null): zones mode.
  std::string stopping_data;
  /// What the robot state source delivers beyond time-stamped joints: "robot_status" (frames
  /// carry the controller's robot_status) and "tcp_pose_check" (its actual_TCP_pose is checked
  /// against the forward kinematics); empty: nothing more (or not written: robot_state empty).
  std::vector<std::string> robot_state_reports;
  /// Pipeline::unknown_background_share of a background loaded before the run; < 0 (null):
  /// not known yet (it is learnt during the run; the summary has it then).
  double unknown_background_share = -1.0;
  /// The depth filters as they run: `filters.preset`, the domain of filter_domain(), a note
  /// when the domain is not the one the preset asks for, and the filtered resolution.
  struct Filters {
    std::string preset;    ///< empty: not written (no configuration, e.g. in tests)
    std::string domain;    ///< "none", "disparity" or "depth"
    std::string note;      ///< e.g. why there is no disparity domain; empty for none
    Intrinsics intrinsics; ///< of the filtered image (background, Contact::pixel)
  } filters;
  /// A fused cell (`hrcsense fuse`, `hrcsense cell`): each configured camera's name, pose and,
  /// where known, intrinsics (`cameras` in the header). Empty for a single camera's run.
  struct Camera {
    std::string name;
    Pose T_base_camera = Pose::Identity();
    double nominal_fps = 0.0;
    Intrinsics intrinsics;  ///< width 0: not known before the camera reports (written as null)
  };
  std::vector<Camera> cameras;
};

/// Source timestamps out of order, counted over a run (each frame against the one before).
struct TimestampCounts {
  int64_t backwards = 0;       ///< a timestamp earlier than the previous frame's
  int64_t repeated = 0;        ///< the same timestamp as the previous frame's
  int64_t gaps = 0;            ///< steps of more than 1.5 nominal periods (up to max_frame_age_s)
  int64_t frames_skipped = 0;  ///< frames missing in those gaps, at the nominal rate
  int64_t jumps = 0;           ///< steps longer than safety.max_frame_age_s (paced waits are cut there)
};

/// Totals written once at the end.
struct RunSummary {
  int64_t frames_in = 0;          ///< frames read from the source
  int64_t frames_processed = 0;   ///< frames that went through processing
  int64_t frames_dropped = 0;     ///< dropped by mailboxes (paced runs and live sources; unpaced files and the simulator wait)
  int64_t frames_dropped_camera = 0;  ///< lost before the source delivered them (Source::frames_dropped_camera)
  int64_t frames_valid = 0;
  int64_t verdict_run = 0, verdict_slow = 0, verdict_stop = 0;
  double wall_s = 0.0;
  double fps = 0.0;               ///< frames_processed / wall_s
  double latency_p50_us = 0.0, latency_p99_us = 0.0;
  float min_distance_m = -1.0F;   ///< smallest distance seen; -1 if never any foreground
  /// How the run ended: source_ended, frame_limit_reached, stop_requested, source_error,
  /// processing_error or output_error; end_reason says it for people.
  ReasonCode end_code = ReasonCode::source_ended;
  std::string end_reason;         ///< "end of source", or the source's error
  /// Why the run failed (source error, processing error, output failed); empty when it ended
  /// normally (end of source, frame limit, stop requested). The app exits 1 when set.
  std::string error;
  TimestampCounts timestamps;     ///< source timestamps out of order
  RobotStateStats robot_state;    ///< the robot state source's counters
  RobotStatusCounts robot_status; ///< the controller's status over the frames written
  double unknown_background_share = -1.0;  ///< Pipeline::unknown_background_share at the end; < 0: no background
  /// A fused cell: what came of each camera's measurements (`cameras` in the summary).
  struct CameraIntake {
    std::string name;
    int64_t accepted = 0;
    int64_t malformed = 0;     ///< unreadable, or values measurement_problem() refuses
    int64_t out_of_order = 0;
    int64_t clock_ahead = 0;
    int64_t grid_mismatch = 0;
    int64_t name_mismatch = 0; ///< another camera's name on this camera's topic
    int64_t sessions = 0;
    std::string last_problem;
  };
  std::vector<CameraIntake> cameras;
  /// A fused cell: writers discovered on `<ns>/measurement/<x>`, x no configured camera (never
  /// read), and the last such topic.
  int64_t unconfigured_measurement_publishers = 0;
  std::string last_unconfigured_measurement_topic;
};

/// A consumer of results. One of the four virtual interfaces of hrcsense (listed at the top of source.hpp).
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void header(const RunHeader& header) = 0;
  virtual void frame(const FrameResult& result) = 0;
  virtual void summary(const RunSummary& summary) = 0;
  /// True once the sink can no longer deliver results (a closed pipe, a full disk); the run
  /// then ends. failure() says why.
  virtual bool failed() const { return false; }
  virtual std::string failure() const { return {}; }
};

}  // namespace hrcsense
