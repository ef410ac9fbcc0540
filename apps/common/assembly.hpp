// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — what both executables (`hrcsense`, `hrcsense-view`) build from a
// configuration: the source, the simulator, the background file, the run header. The
// configuration itself stays plain data (config.hpp); adapters are chosen here, and one that
// this build does not have is a ConfigError saying so.
#pragma once

#include "hrcsense/clock.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/net/link.hpp"
#include "hrcsense/net/rtde.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/sim/sim.hpp"

#include "realsense/realsense_plan.hpp"

#include <atomic>
#include <functional>
#include <memory>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense {

/// What messages call the configuration: its file, or "configuration" when it has none (the
/// defaults and --set alone).
std::string config_where(const Config& config);

/// The configured arm as a static simulator object named "robot": its rendering capsules
/// (robot_render_capsules: the visual body, no padding) at robot.joints_rad in the
/// robot.base_frame frame, so the arm is part of the learnt background. Empty for robot.model
/// points.
std::optional<SceneObject> robot_scene_object(const Config& config);

/// robot.trajectory.follow_link: a new clock for the simulated arm that obeys the link, to share
/// between make_simulator, make_source and make_robot_state_source (and to tell what was sent:
/// TrajectoryClock::sent). Null without it.
std::shared_ptr<TrajectoryClock> make_trajectory_clock(const Config& config);

/// The simulator described by a configuration (sim.*, scene.*, camera pose, robot). With
/// robot.trajectory the arm is the simulator's moving arm (Simulator::arm), not a scene object;
/// with `trajectory_clock` it follows that clock (follow_link), else the frame time.
Simulator make_simulator(const Config& config, std::shared_ptr<TrajectoryClock> trajectory_clock = nullptr);

/// The source the configuration names (source.type); throws ConfigError for a type this
/// build does not have (naming it: realsense without the SDK says how to get it) or a recorded
/// source without source.path. A bag reads its joint states too when robot.state.source is
/// recorded.
struct SourceOptions {
  bool with_color = false;  ///< recorded sources decode their colour frames too (the pipeline does not need them)
  const std::atomic<bool>* stop_requested = nullptr;  ///< ends a live camera's waits while it is unplugged (null: never)
  std::shared_ptr<TrajectoryClock> trajectory_clock;  ///< sim: the arm follows it (make_trajectory_clock)
};
/// A live source that could not start (a ROS 2 camera that never answered, a stop requested
/// while waiting for it): the run still writes a header, a stop and a summary naming it.
class SourceStartError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws ConfigError for what the configuration gets wrong, SourceStartError as above.
std::unique_ptr<Source> make_source(const Config& config, const SourceOptions& options = {});

/// The live camera's parameters from `source.*` (source.type realsense): the SDK adapter is
/// given plain values and never sees the configuration.
RealSenseParams realsense_params(const SourceConfig& source, const std::atomic<bool>* stop_requested);

/// The RealSense cameras connected (`hrcsense devices`); throws ConfigError in a build without
/// the SDK, saying how to get it.
std::vector<DeviceDescriptor> list_cameras();

/// The robot state source (robot.state.source): fixed; sim (SimRobotState on the trajectory,
/// with robot.state.sim_latency_s / sim_jitter_s, seeded by source.seed); rtde; udp_json; ros2
/// (robot.state.ros2.* on ros2.domain_id). Throws ConfigError for one this build does not have
/// (ros2 without Cyclone DDS), for rtde without robot.state.host, and for recorded (it needs
/// the source: the overload below). A live source (rtde, udp_json, ros2) stamps arrivals with `clock` (null: the
/// steady clock, run_pipeline's default); it must outlive the source. `sim` reads the arm's
/// joints at `trajectory_clock`'s time when given (the simulator's, follow_link).
std::unique_ptr<RobotStateSource> make_robot_state_source(const Config& config, RunClock* clock = nullptr,
                                                          std::shared_ptr<TrajectoryClock> trajectory_clock = nullptr);

/// As above, and `recorded`: the joint states of `source`, the BagSource make_source built for
/// the configuration (it reads them as it plays). Throws ConfigError when `source` is no
/// BagSource, IoError naming the file and the topic when the bag has no joint states.
std::unique_ptr<RobotStateSource> make_robot_state_source(const Config& config, Source& source,
                                                          RunClock* clock = nullptr,
                                                          std::shared_ptr<TrajectoryClock> trajectory_clock = nullptr);

/// robot.state.source is a live robot (rtde, udp_json, ros2): in a cell with several cameras the
/// fuser owns it and republishes it on `<ros2.namespace>/joint_states` (docs/MULTICAMERA.md).
bool robot_state_is_live(const Config& config);

/// The `--set` overrides that make a camera process of a cell read the fuser's republished
/// robot state: robot.state.source ros2 on `<ros2.namespace>/joint_states`, and the robot's
/// speed fraction from `<ros2.namespace>/robot_speed_scaling` (robot.state.ros2.speed_scaling_topic,
/// speed_scaling_unit fraction). robot.state.ros2.tf_prefix stays as configured, as the fuser
/// writes the joint names with that prefix. Empty when the robot state is not live.
std::vector<std::string> camera_robot_state_sets(const Config& config);

