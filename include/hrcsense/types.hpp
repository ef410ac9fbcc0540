// SPDX-License-Identifier: Apache-2.0
// hrcsense — the plain value types that flow between the pipeline's stages.
#pragma once

#include "hrcsense/ssm.hpp"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {

/// π, for angles in degrees and for disc areas.
inline constexpr double kPi = 3.14159265358979323846;

/// Lens distortion models with the RealSense SDK's numeric values (rs2_distortion).
enum class Distortion : int {
  none = 0,
  modified_brown_conrady = 1,
  inverse_brown_conrady = 2,
  ftheta = 3,
  brown_conrady = 4,
  kannala_brandt4 = 5,
};

/// Pinhole intrinsics plus distortion, with the same meaning as the SDK's rs2_intrinsics.
/// Integer pixel (u, v) is the centre of that pixel; the left image edge is at u = -0.5.
struct Intrinsics {
  int width = 0;                       ///< pixels
  int height = 0;                      ///< pixels
  float fx = 0.0F;                     ///< focal length in pixel widths
  float fy = 0.0F;                     ///< focal length in pixel heights
  float ppx = 0.0F;                    ///< principal point, pixels from the left edge
  float ppy = 0.0F;                    ///< principal point, pixels from the top edge
  Distortion model = Distortion::none; ///< distortion model
  std::array<float, 5> coeffs{};       ///< [k1 k2 p1 p2 k3] or [k1 k2 k3 k4 0] or [w ...]
};

/// A rigid transform. `T_a_b` maps points given in frame b into frame a.
using Pose = Eigen::Isometry3d;

/// A rigid transform between two sensors, laid out as the SDK's rs2_extrinsics.
/// "From A to B": P_B = R * P_A + t, with the rotation stored column-major as the SDK does:
/// element (row i, column j) is rotation[3 * j + i].
struct Extrinsics {
  std::array<float, 9> rotation{1.0F, 0.0F, 0.0F, 0.0F, 1.0F, 0.0F, 0.0F, 0.0F, 1.0F};
  std::array<float, 3> translation_m{};  ///< metres
};

/// A 16-bit depth image; raw 0 means "no data".
struct DepthImage {
  int width = 0;
  int height = 0;
  float depth_scale_m = 0.001F;  ///< metres per raw unit
  std::vector<uint16_t> pixels;  ///< row-major, width * height

  uint16_t at(int u, int v) const { return pixels[static_cast<size_t>(v) * width + u]; }
  /// Sets the size; keeps the buffer's capacity, so reuse does not allocate.
  void resize(int w, int h) {
    width = w;
    height = h;
    pixels.resize(static_cast<size_t>(w) * h);
  }
};

/// An 8-bit RGB image, row-major, 3 bytes per pixel.
struct ColorImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
};

/// Label 0 in GroundTruth::labels: the static scene (learnt as background).
inline constexpr uint16_t kStaticLabel = 0;
/// The simulator's moving arm in GroundTruth::labels (neither static nor a foreground object).
inline constexpr uint16_t kRobotLabel = 0xFFFF;

/// A contact between the foreground and the robot: the closest pair of points.
struct Contact {
  bool valid = false;                              ///< false when there was no foreground
  float distance_m = 0.0F;                         ///< >= 0; 0 when a point is inside a capsule
  bool inside = false;                             ///< the point is inside or on a capsule (distance 0)
  Eigen::Vector3f closest_base = Eigen::Vector3f::Zero();        ///< foreground point, base frame
  Eigen::Vector3f closest_camera = Eigen::Vector3f::Zero();      ///< same point, camera frame
  Eigen::Vector3f closest_robot_base = Eigen::Vector3f::Zero();  ///< point on the robot, base frame
  int robot_link = -1;                             ///< index of the capsule's link
  int pixel = -1;                                  ///< source pixel index (v * width + u), -1 if none
};

/// The simulator's truth for one robot link (GroundTruth::links).
struct LinkTruth {
  int link = -1;                   ///< robot link index (Capsule::link)
  float distance_m = 0.0F;         ///< padded capsules to the nearest moving object's pixel, m
  float speed_towards_mps = 0.0F;  ///< the link point's speed towards that pixel, m/s (negative: away)
};

