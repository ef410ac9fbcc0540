// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — sources, the simulator, the robot state and the background file from a
// configuration.
#include "common/assembly.hpp"

#include "hrcsense/io/io.hpp"
#include "hrcsense/net/link.hpp"
#include "hrcsense/recordings/recordings.hpp"
#include "hrcsense/net/rtde.hpp"
#include "hrcsense/session.hpp"
#include "hrcsense/net/udp_json.hpp"

#if HRCSENSE_HAVE_DDS
#include "dds/camera_previews.hpp"
#include "dds/measurement_endpoints.hpp"
#include "dds/ros2_camera_source.hpp"
#include "dds/ros2_cell_clock.hpp"
#include "dds/ros2_joint_state_writer.hpp"
#include "dds/ros2_joint_state_source.hpp"
#include "dds/ros2_outputs.hpp"
#endif
#ifdef HRCSENSE_HAVE_REALSENSE
#include "realsense/realsense_source.hpp"
#endif

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

namespace hrcsense {

std::optional<SceneObject> robot_scene_object(const Config& config) {
  const RobotParams& robot = config.pipeline.robot;
  if (!robot.arm) return std::nullopt;
  SceneObject arm;
  arm.name = "robot";
  arm.is_static = true;
  const RobotModel rendered = robot_render_capsules(*robot.arm, config.robot_state.joints_rad, robot.base_frame);
  for (const Capsule& capsule : rendered.capsules) {
    if (capsule.radius_m <= 0.0F) continue;  // a bare segment has no surface to see
    Shape shape;
    shape.type = Shape::Type::capsule;
    shape.a = capsule.a;
    shape.b = capsule.b;
    shape.radius_m = capsule.radius_m;
    arm.shapes.push_back(shape);
  }
  return arm;
}

std::shared_ptr<TrajectoryClock> make_trajectory_clock(const Config& config) {
  const bool follows = config.robot_state.trajectory && config.robot_state.trajectory->follow_link;
  return follows ? std::make_shared<TrajectoryClock>() : nullptr;
}

Simulator make_simulator(const Config& config, std::shared_ptr<TrajectoryClock> trajectory_clock) {
  Simulator simulator;
  simulator.params = config.sim;
  simulator.scene = config.scene;
  // The true pose renders; the pipeline keeps the one it is told (they differ only on request).
  simulator.T_base_camera = config.sim_camera_T_base_camera.value_or(config.pipeline.T_base_camera);
  simulator.camera_knock = config.sim_camera_knock;
  simulator.params.epoch_ns = config.sim_epoch_ns;  // the shared scene clock (sim.epoch)
  simulator.robot = fixed_robot_model(config);
  if (config.robot_state.trajectory) {
    // A moving arm: rendered at each frame's time with its own label (robot.trajectory).
    simulator.arm = SimArm{config.pipeline.robot, *config.robot_state.trajectory, std::nullopt, std::move(trajectory_clock)};
    return simulator;
  }
  // A fixed arm is part of the static scene: rendered, learnt as background, never foreground.
  if (auto arm = robot_scene_object(config)) simulator.scene.objects.push_back(*arm);
  return simulator;
}

std::string config_where(const Config& config) { return config.file.empty() ? "configuration" : config.file; }

namespace {

// source.type ros2: realsense-ros topics over Cyclone DDS (docs/CAMERAS.md).
std::unique_ptr<Source> make_ros2_source([[maybe_unused]] const Config& config,
                                         [[maybe_unused]] const SourceOptions& options,
                                         [[maybe_unused]] const std::string& where) {
#if HRCSENSE_HAVE_DDS
  const Ros2SourceConfig& ros2 = config.source.ros2;
  ros2::Ros2SourceParams params;
  params.topics = ros2::realsense_topics(ros2.node_namespace);
  if (!ros2.depth_topic.empty()) {
    params.topics.depth_image = ros2.depth_topic;
    params.topics.depth_info = ros2::camera_info_topic(ros2.depth_topic);
  }
  if (!ros2.color_topic.empty()) {
    params.topics.color_image = ros2.color_topic;
    params.topics.color_info = ros2::camera_info_topic(ros2.color_topic);
  }
  if (!ros2.extrinsics_topic.empty()) params.topics.extrinsics = ros2.extrinsics_topic;
  params.color = ros2.color;
  params.domain_id = static_cast<uint32_t>(ros2.domain_id);
  params.startup_timeout_s = ros2.startup_timeout_s;
  params.stereo_baseline_mm = config.source.stereo_baseline_mm;
  params.stop_requested = options.stop_requested;
  try {
    return std::make_unique<ros2::Ros2CameraSource>(params);
  } catch (const ros2::Ros2StartupError& e) {
    throw SourceStartError(e.what());
  }
#else
  throw ConfigError(where + ": source.type 'ros2': this hrcsense was built without Cyclone DDS; install "
                    "cyclonedds-dev and cyclonedds-tools (scripts/setup does) and rebuild");
#endif
}

}  // namespace

RealSenseParams realsense_params(const SourceConfig& source, const std::atomic<bool>* stop_requested) {
  RealSenseParams params;
  params.serial = source.serial;
  params.width = source.width;
  params.height = source.height;
  params.fps = source.fps;
  params.color = source.color.enabled;
  params.color_width = source.color.width;
  params.color_height = source.color.height;
  params.color_fps = source.color.fps;
  for (const CameraOption& option : source.options) params.options.push_back({option.name, option.value});
  params.settle_frames = source.settle_frames;
  params.path = source.path;
  params.loop = source.loop;
  params.stop_requested = stop_requested;
  return params;
}

std::unique_ptr<Source> make_source(const Config& config, const SourceOptions& options) {
  const std::string where = config_where(config);
  const SourceType type = config.source.type;
  switch (type) {
    case SourceType::sim: return std::make_unique<SimSource>(make_simulator(config, options.trajectory_clock));
    case SourceType::folder:  // is_recording
    case SourceType::bag: {
      if (config.source.path.empty()) {
        throw ConfigError(where + ": source.path: required for source.type " + source_type_name(type));
      }
      RecordingParams params{config.source.path, config.source.loop, config.source.stereo_baseline_mm};
      params.with_color = options.with_color;
      if (type == SourceType::folder) return std::make_unique<FolderSource>(params);
      // make_robot_state_source takes them
      params.with_joint_states = config.robot_state.source == RobotStateOrigin::recorded;
      return std::make_unique<BagSource>(params);
    }
    case SourceType::ros2: return make_ros2_source(config, options, where);
    case SourceType::realsense:
#ifdef HRCSENSE_HAVE_REALSENSE
      return std::make_unique<RealSenseSource>(realsense_params(config.source, options.stop_requested));
#else
      throw ConfigError(realsense_missing_message(where + ": source.type 'realsense'"));
#endif
  }
  // The configuration knows every type; the live adapters are optional targets.
  throw ConfigError(where + ": source.type '" + source_type_name(type) + "': not built into this hrcsense");
}

std::vector<DeviceDescriptor> list_cameras() {
#ifdef HRCSENSE_HAVE_REALSENSE
  return list_realsense_devices();
#else
  throw ConfigError(realsense_missing_message("hrcsense devices"));
#endif
}

namespace {

// What every robot state source keeps its samples under: robot.state.max_age_s and, with an
// arm, its joint limits, so that no source takes a pose the arm cannot have.
RobotStateHistoryParams robot_state_history_params(const Config& config) {
  RobotStateHistoryParams params = config.robot_state.history;
  if (const std::optional<RobotDescription>& arm = config.pipeline.robot.arm) {
    for (size_t j = 0; j < kJointCount; ++j) {
      params.q_min_rad[j] = arm->limits[j].min_rad;
      params.q_max_rad[j] = arm->limits[j].max_rad;
    }
  }
  return params;
}

// robot.state.source ros2: a ROS 2 driver's /joint_states over Cyclone DDS (docs/ROS2.md).
std::unique_ptr<RobotStateSource> make_ros2_robot_state_source([[maybe_unused]] const Config& config,
                                                               [[maybe_unused]] RunClock& clock,
                                                               [[maybe_unused]] const std::string& where) {
#if HRCSENSE_HAVE_DDS
  const Ros2JointStateConfig& ros2 = config.robot_state.ros2;
  ros2::Ros2JointStateParams params;
  params.topic = ros2.topic;
  params.tf_prefix = ros2.tf_prefix;
  params.speed_scaling_topic = ros2.speed_scaling_topic;
  params.speed_scaling_unit = ros2.speed_scaling_unit;
  params.domain_id = static_cast<uint32_t>(config.ros2.domain_id);
  params.history = robot_state_history_params(config);
  return std::make_unique<ros2::Ros2JointStateSource>(params, clock);
#else
  throw ConfigError(where + ": robot.state.source 'ros2': this hrcsense was built without Cyclone DDS; install "
                    "cyclonedds-dev and cyclonedds-tools (scripts/setup does) and rebuild");
#endif
}

}  // namespace

std::unique_ptr<RobotStateSource> make_robot_state_source(const Config& config, RunClock* clock,
                                                          std::shared_ptr<TrajectoryClock> trajectory_clock) {
  const RobotStateConfig& state = config.robot_state;
  const RobotStateOrigin source = state.source;
  if (source == RobotStateOrigin::fixed) return std::make_unique<FixedRobotState>(state.joints_rad);
  const std::string where = config_where(config);
  if (source == RobotStateOrigin::sim) {
    // Config requires the trajectory with the sim source; checked again for a hand-made Config.
    if (!config.robot_state.trajectory) throw ConfigError(where + ": robot.trajectory: required for robot.state.source sim");
    SimRobotState::Params params;
    params.latency_s = config.robot_state.sim_latency_s;
    params.jitter_s = config.robot_state.sim_jitter_s;
    params.seed = config.sim.seed;  // source.seed
    params.history = robot_state_history_params(config);
    params.clock = std::move(trajectory_clock);
    params.epoch_ns = config.sim_epoch_ns;  // the frames' host times are on the scene clock then
    return std::make_unique<SimRobotState>(*config.robot_state.trajectory, params);
  }
  // Arrival times on the run's clock: the steady clock, run_pipeline's default (RunOptions::clock
  // null), unless the caller passes its own. SteadyClock has no state, so one shared instance
  // reads the same time as the run's.
  static SteadyClock steady_clock;
  RunClock& run_clock = clock != nullptr ? *clock : steady_clock;
  if (source == RobotStateOrigin::udp_json) {
    UdpJsonParams params;
    params.listen = state.listen;
    params.history = robot_state_history_params(config);
    // A bind failure (port in use, address not local) is a runtime error naming the key and
    // the address; an address that is no numeric host:port is the configuration's error.
    try {
      return std::make_unique<UdpJsonRobotState>(params, run_clock);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(where + ": " + e.what());
    }
  }
  if (source == RobotStateOrigin::rtde) {
    if (state.host.empty()) throw ConfigError(where + ": robot.state.host: required for robot.state.source rtde");
    RtdeParams params;
    params.host = state.host;
    params.port = state.port;
    params.frequency_hz = state.frequency_hz;
    params.history = robot_state_history_params(config);
    params.arm = config.pipeline.robot.arm;  // the forward kinematics actual_TCP_pose is checked against
    return std::make_unique<RtdeRobotState>(params, run_clock);
  }
  if (source == RobotStateOrigin::ros2) return make_ros2_robot_state_source(config, run_clock, where);
  if (source == RobotStateOrigin::recorded) {
    throw ConfigError(where + ": robot.state.source recorded: the joint states come from the recording (source.type bag)");
  }
  throw ConfigError(where + ": robot.state.source '" + robot_state_origin_name(source) +
                    "': not built into this hrcsense");
}

std::unique_ptr<RobotStateSource> make_robot_state_source(const Config& config, Source& source, RunClock* clock,
                                                          std::shared_ptr<TrajectoryClock> trajectory_clock) {
  if (config.robot_state.source != RobotStateOrigin::recorded) {
    return make_robot_state_source(config, clock, std::move(trajectory_clock));
  }
  const std::string where = config_where(config);
  const auto* bag = dynamic_cast<const BagSource*>(&source);
  if (bag == nullptr) {
    throw ConfigError(where + ": robot.state.source recorded: needs source.type bag (a recording made by hrcsense), not " +
                      source_type_name(config.source.type));
  }
  std::unique_ptr<RobotStateSource> states = bag->recorded_robot_state();
  if (!states) {
    throw IoError(config.source.path + ": no robot joint states (topic /hrcsense/joint_states), which robot.state.source "
                  "recorded needs: record with hrcsense record or hrcsense run --record");
  }
  return states;
}

bool robot_state_is_live(const Config& config) {
  const RobotStateOrigin source = config.robot_state.source;
  return source == RobotStateOrigin::rtde || source == RobotStateOrigin::udp_json || source == RobotStateOrigin::ros2;
}

std::vector<std::string> camera_robot_state_sets(const Config& config) {
  if (!robot_state_is_live(config)) return {};
  // The key names of load_config; the topics are what the fuser's writers use
  // (cell_joint_states_topic, cell_robot_speed_scaling_topic), spelled here too for a build
  // without DDS, where nothing runs. The fuser writes the speed as a fraction, 0..1.
  const std::string& ns = config.ros2.node_namespace;
  return {"robot.state.source=ros2", "robot.state.ros2.topic=" + ns + "/joint_states",
          "robot.state.ros2.speed_scaling_topic=" + ns + "/robot_speed_scaling",
          "robot.state.ros2.speed_scaling_unit=fraction"};
}

Config with_cell_clock(const Config& config, [[maybe_unused]] double timeout_s,
                       [[maybe_unused]] const std::atomic<bool>* stop_requested) {
  if (config.camera.empty() || config.source.type != SourceType::sim || config.sim_epoch_ns) return config;
#if HRCSENSE_HAVE_DDS
  Config joined = config;
  try {
    joined.sim_epoch_ns = ros2::wait_for_cell_clock(static_cast<uint32_t>(config.ros2.domain_id),
                                                    config.ros2.node_namespace, timeout_s, stop_requested);
  } catch (const ros2::Ros2Error& e) {
    throw ConfigError(config_where(config) + ": --camera " + config.camera + " without sim.epoch: " + e.what());
  }
  spdlog::info("camera '{}': the scene clock's epoch {:.3f} s from {}", config.camera,
               static_cast<double>(*joined.sim_epoch_ns) * 1e-9, ros2::cell_clock_topic(config.ros2.node_namespace));
  return joined;
#else
  throw ConfigError(config_where(config) + ": --camera " + config.camera + " of a simulated cell without sim.epoch: "
                    "this hrcsense was built without Cyclone DDS to read the fuser's cell_clock; set sim.epoch");
#endif
}

bool load_background_file(const Config& config, const SourceInfo& info, Pipeline& pipeline) {
  if (config.background_path.empty() || !std::filesystem::exists(config.background_path)) return false;
  BackgroundModel model = load_background(config.background_path);  // IoError: damaged file
  // The background is at the filtered resolution (after decimation), not the source's.
  const Intrinsics filtered = filtered_intrinsics(config.pipeline.filters, info.intrinsics);
  if (model.width != filtered.width || model.height != filtered.height) {
    throw IoError(config.background_path + ": background is " + std::to_string(model.width) + "x" +
                  std::to_string(model.height) + " but the filtered source is " + std::to_string(filtered.width) +
                  "x" + std::to_string(filtered.height) + " (filters.preset " +
                  filter_preset_name(config.filters_preset) + ")");
  }
  pipeline.set_background(std::move(model), "background.path '" + config.background_path + "'");
  return true;
}

void save_learnt_background(const Config& config, const Pipeline& pipeline) {
  if (config.background_path.empty()) return;
  if (!pipeline.background_ready()) {
    spdlog::warn("background not saved to {}: learning did not finish", config.background_path);
    return;
  }
  const std::filesystem::path parent = std::filesystem::path(config.background_path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  save_background(config.background_path, pipeline.background());
  spdlog::info("background saved to {}", config.background_path);
}

std::unique_ptr<UdpLinkSink> make_udp_link_sink(const Config& config, const RunClock* clock) {
  const LinkConfig& link = config.link;
  if (link.udp_address.empty()) return nullptr;
  static SteadyClock steady_clock;  // stateless: reads the same time as the run's
  UdpLinkParams params;
  params.address = link.udp_address;
  params.format = link.udp_format == UdpFormat::json ? UdpLinkParams::Format::json : UdpLinkParams::Format::binary;
  params.heartbeat_hz = link.heartbeat_hz;
  params.backend = proximity_backend_name(config.pipeline.backend);
  try {
    return std::make_unique<UdpLinkSink>(params, clock != nullptr ? *clock : steady_clock);
  } catch (const std::invalid_argument& e) {
    // The message names link.udp.address (or link.heartbeat_hz); add the file.
    throw ConfigError(config_where(config) + ": " + e.what());
  }
}

std::unique_ptr<RtdeLinkSink> make_rtde_link_sink(const Config& config, const RunClock* clock) {
  const LinkConfig& link = config.link;
  if (link.rtde_write == RtdeWrite::off) return nullptr;
  const std::string where = config_where(config);
  if (config.robot_state.host.empty()) {
    throw ConfigError(where + ": link.rtde.write: needs the controller's address robot.state.host");
  }
  static SteadyClock steady_clock;
  RtdeLinkParams params;
  params.host = config.robot_state.host;
  params.port = config.robot_state.port;
  params.mode = link.rtde_write == RtdeWrite::speed_slider ? RtdeLinkParams::Mode::speed_slider
                                                           : RtdeLinkParams::Mode::input_register;
  params.register_index = link.rtde_register;
  params.min_speed_slider = link.rtde_min_speed_slider;
  params.heartbeat_hz = link.heartbeat_hz;
  try {
    return std::make_unique<RtdeLinkSink>(params, clock != nullptr ? *clock : steady_clock);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(where + ": " + e.what());
  }
}

namespace {

#if HRCSENSE_HAVE_DDS
// `run --camera NAME` with ros2.publish: no verdict, markers or TF of its own (the fuser
// publishes those), only what a viewer shows of the camera: its cloud and a depth preview.
Ros2Outputs make_camera_preview_outputs(const Config& config) {
  const Ros2Config& ros2 = config.ros2;
  ros2::CameraPreviewParams params;
  params.domain_id = static_cast<uint32_t>(ros2.domain_id);
  params.node_namespace = ros2.node_namespace;
  params.camera_name = config.camera;
  params.base_frame = ros2::base_frame_id(config.pipeline.robot.base_frame);
  params.cloud_hz = ros2.cloud_hz;
  params.preview_hz = ros2.preview_hz;
  params.decimation = ros2.preview_decimation;
  std::unique_ptr<ros2::CameraPreviewSink> sink;
  try {
    sink = std::make_unique<ros2::CameraPreviewSink>(params);
  } catch (const ros2::Ros2Error& e) {
    throw ConfigError(config_where(config) + ": --camera " + config.camera + ": " + e.what());
  }
  const int width = config.source.width / std::max(ros2.preview_decimation, 1);
  const int height = config.source.height / std::max(ros2.preview_decimation, 1);
  spdlog::info("camera '{}': previews on {} (base frame, at most {:g} Hz) and {} ({}x{} 16UC1 at most {:g} Hz: {:.0f} kB/s)",
               config.camera, sink->topics().foreground, ros2.cloud_hz, sink->topics().depth_preview, width, height,
               ros2.preview_hz, static_cast<double>(ros2::depth_preview_bytes(width, height)) * ros2.preview_hz * 1e-3);
  Ros2Outputs outputs;
  outputs.on_processed = [tap = sink.get()](const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
    tap->on_processed(frame, pipeline, result);
  };
  outputs.status = [view = sink.get()] {
    const ros2::CameraPreviewCounters c = view->counters();
    return Ros2OutputsStatus{0, 0, c.clouds, c.failed_writes, c.last_error};
  };
  outputs.sink = std::move(sink);
  return outputs;
}
#endif

}  // namespace

Ros2Outputs make_ros2_output_sink(const Config& config) {
  const Ros2Config& ros2 = config.ros2;
  if (!ros2.publish) return {};
#if HRCSENSE_HAVE_DDS
  if (!config.camera.empty()) return make_camera_preview_outputs(config);
  ros2::Ros2OutputParams params;
  params.domain_id = static_cast<uint32_t>(ros2.domain_id);
  params.node_namespace = ros2.node_namespace;
  params.speed_scaling_topic = ros2.speed_scaling_topic;
  params.cloud_hz = ros2.cloud_hz;
  params.camera_name = ros2.camera_name;
  params.base_frame = ros2::base_frame_id(config.pipeline.robot.base_frame);
  params.T_base_camera = config.pipeline.T_base_camera;
  params.robot = config.pipeline.robot;
  params.max_frame_gap_periods = config.pipeline.safety.max_frame_gap_periods;
  params.max_frame_age_s = config.pipeline.safety.max_frame_age_s;
  // realsense-ros publishes its link → optical frames itself: a second parent is never given.
  params.camera_publishes_optical = config.source.type == SourceType::ros2;
  params.camera_domain_id = static_cast<uint32_t>(config.source.ros2.domain_id);
  auto sink = std::make_unique<ros2::Ros2OutputSink>(params);
  const ros2::Ros2OutputTopics& topics = sink->topics();
  std::string frames = sink->tf_static_edges().empty() ? "none" : "";
  for (const ros2::TfEdge& edge : sink->tf_static_edges()) {
    frames += (frames.empty() ? "" : ", ") + edge.parent_frame + " → " + edge.child_frame;
  }
  const std::string clouds = ros2.cloud_hz > 0.0 ? fmt::format("at most {:g} Hz", ros2.cloud_hz) : std::string("off");
  spdlog::info("ROS 2 outputs on domain {} under {} (verdict, speed scaling on {}, markers, foreground {}, /tf_static "
               "{}; frame {})",
               ros2.domain_id, ros2.node_namespace, topics.speed_scaling, clouds, frames, params.base_frame);
  if (!sink->camera_tf_note().empty()) spdlog::warn("ROS 2 outputs: {}", sink->camera_tf_note());
  Ros2Outputs outputs;
  outputs.on_processed = [tap = sink.get()](const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
    tap->on_processed(frame, pipeline, result);
  };
  outputs.status = [view = sink.get()] {
    const ros2::Ros2OutputCounters c = view->counters();
    return Ros2OutputsStatus{c.verdicts, c.marker_arrays, c.clouds, c.failed_writes, c.last_error};
  };
  outputs.sink = std::move(sink);
  return outputs;
#else
  throw ConfigError(config_where(config) + ": ros2.publish: this hrcsense was built without Cyclone DDS; install "
                    "cyclonedds-dev and cyclonedds-tools (scripts/setup does) and rebuild");
#endif
}

std::unique_ptr<Sink> make_measurement_sink(const Config& config) {
#if HRCSENSE_HAVE_DDS
  ros2::MeasurementWriterParams params;
  params.domain_id = static_cast<uint32_t>(config.ros2.domain_id);
  params.node_namespace = config.ros2.node_namespace;
  params.camera_name = config.camera;
  params.base_frame = ros2::base_frame_id(config.pipeline.robot.base_frame);
  params.T_base_camera = config.pipeline.T_base_camera;
  params.max_frame_gap_periods = config.pipeline.safety.max_frame_gap_periods;
  for (const CameraEntry& entry : config.cameras) {
    if (entry.name == config.camera) params.nominal_fps = entry.fps;
  }
  try {
    auto sink = std::make_unique<ros2::MeasurementSink>(params);
    spdlog::info("camera '{}': measurements on {} (domain {}); no verdict is sent from here", config.camera, sink->topic(),
                 config.ros2.domain_id);
    return sink;
  } catch (const ros2::Ros2Error& e) {
    throw ConfigError(config_where(config) + ": --camera " + config.camera + ": " + e.what());
  }
#else
  throw ConfigError(config_where(config) + ": --camera: this hrcsense was built without Cyclone DDS; install "
                    "cyclonedds-dev and cyclonedds-tools (scripts/setup does) and rebuild");
#endif
}

std::string describe_ros2_outputs(const Ros2OutputsStatus& status) {
  std::string text = "ROS 2 outputs: " + std::to_string(status.verdicts) + " verdicts, " +
                     std::to_string(status.marker_arrays) + " marker arrays, " + std::to_string(status.clouds) +
                     " foreground clouds; " + std::to_string(status.failed_writes) + " writes refused";
  if (!status.last_error.empty()) text += " (last: " + status.last_error + ")";
  return text;
}

std::string describe_link_counters(const RtdeLinkSink& link) {
  const RtdeLinkCounters c = link.counters();
  std::string text = "RTDE link (" + link.input_names() + "): " + std::to_string(c.writes) + " writes (" +
                     std::to_string(c.stop_writes) + " stops) over " + std::to_string(c.streaming) + " of " +
                     std::to_string(c.connections) + " connections; " + std::to_string(c.disconnects) +
                     " lost, " + std::to_string(c.refusals) + " refused, " + std::to_string(c.malformed) +
                     " malformed replies";
  if (!c.last_problem.empty()) text += " (last: " + c.last_problem + ")";
  return text;
}

std::string describe_link_counters(const UdpLinkSink& link) {
  const UdpLinkCounters c = link.counters();
  std::string text = "link to " + link.address() + ": " + std::to_string(c.frames) + " frames, " +
                     std::to_string(c.heartbeats) + " heartbeats, " + std::to_string(c.final_stops) +
                     " final stop sent; " + std::to_string(c.send_errors) + " send errors";
  if (!c.last_error.empty()) text += " (last: " + c.last_error + ")";
  return text;
}

RunHeader make_run_header(const Config& config, const SourceInfo& info) {
  RunHeader header;
  header.config_hash = config_hash(config);
  header.session = process_session();  // the link's datagrams carry the same (UdpLinkParams::session 0)
  header.source = info;
  header.robot_state = robot_state_origin_name(config.robot_state.source);
  if (config.pipeline.safety.mode == SafetyParams::Mode::ssm) {
    header.stopping_data = stopping_data_name(config.pipeline.safety.ssm.stopping_data);
  }
  if (config.robot_state.source == RobotStateOrigin::rtde) {
    header.robot_state_reports.push_back("robot_status");
    if (config.pipeline.robot.arm) header.robot_state_reports.push_back("tcp_pose_check");
  }
  RunHeader::Filters& filters = header.filters;
  const FilterChainParams& chain = config.pipeline.filters;
  filters.preset = filter_preset_name(config.filters_preset);
  filters.domain = filter_domain(chain, info.stereo_baseline_mm);
  const bool wants_disparity =
      has_block(chain.order, FilterBlock::to_disparity);
  if (wants_disparity && filters.domain == "depth") {
    filters.note = "no stereo baseline: to_disparity/to_depth skipped, spatial and temporal run on depth "
                   "(set source.stereo_baseline_mm)";
  }
  filters.intrinsics = filtered_intrinsics(chain, info.intrinsics);
  return header;
}

}  // namespace hrcsense
