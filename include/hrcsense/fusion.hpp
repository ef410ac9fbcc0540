// SPDX-License-Identifier: Apache-2.0
// hrcsense — a cell with several cameras (docs/MULTICAMERA.md): each camera's process measures
// and publishes a CameraMeasurement; the fuser keeps the newest of each camera and makes one
// Measurement for the cell's SafetyMonitor: per robot link the nearest contact over the
// cameras, T_r from the oldest contributing capture, a stop naming the camera when one is
// stale, restarted, or stops itself.
#pragma once

#include "hrcsense/robot.hpp"
#include "hrcsense/safety.hpp"
#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/types.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {

/// What one camera's process sends for one of its frames: everything the decision needs and
/// nothing of the image. Times are on the cell's shared clock: CLOCK_REALTIME ns, kept in step
/// across hosts by chrony or PTP (docs/MULTICAMERA.md, "Clocks").
struct CameraMeasurement {
  std::string camera_name;   ///< the scene's `cameras:` entry (a ROS name token)
  uint32_t session = 0;      ///< random per process start: a new value is a restart
  uint64_t sequence = 0;     ///< 1 for a session's first measurement, +1 per measurement
  int64_t frame = 0;         ///< the camera's frame index (simulated: the scene frame)
  int64_t capture_ns = 0;    ///< when the frame was captured, the shared clock
  double nominal_fps = 0.0;  ///< the camera's nominal rate (the stale rule counts its periods)
  Intrinsics intrinsics;     ///< of the depth image measured (the fused header shows it)
  Pose T_base_camera = Pose::Identity();  ///< the pose the camera measured with
  /// The measurement can be decided on; false: `reason_code` / `reason` say why (a stop).
  bool valid = false;
  ReasonCode reason_code = ReasonCode::no_valid_depth;
  std::string reason;
  Contact contact;                ///< the camera's overall closest pair; invalid: no foreground
  std::vector<LinkContact> links; ///< per link with a contact, link order
  /// The camera's own per-ray unknown distance (docs/SAFETY.md), m; NaN: none known.
  float unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
  SeenFreeGrid seen_free;         ///< cubes of the shared grid seen free; cells 0: none computed
  uint32_t foreground_points = 0;
  uint32_t self_filtered_pixels = 0;
  uint32_t invalid_pixels = 0;
  float valid_share = 0.0F;
  /// The robot state the capsules were built from (its sample time on the shared clock).
  RobotState robot_state;
  double robot_state_age_ms = 0.0;
  /// The frame's capture to the measurement's publication, µs (MeasurementSink; processing alone
  /// for a measurement not yet sent): the fused latency's camera part.
  double latency_us = 0.0;
  /// Simulated cameras: the truth for this camera's pixels (GroundTruth::contact, ::links).
  std::optional<Contact> truth;
  std::vector<LinkTruth> truth_links;
};

/// A camera's name is a ROS 2 name token: a letter, then letters, digits and '_' (it becomes the
/// last token of its topic, `<ns>/measurement/<NAME>`).
bool is_camera_name(const std::string& name);

/// The newest measurement of a camera's frame, for a fuser: `m` (a FrameResult or a Pipeline's
/// measurement, clocked by run_pipeline) with its times moved from the run's steady clock onto
/// the shared clock by `realtime_minus_steady_ns` (CLOCK_REALTIME − CLOCK_MONOTONIC, read once
/// per frame). The capture is m.seen_ns: the frame's capture on the host clock where the source
/// knows it, else its delivery (the same instant a single camera's T_r counts from). Leaves
/// camera_name, session, sequence, nominal_fps, intrinsics and T_base_camera as they are.
void to_camera_measurement(const Measurement& m, int64_t realtime_minus_steady_ns, CameraMeasurement& out);

/// Why `m` cannot be fused, naming the field (e.g. "links[2].distance_m: -0.1 is not a
/// distance"), or empty when it can: a name, a session and a sequence, a finite positive rate and
/// capture, link indices in 0..kMaxFusedLinks−1 and each at most once, for a valid measurement
/// finite non-negative distances and finite points, a reason code the enum knows. Pure.
std::string measurement_problem(const CameraMeasurement& m);

/// Links a measurement may name: more than any arm hrcsense describes (6 links and a tool, or the
/// points of robot.model points), few enough that a hostile sender cannot make the fuser loop long.
inline constexpr int kMaxFusedLinks = 64;

/// A camera the fuser expects (the scene's `cameras:` entries).
struct FusionCamera {
  std::string name;
  double fps = 30.0;  ///< nominal rate: the stale rule's period until its measurements say
};

