// SPDX-License-Identifier: Apache-2.0
// hrcsense — the configuration: YAML files plus --set KEY=VALUE overrides, parsed in one
// place into the stages' parameter structs. Every key has a default (docs/CONFIG.md);
// an unknown or ill-typed key is an error that names the key and the file.
#pragma once

#include "hrcsense/calibration.hpp"
#include "hrcsense/pipeline_params.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/robot_state_history.hpp"
#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/sim/sim.hpp"

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense {

// Closed choices (a key with a fixed list of names) are enums, parsed once in src/config; the
// rest of the code compares the enum, and prints the name with the *_name function below.

/// `source.type`: where the frames come from.
enum class SourceType { sim, folder, bag, realsense, ros2 };
/// A recording played back (folder or bag), not a live or simulated camera.
inline bool is_recording(SourceType type) { return type == SourceType::folder || type == SourceType::bag; }
/// `link.udp.format`: the datagram's layout.
enum class UdpFormat { binary, json };
/// `link.rtde.write`: what goes to the controller over RTDE (input_register is `register`).
enum class RtdeWrite { off, speed_slider, input_register };
/// `robot.model`: padded points, a built-in arm, or an arm from `robot.description`.
enum class RobotModelType { points, ur5, ur5e, ur10e, custom };
/// `robot.state.ros2.speed_scaling_unit`: how the driver's std_msgs/Float64 speed scaling reads.
enum class SpeedScalingUnit { percent, fraction };

/// The configuration's name of each choice (a static string): "sim", "json", "register", ...
const char* source_type_name(SourceType type);
const char* udp_format_name(UdpFormat format);
const char* rtde_write_name(RtdeWrite write);
const char* robot_model_name(RobotModelType model);
const char* record_on_error_name(RecordOnError on_error);  ///< "continue", "stop"
const char* speed_scaling_unit_name(SpeedScalingUnit unit);  ///< "percent", "fraction"
/// The built-in arm a model names; nullopt for points and custom.
std::optional<BuiltinArm> builtin_arm_of(RobotModelType model);

/// A configuration problem; what() names the file and the key.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `source.ros2.*`: realsense-ros 4.x camera topics read over Cyclone DDS (docs/CAMERAS.md).
/// A topic left empty follows the namespace: `<namespace>/depth/image_rect_raw`,
/// `<namespace>/color/image_raw`, `<namespace>/extrinsics/depth_to_color`; each image's
/// CameraInfo is its sibling `camera_info`.
struct Ros2SourceConfig {
  std::string node_namespace = "/camera/camera";  ///< `source.ros2.namespace`: the camera node
  std::string depth_topic;          ///< `source.ros2.depth_topic`
  std::string color_topic;          ///< `source.ros2.color_topic`
  std::string extrinsics_topic;     ///< `source.ros2.extrinsics_topic`
  bool color = true;                ///< `source.ros2.color`: pair colour images with depth when they come
  int domain_id = 0;                ///< `source.ros2.domain_id`: the DDS domain (ROS_DOMAIN_ID)
  double startup_timeout_s = 10.0;  ///< `source.ros2.startup_timeout_s`: wait for the first depth CameraInfo
};

/// `publish.*`: `hrcsense publish`, a configured source as realsense-ros topics.
struct PublishConfig {
  std::string node_namespace = "/camera/camera";  ///< `publish.namespace`
  int domain_id = 0;                ///< `publish.domain_id`
  int wait_for_subscribers = 0;     ///< `publish.wait_for_subscribers`: start once this many depth readers matched
  double wait_timeout_s = 30.0;     ///< `publish.wait_timeout_s`: how long to wait for them
};

/// `ros2.*`: hrcsense's results as ROS 2 topics over Cyclone DDS, and the DDS domain of its ROS 2
/// inputs (robot.state.source ros2); docs/ROS2.md.
struct Ros2Config {
  bool publish = false;                    ///< `ros2.publish`: verdict, speed_scaling, markers, foreground, /tf_static
  int domain_id = 0;                       ///< `ros2.domain_id`: the DDS domain (ROS_DOMAIN_ID)
  std::string node_namespace = "/hrcsense";  ///< `ros2.namespace`: the topics' prefix
  double cloud_hz = 10.0;                  ///< `ros2.cloud_hz`: foreground clouds per second at most; 0: none
  /// `ros2.preview_hz`: a camera of a cell (`run --camera NAME`) publishes its decimated depth
  /// on <namespace>/<NAME>/depth_preview this often at most; 0: none.
  double preview_hz = 5.0;
  /// `ros2.preview_decimation`: the preview keeps one pixel per this many in each direction
  /// (4: 848×480 → 212×120).
  int preview_decimation = 4;
  /// `ros2.speed_scaling_topic`: an absolute name for the speed scaling output; empty:
  /// <namespace>/speed_scaling.
  std::string speed_scaling_topic;
  /// `ros2.camera_name`: the camera's frames are <camera_name>_link and
  /// <camera_name>_depth_optical_frame (realsense-ros's names).
  std::string camera_name = "camera";
};

/// One RealSense SDK option to set on the depth sensor (`source.options.<name>`): the SDK's
/// option name in snake_case (visual_preset, laser_power, emitter_enabled, exposure,
/// enable_auto_exposure) and the numeric value the SDK takes, already checked against the
/// SDK's range (a visual preset is its rs2_rs400_visual_preset number).
struct CameraOption {
  std::string name;
  float value = 0.0F;
};

/// `source.color`: the colour stream of a live camera (`source.type: realsense`).
struct ColorStreamConfig {
  bool enabled = false;  ///< `source.color.enabled`: stream colour too (off: depth alone)
  int width = 848;       ///< `source.color.width`, pixels
  int height = 480;      ///< `source.color.height`, pixels
  int fps = 30;          ///< `source.color.fps`, frames/s (the D435's RGB sensor: 6, 15, 30, 60)
};

struct SourceConfig {
  SourceType type = SourceType::sim;  ///< `source.type`
  /// `source.latency_s`: how long before its stamp the camera saw the scene (exposure and
  /// readout), s; part of T_r. Default per source type: 0 for the simulator (it renders at its
  /// stamp), kCameraLatencyS for cameras and recordings of them (docs/SAFETY.md).
  double latency_s = 0.0;
  std::string path;                ///< file or folder for recorded sources (realsense: a .bag to play through the SDK)
  bool pace = false;               ///< play at the recorded / nominal rate
  bool loop = false;               ///< start over at the end
  float stereo_baseline_mm = 0.0F; ///< for sources that do not carry one
  // The live camera (`source.type: realsense`, docs/CAMERAS.md).
  std::string serial;              ///< `source.serial`: the camera's serial number; empty: the first camera found
  int width = 848;                 ///< `source.width`: depth width, pixels
  int height = 480;                ///< `source.height`: depth height, pixels
  int fps = 30;                    ///< `source.fps`: depth rate, one of the D435's 6, 15, 30, 60, 90 frames/s
  ColorStreamConfig color;         ///< `source.color.*`
  /// `source.options.*`, in the order the SDK must get them (visual_preset first: a preset
  /// resets the other options; enable_auto_exposure before exposure).
  std::vector<CameraOption> options;
  /// `source.settle_frames`: frames skipped after the start (and each reconnect) while auto
  /// exposure settles, before background learning sees any; 0 with auto exposure off.
  int settle_frames = 30;
  Ros2SourceConfig ros2;           ///< `source.ros2.*`
};

/// Where the robot's joint state comes from (`robot.state.*`, docs/ROBOT.md).
/// `robot.state.ros2.*`: sensor_msgs/JointState from a ROS 2 driver over Cyclone DDS, on
/// `ros2.domain_id` (docs/ROS2.md, "Joint states in").
struct Ros2JointStateConfig {
  std::string topic = "/joint_states";  ///< `robot.state.ros2.topic`
  /// `robot.state.ros2.tf_prefix`: put before UR's six joint names (e.g. "ur_" for
  /// ur_shoulder_pan_joint); empty by default.
  std::string tf_prefix;
  /// `robot.state.ros2.speed_scaling_topic`: the driver's speed scaling, std_msgs/Float64; empty:
  /// not read.
  std::string speed_scaling_topic = "/speed_scaling_state_broadcaster/speed_scaling";
  /// `robot.state.ros2.speed_scaling_unit`: percent (UR's driver publishes 0-100) or fraction (0-1).
  SpeedScalingUnit speed_scaling_unit = SpeedScalingUnit::percent;
};

struct RobotStateConfig {
  /// `robot.state.source`: fixed (robot.joints_rad), sim (robot.trajectory), rtde (a UR
  /// controller), udp_json (any robot), recorded (a .bag from hrcsense record), ros2 (a ROS 2
  /// driver's /joint_states).
  RobotStateOrigin source = RobotStateOrigin::fixed;
  /// `robot.joints_rad`: the fixed pose, joint 1 first (required for an arm with the fixed
  /// source; zeros when not given).
  JointAngles joints_rad{};
  std::string host;              ///< `robot.state.host`: the RTDE controller (required for rtde)
  int port = 30004;              ///< `robot.state.port`: RTDE's port
  double frequency_hz = 125.0;   ///< `robot.state.frequency_hz`: RTDE output rate (CB3 ≤ 125, e-Series ≤ 500)
  std::string listen = "127.0.0.1:30010";  ///< `robot.state.listen`: udp_json address host:port
  /// `robot.state.max_age_s`, `robot.state.camera_latency_s`: stale limit and camera delay.
  RobotStateHistoryParams history;
  double camera_latency_s = 0.0;
  double sim_latency_s = 0.0;    ///< `robot.state.sim_latency_s`: the simulated state arrives this late
  double sim_jitter_s = 0.0;     ///< `robot.state.sim_jitter_s`: uniform jitter on that delay
  /// `robot.trajectory`: the simulator's scripted arm motion (an arm only; required for the
  /// sim source). Set: the simulator moves the arm along it instead of rendering it fixed at
  /// robot.joints_rad.
  std::optional<RobotTrajectory> trajectory;
  Ros2JointStateConfig ros2;     ///< `robot.state.ros2.*`
};

/// `record.*`: recordings made by `hrcsense record` and `hrcsense run --record` (docs/RECORDINGS.md).
struct RecordConfig {
  int64_t split_mb = 0;             ///< `record.split_mb`: > 0: a new file (NAME-000.bag, ...) past this many MiB; 0: one file
  /// `record.on_error`: continue (processing goes on unrecorded) or stop
  RecordOnError on_error = RecordOnError::continue_run;
  int queue_frames = 16;            ///< `record.queue_frames`: frames waiting for the disk before drops
};

/// `link.*`: the verdict sent to the robot controller (docs/SAFETY.md, "The link").
struct LinkConfig {
  /// `link.udp.address`: "host:port" (numeric IPv4 or [IPv6]) the datagrams go to; empty: no
  /// UDP link.
  std::string udp_address;
  UdpFormat udp_format = UdpFormat::binary;  ///< `link.udp.format`: binary (the HRCS layout) or json (the frame line)
  double heartbeat_hz = 20.0;         ///< `link.heartbeat_hz`: heartbeats while no frame comes, Hz
  /// `link.rtde.write`: off (default), speed_slider or register: the speed scale written to the
  /// controller at robot.state.host over RTDE.
  RtdeWrite rtde_write = RtdeWrite::off;
  int rtde_register = 24;             ///< `link.rtde.register`: input_double_register_N, N in 24..47
  /// `link.rtde.min_speed_slider`: the slider never goes below this fraction (a hard 0 then
  /// another value has caused protective stops); stops go through the register path.
  double rtde_min_speed_slider = 0.01;
  /// `link.rtde.slider_unguarded_ok`: allow `speed_slider` in `safety.mode: ssm`. The slider
  /// keeps its last value (1.0 after a `run`) when hrcsense dies, so it is refused there unless
  /// the integrator has guarded it on the robot (docs/SAFETY.md) and says so here.
  bool rtde_slider_unguarded_ok = false;
};

/// One entry of the scene's `cameras:` list (H2, docs/MULTICAMERA.md): a camera of a cell with
/// several. `hrcsense run --camera NAME` measures with the entry's keys laid over the top-level
/// ones; the fuser reads the list for the names it accepts, their poses and rates.
struct CameraEntry {
  std::string name;                       ///< `name`: a ROS name token ([A-Za-z][A-Za-z0-9_]*)
  Pose T_base_camera = Pose::Identity();  ///< `T_base_camera`: where the camera is told it is
  double fps = 30.0;                      ///< `fps`: its nominal rate (the stale rule's period)
  SourceType source_type = SourceType::sim;  ///< its `source.type` (the top-level one unless it says)
  /// The depth intrinsics where the configuration alone fixes them (simulated cameras); unset
  /// for cameras, which report theirs with each measurement.
  std::optional<Intrinsics> intrinsics;
};

/// `cell.*`: what every process of a cell with several cameras shares.
struct CellConfig {
  /// `cell.workspace_base` (default `foreground.workspace_base`'s box) and `cell.voxel_m`
  /// (0.05 m); enabled when the configuration has `cameras:`.
  SeenFreeGridSpec grid;
  /// `cell.clock_offset_max_s` (0): the bound checked for every camera host's clock offset from
  /// the fuser's (docs/MULTICAMERA.md, "Clocks"); the fuser takes every capture as this much older.
  double clock_offset_max_s = 0.0;
  /// `cell.fuser_priority` (0): 1..99 runs every thread of the fuser under SCHED_FIFO at this
  /// priority, so that the cameras' processing on the same host cannot delay its decision
  /// (docs/MULTICAMERA.md, "The fuser's host"); 0 leaves it to the normal scheduler.
  int fuser_priority = 0;
};

struct Config {
  std::string file;                ///< where it was read from ("" for defaults only)
  SourceConfig source;
  SimParams sim;                   ///< `sim.*`: the simulated camera; `source.seed` is sim.seed
  Scene scene;                     ///< `scene.objects`: the simulated scene
  /// `sim.camera_T_base_camera`: where the simulated camera truly is, base ← camera; unset: where
  /// hrcsense is told it is (pipeline.T_base_camera). The pipeline never reads it.
  std::optional<Pose> sim_camera_T_base_camera;
  /// `sim.camera_knock_frame`, `sim.camera_knock_T_base_camera`: the true pose from a frame on.
  SimCameraKnock sim_camera_knock;
  /// `filters.preset`: none, sdk (default: the RealSense Viewer's) or thesis; the chain itself
  /// is in pipeline.filters.
  FilterPreset filters_preset = FilterPreset::sdk;
  std::string background_path;     ///< `background.path`: load if it exists, else save after learning
  /// `background.reference`: a background taught with the cell empty (`hrcsense teach`); each
  /// start learns afresh and compares the learnt background with it (background_path is then
  /// ignored). Empty: none.
  std::string background_reference;
  PipelineParams pipeline;         ///< camera pose, robot, background, foreground, proximity, safety
  /// `robot.model`: points, ur5, ur5e, ur10e or custom. The arm (built in or from
  /// `robot.description`), `robot.padding_m` in effect (an arm's own padding by default) and
  /// `robot.base_frame` are in pipeline.robot; `proximity.*` in pipeline.backend and
  /// pipeline.proximity.
  RobotModelType robot_model = RobotModelType::points;
  RobotStateConfig robot_state;          ///< `robot.state.*` and `robot.joints_rad`
  RecordConfig record;                   ///< `record.*`
  PublishConfig publish;                 ///< `publish.*`
  Ros2Config ros2;                       ///< `ros2.*`
  LinkConfig link;                       ///< `link.*`
  CalibrationParams calibration;         ///< `calibration.*`: `hrcsense calibrate` (docs/CALIBRATION.md)
  /// `cameras:`: the cell's cameras (empty: a cell of one camera, the top-level keys).
  std::vector<CameraEntry> cameras;
  /// `--camera NAME`: the entry this configuration was loaded for (its keys laid over the
  /// top-level ones); empty: none.
  std::string camera;
  CellConfig cell;                       ///< `cell.*`
  /// `sim.epoch`: the shared scene clock's frame 0, CLOCK_REALTIME ns (frame i is due at
  /// epoch + i / fps); unset: a simulated camera of a cell takes it from `<ns>/cell_clock`,
  /// any other simulated run starts at frame 0 when it starts.
  std::optional<int64_t> sim_epoch_ns;
  std::string canonical_yaml;      ///< the effective configuration, for the hash in the header
  /// What a person starting the run must hear about this configuration (e.g. ssm without the
  /// robot's stopping data); logged as warnings at the start, one line each.
  std::vector<std::string> warnings;
};

/// `source.latency_s`'s default for cameras (realsense, ros2) and recordings (bag, folder):
/// one exposure and readout at 30 frames/s.
inline constexpr double kCameraLatencyS = 0.033;

/// Reads `path` (may be empty: defaults only) and applies `overrides` ("key.sub=value",
/// value in YAML syntax) in order. Throws ConfigError naming file and key.
/// `camera` non-empty: the `cameras:` entry of that name is laid over the top-level keys
/// (docs/MULTICAMERA.md); an unknown name is a ConfigError listing the entries.
Config load_config(const std::string& path, const std::vector<std::string>& overrides,
                   const std::string& camera = {});

/// `rotation_rpy_deg` of a pose in CONFIG.md's convention, R = Rz(yaw)·Ry(pitch)·Rx(roll): [roll,
/// pitch, yaw] in degrees (pitch in [−90, 90]).
Eigen::Vector3d rotation_rpy_deg(const Pose& pose);

/// The text of a configuration file with one `cameras:` entry's pose replaced (`hrcsense calibrate
/// --camera NAME --write-back`, docs/CALIBRATION.md): the entry `camera`'s T_base_camera
/// translation_m and rotation_rpy_deg lists become `T_base_camera`'s (6 and 5 decimals), every
/// other byte of `yaml_text` (comments, the other entries, the layout) stays. Both lists must be
/// written in flow form ([x, y, z]) inside the entry itself (not through an alias). Throws
/// ConfigError naming `where` and the entry's key when the text does not parse, has no such
/// entry or holds the pose in another form.
std::string with_camera_pose_text(const std::string& yaml_text, const std::string& camera, const Pose& T_base_camera,
                                  const std::string& where);

/// Reads a robot description file (docs/ROBOT.md); throws ConfigError naming the file and the
/// field, e.g. "arm.yaml: key 'links.forearm[1].radius_m': expected a number >= 0".
RobotDescription load_robot_description(const std::string& path);

/// The robot's capsules at the fixed pose robot.joints_rad (robot_model_at), base frame.
RobotModel fixed_robot_model(const Config& config);

/// `--set` overrides (KEY=VALUE) that give a configuration `tuning`: every option of the blocks
/// in tuning.filters.order, foreground.k_sigma, min_margin_m and min_object_mm, and
/// proximity.backend. load_config(file, sets + these) validates them as it validates a file,
/// and its canonical_yaml is a configuration `hrcsense run --config` accepts (hrcsense-view's
/// "save tuned parameters").
std::vector<std::string> tuning_overrides(const LiveTuning& tuning);

/// FNV-1a 64-bit hash of the effective configuration, as 16 hex digits.
std::string config_hash(const Config& config);

}  // namespace hrcsense