/// What the simulator knows exactly about a frame it rendered.
struct GroundTruth {
  std::vector<float> depth_m;    ///< noise-free Z per pixel, metres; 0 where nothing was hit
  /// Label per pixel: kStaticLabel for the static scene (and where nothing is hit), kRobotLabel
  /// for the moving arm, 1 + index among the non-static scene objects otherwise.
  std::vector<uint16_t> labels;
  /// Closest point over the noise-free rendered pixels of non-static, non-robot objects (base
  /// frame) to the robot's searched capsules.
  Contact contact;
  /// Closest point over the analytic surfaces of non-static, non-robot objects, visible or not.
  Contact analytic_contact;
  /// Per robot link (in link order, links with a capsule only): the distance from the link's
  /// searched capsules to the nearest noise-free rendered pixel of a moving object and that
  /// link point's speed towards it from the trajectory's joint velocities (`truth.links`).
  /// Computed in the simulator's own code; empty when nothing moving was rendered.
  std::vector<LinkTruth> links;
};

/// One depth frame from a source, with everything needed to interpret it.
struct Frame {
  int64_t index = 0;                 ///< 0-based index of the frame in its source
  int64_t timestamp_ns = 0;          ///< capture time; integer so recordings round-trip exactly
  /// The frame's time on the host's monotonic clock (ns), what the robot state is looked up
  /// at: a live source sets it (its capture time mapped to the host clock); 0 leaves it to
  /// run_pipeline (docs/ROBOT.md, "Clocks").
  int64_t host_time_ns = 0;
  DepthImage depth;
  Intrinsics intrinsics;             ///< of the depth image
  float stereo_baseline_mm = 0.0F;   ///< 0 when the source does not know it
  std::optional<ColorImage> color;
  Intrinsics color_intrinsics;       ///< of the colour image; width 0 when there is none
  std::optional<Extrinsics> depth_to_color;  ///< depth sensor -> colour sensor, when known
  std::optional<GroundTruth> truth;  ///< simulated sources only
};

/// Structure-of-arrays point cloud, so that distance loops vectorise.
struct PointCloud {
  std::vector<float> x, y, z;      ///< metres
  std::vector<uint32_t> pixel;     ///< source pixel index (v * width + u)

  size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
  void clear() {
    x.clear();
    y.clear();
    z.clear();
    pixel.clear();
  }
  void reserve(size_t n) {
    x.reserve(n);
    y.reserve(n);
    z.reserve(n);
    pixel.reserve(n);
  }
  void push_back(float px, float py, float pz, uint32_t pixel_index) {
    x.push_back(px);
    y.push_back(py);
    z.push_back(pz);
    pixel.push_back(pixel_index);
  }
  Eigen::Vector3f point(size_t i) const { return {x[i], y[i], z[i]}; }
};

/// A segment with a radius, in the robot base frame. A point is a capsule with a == b, radius 0.
struct Capsule {
  Eigen::Vector3f a = Eigen::Vector3f::Zero();
  Eigen::Vector3f b = Eigen::Vector3f::Zero();
  float radius_m = 0.0F;
  int link = 0;  ///< which robot link the capsule belongs to
};

/// Number of joints of the arms hrcsense describes (6R, standard DH).
inline constexpr int kJointCount = 6;

/// Joint angles in radians (or velocities in rad/s), joint 1 (base) first, as on the UR
/// pendant and in ROS.
using JointAngles = std::array<double, kJointCount>;

/// Where a robot state came from (`robot.state.source`).
enum class RobotStateOrigin { fixed, sim, rtde, udp_json, recorded, ros2 };

/// `record.on_error`: after a write error, go on without recording (continue) or end the run (stop).
enum class RecordOnError { continue_run, stop_run };

/// What the robot controller says of itself at a robot state's time: UR RTDE's robot_mode,
/// safety_mode, speed_scaling and target_speed_fraction (../shared/specs/ur-rtde.md) and the
/// check of its actual_TCP_pose. The modes are reported only: the robot's own safety system acts
/// on them, and hrcsense's verdict is about the people in the cell. The two speed readings
/// become RobotState::speed_fraction, which the ssm speed scale is computed against.
struct RobotStatus {
  bool known = false;          ///< the source reports it (rtde) for this state; else the rest is unset
  int32_t robot_mode = -1;     ///< UR robot_mode: 7 running, 5 idle, 3 power off...; robot_mode_name()
  int32_t safety_mode = 0;     ///< UR safety_mode: 1 normal, 3 protective stop, 5 safeguard stop...; safety_mode_name()
  double speed_scaling = 0.0;  ///< the controller's trajectory speed scaling, 0..1
  /// The speed slider's value, 0..1 (RTDE target_speed_fraction); NaN: not read.
  double target_speed_fraction = std::numeric_limits<double>::quiet_NaN();
  /// actual_TCP_pose disagrees with the forward kinematics of actual_q (a wrong robot.model, or
  /// a base frame turned; docs/ROBOT.md, "TCP pose check"). False when not checked.
  bool tcp_pose_mismatch = false;
};