struct FusionParams {
  /// The cell's decision terms: max_frame_gap_periods (the stale rule) and the ssm terms that
  /// rank two cameras' contacts of one link.
  SafetyParams safety;
  RobotParams robot;  ///< the arm, for the distance to the cubes no camera saw free
  /// The shared grid (`cell.*`); disabled: the fused unknown distance is the largest of the
  /// cameras' per-ray distances.
  SeenFreeGridSpec grid;
  /// A capture stamped further than this ahead of the fuser's clock is rejected (a camera whose
  /// clock jumped, or an unsynchronised host), ns.
  int64_t max_clock_ahead_ns = 50'000'000;
  /// The bound on any camera host's clock offset from the fuser's (`cell.clock_offset_max_s`),
  /// ns: every capture counts as this much older, for T_r and for the stale rule, so that an
  /// offset within the bound never makes a verdict laxer. 0 on one host.
  int64_t clock_offset_max_ns = 0;
};

/// What became of a received measurement.
enum class FusionIntake { accepted, unknown_camera, malformed, out_of_order, clock_ahead, grid_mismatch };
const char* fusion_intake_name(FusionIntake intake);  ///< "accepted", "unknown_camera", ...

/// One camera's counters (FusionCounters).
struct FusionCameraCounters {
  int64_t accepted = 0;
  int64_t malformed = 0;     ///< measurement_problem() said why; the last is in last_problem
  int64_t out_of_order = 0;  ///< a sequence or capture not after the newest of its session
  int64_t clock_ahead = 0;   ///< stamped in the fuser's future (FusionParams::max_clock_ahead_ns)
  int64_t grid_mismatch = 0; ///< a seen-free grid of another cell count
  int64_t sessions = 0;      ///< sessions seen (1 + restarts)
  std::string last_problem;
};

/// The fuser's memory: the newest measurement of each configured camera and what each camera's
/// stream has been. Not thread-safe; one per fuser.
class CellFusion {
 public:
  CellFusion(std::vector<FusionCamera> cameras, FusionParams params);

  /// Takes `m`, received at `now_ns` on the shared clock: kept as its camera's newest unless it
  /// is rejected (the return says why; counted). A new session replaces the old one at once:
  /// the camera is stale until that session's first valid measurement.
  FusionIntake add(const CameraMeasurement& m, int64_t now_ns);

  /// The cell's measurement for the instant `instant_ns` (shared clock; `frame` its scene frame
  /// index), decided at `now_ns`: `out`'s Measurement part (its buffers reused). Valid only when
  /// every camera's newest measurement is valid and fresh: a camera whose newest valid capture is
  /// more than safety.max_frame_gap_periods of its periods before `now_ns`, or that restarted and
  /// has no valid measurement of its new session yet, withholds it with `camera_stale`; a camera
  /// whose newest measurement is a stop withholds it with its own code. The reason names every
  /// such camera. Valid: per robot link the strictest of the cameras' contacts (in zones mode the
  /// nearest; in ssm the smallest d − S_p, which is the nearest unless a farther contact is less
  /// certain or approached faster), the overall contact the nearest, the seen time (T_r's start,
  /// Measurement::seen_ns) the oldest contributing capture, the robot state that camera's, and
  /// the unknown distance from the union of the grids. The times of `out` are on the shared clock
  /// (decide it with SafetyMonitor::decide(result, now_ns)). Also fills out.cameras.
  void fuse(int64_t instant_ns, int64_t frame, int64_t now_ns, Measurement& out);

  /// The camera whose contact `out.links[i]` is (index into cameras()), after fuse().
  const std::vector<int>& link_camera() const { return link_camera_; }
  /// The camera of the overall contact after fuse(), -1 without one.
  int contact_camera() const { return contact_camera_; }
  /// The name of the camera that measured link `link` (Capsule::link) in the last fuse(), or of
  /// the overall contact when `link` < 0 or not found; empty without a contact.
  const std::string& camera_of_link(int link) const;

  const std::vector<FusionCamera>& cameras() const { return cameras_; }
  /// -1 for a name that is not configured.
  int camera_index(const std::string& name) const;
  /// The newest accepted measurement of camera `i`, null before the first.
  const CameraMeasurement* newest(size_t i) const;
  const FusionCameraCounters& counters(size_t i) const { return slots_[i].counters; }
  int64_t unknown_camera_count() const { return unknown_camera_; }

 private:
  struct Slot {
    bool have = false;               ///< a measurement of the current session came
    CameraMeasurement newest;        ///< the newest accepted
    bool have_valid = false;         ///< a valid measurement of the current session came
    int64_t newest_valid_capture_ns = 0;
    uint32_t previous_session = 0;   ///< the session before a restart (for the reason)
    bool restarted = false;          ///< the session changed and no valid measurement came since
    FusionCameraCounters counters;
  };
  std::vector<FusionCamera> cameras_;
  FusionParams params_;
  std::vector<Slot> slots_;
  int64_t unknown_camera_ = 0;
  std::vector<int> link_camera_;  ///< per out.links entry: its camera
  std::vector<int> link_ids_;     ///< per out.links entry: its link
  int contact_camera_ = -1;
  RobotModel robot_model_;           ///< scratch: the capsules at the fused state
  UnknownDistanceScratch distance_scratch_;  ///< scratch of unknown_cells_distance_m
  std::string empty_;
};

}  // namespace hrcsense