/// `hrcsense run --camera NAME` of a simulated camera without `sim.epoch`: the configuration
/// with the epoch the fuser publishes on `<ros2.namespace>/cell_clock`, waited for up to
/// `timeout_s`; any other configuration as it is. Throws ConfigError naming the topic and the
/// domain when no valid epoch came (or in a build without Cyclone DDS).
Config with_cell_clock(const Config& config, double timeout_s, const std::atomic<bool>* stop_requested);

/// Loads background.path into `pipeline` when the file exists (checked against the filtered
/// resolution: after decimation); false when there is nothing to load. Throws IoError for a
/// damaged or mismatched file, naming it.
bool load_background_file(const Config& config, const SourceInfo& info, Pipeline& pipeline);

/// Saves the learnt background to background.path (creating its folder); a warning on stderr
/// when learning did not finish. Nothing without background.path.
void save_learnt_background(const Config& config, const Pipeline& pipeline);

/// The link to the robot controller (`link.udp.*`, docs/SAFETY.md): a UdpLinkSink sending to
/// link.udp.address, on `clock` (null: the steady clock, run_pipeline's default; it must
/// outlive the sink); null when link.udp.address is empty. Throws ConfigError naming the file
/// and link.udp.address for an address that is not numeric host:port.
std::unique_ptr<UdpLinkSink> make_udp_link_sink(const Config& config, const RunClock* clock = nullptr);

/// `link.rtde.write` (speed_slider or register): an RtdeLinkSink writing to the controller at
/// robot.state.host:port with its own connection; null for `off`. Throws ConfigError naming
/// the file and the key for a value outside its range (load_config checks them first).
std::unique_ptr<RtdeLinkSink> make_rtde_link_sink(const Config& config, const RunClock* clock = nullptr);

/// What the ROS 2 outputs did: for the fault log while the run goes, and its last line.
struct Ros2OutputsStatus {
  int64_t verdicts = 0;       ///< Verdict samples written
  int64_t marker_arrays = 0;  ///< MarkerArray samples written
  int64_t clouds = 0;         ///< foreground PointCloud2 samples written
  int64_t failed_writes = 0;  ///< writes DDS refused, on any topic
  std::string last_error;     ///< the last of them, naming the topic
};

/// "ROS 2 outputs: N verdicts, M marker arrays, K foreground clouds; F writes refused (last: ...)".
std::string describe_ros2_outputs(const Ros2OutputsStatus& status);

/// `ros2.publish`: the ROS 2 outputs (dds/ros2_outputs.hpp, docs/ROS2.md) as a sink and the
/// processing thread's tap that hands it the foreground cloud.
struct Ros2Outputs {
  std::unique_ptr<Sink> sink;  ///< null without ros2.publish
  /// RunOptions::on_processed for the foreground cloud; null without a sink.
  std::function<void(const Frame&, const Pipeline&, const FrameResult&)> on_processed;
  /// What the outputs have written so far (call on the output thread or after the run); null
  /// without a sink.
  std::function<Ros2OutputsStatus()> status;
};

/// The outputs of ros2.* (domain, namespace, cloud rate, speed scaling topic, camera name) in
/// robot.base_frame, with camera.T_base_camera on /tf_static and the verdict's deadline from
/// safety.max_frame_gap_periods / max_frame_age_s; with source.type ros2 the camera's own
/// link → optical chain is read from its /tf_static first (up to 2 s). Logs what it publishes.
/// Empty without ros2.publish; throws ConfigError in a build without Cyclone DDS, saying so.
/// A camera of a cell (config.camera set) publishes none of these (the fuser does), only its
/// previews for a viewer: its foreground cloud (at most ros2.cloud_hz) and a depth preview
/// decimated by ros2.preview_decimation (at most ros2.preview_hz), dds/camera_previews.hpp.
Ros2Outputs make_ros2_output_sink(const Config& config);

/// `hrcsense run --camera NAME` (config.camera set): the camera's measurements on
/// `<ros2.namespace>/measurement/<NAME>` (dds/measurement_endpoints.hpp, docs/MULTICAMERA.md),
/// with the entry's rate and pose. Throws ConfigError in a build without Cyclone DDS.
std::unique_ptr<Sink> make_measurement_sink(const Config& config);

/// What an RTDE link did, as one line for the log.
std::string describe_link_counters(const RtdeLinkSink& link);

/// What a link sent, as one line for the log: "link to ADDRESS: N frames, M heartbeats, ...".
std::string describe_link_counters(const UdpLinkSink& link);

/// The JSON Lines header of a run: config hash, source, filters (with a note when a chain that
/// asks for disparity runs on depth). Version and commit are the sink's.
RunHeader make_run_header(const Config& config, const SourceInfo& info);

}  // namespace hrcsense