/// The arm's joint state at one instant: what a RobotStateSource delivers for a frame, and
/// what Pipeline::process builds the robot's capsules from.
struct RobotState {
  int64_t host_time_ns = 0;   ///< when the state held, on the host's monotonic clock (0: any time, `fixed`)
  /// The newest sample this state was read from (interpolated or extrapolated from): the
  /// frame's robot_state_age_ms is measured from it. 0 for a state that ages not (`fixed`); a
  /// state that is invalid with a sample time is stale rather than missing.
  int64_t sample_time_ns = 0;
  /// Of the time from sample_time_ns to host_time_ns, how much the joints were moved on with
  /// their velocities (RobotStateHistory::at past the newest sample), ns; the rest of the
  /// state's age is time the arm may have moved unseen (Z_r, docs/SAFETY.md).
  int64_t extrapolated_ns = 0;
  JointAngles q_rad{};        ///< joint angles
  JointAngles qd_rad_s{};     ///< joint velocities
  bool valid = false;         ///< false: no state (never measured, lost, rejected); the frame is a stop
  RobotStateOrigin origin = RobotStateOrigin::fixed;
  RobotStatus status;         ///< the controller's report at this time, where the source has one (rtde)
  /// The share of its programmed speed the arm runs at, as the source reads it, 0..1: RTDE
  /// speed_scaling × target_speed_fraction, udp_json's `speed_fraction`, the simulator's
  /// trajectory clock rate. NaN: the source does not say (the monitor then takes the last
  /// speed scale hrcsense sent). The ssm speed scale is a share of the programmed speed.
  double speed_fraction = std::numeric_limits<double>::quiet_NaN();
};

/// The robot as the proximity search sees it: capsules in the base frame.
struct RobotModel {
  std::vector<Capsule> capsules;
};

/// The safety decision for a frame.
enum class VerdictState { run, slow, stop };

/// Why a verdict is what it is, as a stable code (`reason_code` in the output, its snake_case
/// name from reason_code_name(); docs/OUTPUT.md lists them). Control flow uses the code, never
/// the human-readable Verdict::reason.
enum class ReasonCode : uint16_t {
  clear = 0,                ///< run: the contact is at or beyond the slow distance
  no_foreground = 1,        ///< run: nothing in the cell
  in_slow_zone = 2,         ///< slow
  in_stop_zone = 3,         ///< stop: below the stop distance
  inside_robot = 4,         ///< stop: a foreground point inside a robot capsule
  non_finite_input = 5,     ///< stop: a NaN/Inf distance or point, or foreground the search cannot place
  learning_background = 6,  ///< stop: the background is being learnt
  checking_background = 7,  ///< stop: a loaded background is compared with the first frames
  no_valid_depth = 8,       ///< stop: no valid pixel, before or after the filters
  low_valid_share = 9,      ///< stop: fewer valid pixels after the filters than safety.min_valid_share
  background_mismatch = 10, ///< stop: the background is not of the filtered frame's size
  no_robot_model = 11,      ///< stop: no capsules to measure against
  no_robot_state = 12,      ///< stop: no valid robot state for the frame (an arm needs its joints)
  robot_state_stale = 13,   ///< stop: the newest robot state is older than robot.state.max_age_s
  foreground_failed = 14,   ///< stop: the foreground test could not run
  stale_frame = 15,         ///< stop: when decided, seen longer ago than the no-frame limit (no_frame's)
  no_frame = 16,            ///< stop: the watchdog saw no frame for safety.max_frame_age_s (or max_frame_gap_periods)
  source_ended = 17,        ///< stop: end of the run, the source ended
  frame_limit_reached = 18, ///< stop: end of the run, --frames reached
  stop_requested = 19,      ///< stop: end of the run, SIGINT, SIGTERM, SIGHUP or SIGTSTP
  source_error = 20,        ///< stop: end of the run, the source failed
  processing_error = 21,    ///< stop: end of the run, processing failed
  output_error = 22,        ///< stop: end of the run, the output failed
  /// stop: the watchdog saw no frame because the live camera is unplugged (Source::silence_reason),
  /// until the same serial is back and streams again
  camera_disconnected = 23,
  // Numbered for the controller link's datagrams (docs/OUTPUT.md, docs/SAFETY.md): a number,
  // once given, is never reused.
  unknown_space = 24,        ///< stop: unknown space within safety.unknown_stop_within_m of the robot
  envelope_invalid = 25,     ///< stop: too many invalid pixels inside the robot's projected envelope
  camera_blocked = 26,       ///< stop: a large surface right in front of the camera
  camera_moved = 27,         ///< stop: the static background no longer matches the learnt one
  below_protective_distance = 28,  ///< stop (ssm): closer than S_p with the robot at rest
  speed_limited = 29,        ///< slow (ssm): the speed scale keeps the separation at S_p
  holding = 30,              ///< the verdict holds a stricter state (safety.hysteresis_m, min_hold_s)
  /// stop: the background learnt at start holds something nearer than background.reference
  /// within S_p at rest (zones: safety.slow_distance_m) of the robot; learning goes on
  background_not_empty = 31,
  /// stop (fused cells): a camera's newest valid measurement is older than
  /// safety.max_frame_gap_periods of its periods, or its session changed and no valid
  /// measurement of the new one came yet (verdict_reason names the camera)
  camera_stale = 32,
  /// stop: the arm's measured pixels disagree with its visual shapes seen from
  /// camera.T_base_camera (safety.pose_check_threshold_m): the told camera pose is wrong
  camera_pose_mismatch = 33,
};

struct Verdict {
  VerdictState state = VerdictState::stop;  ///< stop unless proven otherwise
  float speed_scale = 0.0F;                 ///< 1 run, 0 stop, in between slow
  float protective_distance_m = 0.0F;       ///< the distance the rule compared against
  ReasonCode code = ReasonCode::no_valid_depth;  ///< why, as a stable code
  std::string reason;                       ///< why, for people (with details); never empty for stop
};

/// Time spent in one stage of one frame.
struct StageTiming {
  const char* stage = "";  ///< static name, e.g. "background", "foreground", "proximity"
  double us = 0.0;    ///< microseconds
};

/// The seen-free grid of a cell with several cameras (seen_free_grid.hpp), one bit per cube: bit i % 8 of bytes[i / 8] is cube i. 1: seen free this frame.
struct SeenFreeGrid {
  std::vector<uint8_t> bytes;
  size_t cells = 0;
  bool test(size_t i) const { return (bytes[i >> 3] >> (i & 7)) & 1U; }
  void set(size_t i) { bytes[i >> 3] = static_cast<uint8_t>(bytes[i >> 3] | (1U << (i & 7))); }
  /// `cells` cubes, none free.
  void reset(size_t cell_count) {
    cells = cell_count;
    bytes.assign((cell_count + 7) / 8, 0);
  }
};

/// One camera of a fused cell as a fused frame reports it (`cameras` in the JSON Lines).
struct CameraStatus {
  std::string name;
  /// The fused instant's time less the capture of the camera's newest measurement, ms; NaN
  /// when none came.
  double age_ms = std::numeric_limits<double>::quiet_NaN();
  bool valid = false;             ///< its newest measurement could be decided on
  ReasonCode reason_code = ReasonCode::no_frame;  ///< clear when valid, else why not
  uint32_t session = 0;           ///< its session; 0 before the first measurement
};

/// One robot link's closest foreground point and what the decision needs of it
/// (Measurement::links).
struct LinkContact {
  int link = -1;     ///< robot link index (Capsule::link): a UR link, the tool, or one point of robot.model points
  Contact contact;   ///< the closest pair between the foreground and this link's capsules
  /// v_i: the velocity of this link's closest point along the separation vector towards the
  /// foreground point, m/s (negative: away; 0 for fixed points); NaN when not computed.
  float speed_towards_mps = std::numeric_limits<float>::quiet_NaN();
  /// Z_d of this contact (contact_uncertainty_m), m; NaN when not computed.
  float distance_uncertainty_m = std::numeric_limits<float>::quiet_NaN();
};

/// What processing measured for one frame (Pipeline::process), before any decision: the
/// SafetyMonitor turns it into the verdict on the output thread. Buffers are reused frame to
/// frame. A camera's measurement is what a fuser of several cameras (still to come) would receive.
struct Measurement {
  int64_t frame = 0;          ///< source frame index
  /// false for a result that stands for no new source frame (watchdog timeout, end of run);
  /// it then repeats the last frame's index and timestamp.
  bool source_frame = true;
  int64_t timestamp_ns = 0;
  /// Usable depth, processed, background ready: the contacts below can be decided on. False:
  /// the measurement is withheld and `withheld_code` / `withheld_reason` say why (a stop).
  bool valid = false;
  ReasonCode withheld_code = ReasonCode::no_valid_depth;  ///< why not valid
  std::string withheld_reason;                             ///< the same for people, with details
  Contact contact;            ///< the overall closest pair; contact.valid false when there is no foreground
  /// Per robot link with a measured contact, in link order (empty without foreground).
  std::vector<LinkContact> links;
  size_t foreground_points = 0;
  /// Pixels the self-filter removed from the foreground (the robot's own); 0 without an arm.
  size_t self_filtered_pixels = 0;
  size_t invalid_pixels = 0;  ///< raw zeros in the source frame, before any filter
  /// Share of valid (non-zero) pixels in the filtered image, 0..1 (safety.min_valid_share);
  /// 0 when the frame was not filtered (no valid depth at all, or no source frame).
  float valid_share = 0.0F;
  std::vector<StageTiming> timings;
  RobotState robot_state;        ///< the state the robot's capsules were built from
  int64_t host_time_ns = 0;      ///< the frame's host time (Frame::host_time_ns as the run set it)
  /// Frame host time minus robot_state.sample_time_ns, ≥ 0; 0 for a state that ages not.
  double robot_state_age_ms = 0.0;
  /// Run-clock times of the frame, set by run_pipeline (`clocked`): when the source delivered
  /// it and when it was seen (its capture on the host clock when the source set one, a live
  /// camera's, else the delivery; T_r and the stale limit count from here). Not clocked (a caller of
  /// Pipeline::process alone): the decision takes an age of 0 and never calls it stale.
  bool clocked = false;
  int64_t delivered_ns = 0;
  int64_t seen_ns = 0;
  std::optional<Contact> truth;  ///< simulated sources: ground-truth contact
  std::vector<LinkTruth> truth_links;  ///< simulated sources: GroundTruth::links
  double latency_us = 0.0;       ///< from the frame entering processing to the measurement
  /// The robot's distance to the nearest unknown ray (docs/SAFETY.md), m; NaN: none known.
  float unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
  /// The proximity backend that searched this frame (static name, e.g. "octree" when `auto`
  /// picked it); null when no search ran.
  const char* backend = nullptr;
  /// A camera of a cell with several (`hrcsense run --camera`): the cubes of the shared grid it
  /// saw free; cells 0 when no grid is configured. Fused (`hrcsense fuse`): the union.
  SeenFreeGrid seen_free;
  /// Fused cells only: each configured camera's state at this instant (`cameras`) and the
  /// name of the camera that measured the governing contact (`closest_camera_name`; empty:
  /// no contact). Empty for a single camera's measurement.
  std::vector<CameraStatus> cameras;
  std::string closest_camera_name;
  /// Static text when the frame's source timestamp was out of order (backwards, repeated, a
  /// gap or a jump; RunSummary::timestamps counts them); null when in order.
  const char* timestamp_warning = nullptr;
};

/// The strictest of the measurements a mailbox replaced before they were decided
/// (FrameResult::replaced): the result written next carries it.
struct ReplacedVerdicts {
  int64_t count = 0;                         ///< measurements replaced since the last decision
  VerdictState state = VerdictState::run;    ///< the strictest of their verdicts (count > 0)
  float speed_scale = 1.0F;                  ///< the lowest of their speed scales
  ReasonCode code = ReasonCode::clear;       ///< the strictest verdict's reason
  std::string reason;
};

/// Everything a sink needs about one frame: the measurement and the SafetyMonitor's decision.
struct FrameResult : Measurement {
  Verdict verdict;
  /// `safety.mode: ssm`, a valid frame with a contact: the governing link's S_p terms at its
  /// present speed (their sum is Verdict::protective_distance_m); none otherwise.
  std::optional<SsmTerms> ssm;
  /// The link whose d_i − S_p,i is smallest among the links with the strictest verdict: it
  /// governs verdict and scale (`governing_link`); -1 without a contact.
  int governing_link = -1;
  /// Z_d of the governing link's contact, m; NaN without a measured contact.
  float distance_uncertainty_m = std::numeric_limits<float>::quiet_NaN();
  /// v_r of the governing link towards its contact, m/s (negative: away); NaN when not computed.
  float robot_speed_towards_mps = std::numeric_limits<float>::quiet_NaN();
  /// unknown_distance_m less the governing S_p (ssm) or safety.stop_distance_m (zones), m;
  /// NaN without unknown space (`unknown_margin_m`).
  float unknown_margin_m = std::numeric_limits<float>::quiet_NaN();
  /// Per link with a contact (`links`): its S_p at its own present speed, m; same order as
  /// Measurement::links.
  std::vector<float> link_protective_distance_m;
  double frame_age_s = 0.0;      ///< the frame's age when it was decided (host time to then)
  /// The share of its programmed speed the robot was taken to run at (`robot_speed_fraction`):
  /// the state's speed_fraction, else the last scale sent; ssm's speed scale is against it.
  double robot_speed_fraction = 1.0;
  ReplacedVerdicts replaced;     ///< measurements replaced before decision; merged into verdict
};

}  // namespace hrcsense
