// SPDX-License-Identifier: Apache-2.0
// hrcsense config — load_config: the YAML file, then --set overrides, then one typed read
// per key into the stages' parameter structs (the table is read_all below).
#include "cameras_config.hpp"
#include "key_reader.hpp"
#include "robot_config.hpp"
#include "yaml_tree.hpp"

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <limits>
#include <optional>

namespace hrcsense {
namespace {

using config_detail::Bound;
using config_detail::KeyReader;

using config_detail::kMaxCoordinateM;
/// Simulated frames: a year at 30 frames/s; with sim.fps >= 1 every timestamp (index · 1e9 /
/// fps ns) stays below 1e18, inside int64.
constexpr int64_t kMaxSimFrames = 1'000'000'000;
/// Stereo baselines: 0 (unknown) or 1 mm to 1 m (the D435's is 50 mm, the D455's 95 mm).
constexpr float kMinBaselineMm = 1.0F;
constexpr float kMaxBaselineMm = 1000.0F;
/// The watchdog (safety.max_frame_age_s): at least 1 ms (below that it fires between any
/// camera's frames and floods the output) and at most 60 s (a watchdog that waits longer is no
/// watchdog; larger values once overflowed a clock conversion).
constexpr double kMinFrameAgeS = 0.001;
constexpr double kMaxFrameAgeS = 60.0;

Pose pose_from_rpy(const Eigen::Vector3f& translation_m, const Eigen::Vector3f& rpy_deg) {
  const Eigen::Vector3d rpy_rad = rpy_deg.cast<double>() * (kPi / 180.0);
  // R = Rz(yaw) · Ry(pitch) · Rx(roll): roll about x first, then pitch, then yaw (fixed axes).
  const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(rpy_rad.z(), Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(rpy_rad.y(), Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(rpy_rad.x(), Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  Pose pose = Pose::Identity();
  pose.linear() = rotation;
  pose.translation() = translation_m.cast<double>();
  return pose;
}

// A pose in camera.T_base_camera's form below `key` ({translation_m, rotation_rpy_deg}), both
// parts required (a true pose half taken from elsewhere would be a guess); nullopt when neither
// is given. An absent pose stays out of the effective configuration, so that configurations
// without it keep their hash.
std::optional<Pose> read_optional_pose(KeyReader& r, const std::string& key) {
  const std::string translation_key = key + ".translation_m";
  const std::string rotation_key = key + ".rotation_rpy_deg";
  const bool has_translation = r.raw(translation_key).IsDefined();
  const bool has_rotation = r.raw(rotation_key).IsDefined();
  if (!has_translation && !has_rotation) return std::nullopt;
  if (!has_translation || !has_rotation) {
    r.fail(key, "expected both translation_m and rotation_rpy_deg, e.g. {translation_m: [0, 0, 1.5], "
                "rotation_rpy_deg: [0, 0, 0]}");
  }
  Eigen::Vector3f translation_m = Eigen::Vector3f::Zero();
  Eigen::Vector3f rpy_deg = Eigen::Vector3f::Zero();
  r.vec3(translation_key, translation_m, kMaxCoordinateM);
  r.vec3(rotation_key, rpy_deg, 360.0F);
  return pose_from_rpy(translation_m, rpy_deg);
}

// The simulated camera's true pose and its knock (docs/SIMULATOR.md, "A camera pose hrcsense is
// not told"). Absent keys leave the effective configuration as it was.
void read_sim_camera(KeyReader& r, Config& c) {
  c.sim_camera_T_base_camera = read_optional_pose(r, "sim.camera_T_base_camera");
  const std::string frame_key = "sim.camera_knock_frame";
  const std::string pose_key = "sim.camera_knock_T_base_camera";
  if (r.raw(frame_key).IsDefined()) r.integer(frame_key, c.sim_camera_knock.frame, -1, kMaxSimFrames);
  const std::optional<Pose> knocked = read_optional_pose(r, pose_key);
  if (c.sim_camera_knock.frame >= 0 && !knocked) {
    r.fail_pair(frame_key, pose_key, "a knock needs the pose the camera is knocked to");
  }
  if (c.sim_camera_knock.frame < 0 && knocked) {
    r.fail_pair(frame_key, pose_key, "a knocked pose needs the frame of the knock (an integer >= 0)");
  }
  if (knocked) c.sim_camera_knock.T_base_camera = *knocked;
}

[[noreturn]] void not_implemented(const KeyReader& r, const std::string& key, const std::string& value,
                                  const std::string& use) {
  throw ConfigError(r.where() + ": " + key + " '" + value + "' is not implemented yet; use " + use);
}

void read_source_and_sim(KeyReader& r, Config& c) {
  constexpr SourceType kSourceTypes[] = {SourceType::sim, SourceType::folder, SourceType::bag, SourceType::realsense,
                                         SourceType::ros2};
  r.choice("source.type", c.source.type, kSourceTypes, source_type_name);
  // The simulator renders at its stamp; a camera saw the scene up to an exposure earlier.
  c.source.latency_s = c.source.type == SourceType::sim ? 0.0 : kCameraLatencyS;
  r.number_in("source.latency_s", c.source.latency_s, 0.0, 1.0, " s");
  r.text("source.path", c.source.path);
  r.flag("source.pace", c.source.pace);
  r.flag("source.loop", c.source.loop);
  r.integer("source.seed", c.sim.seed);  // the simulator's noise and the sim robot state's jitter
  r.number("source.stereo_baseline_mm", c.source.stereo_baseline_mm, Bound::non_negative, kMaxBaselineMm);
  // A baseline of 1e-39 mm would make the stereo noise model infinite: nothing would be foreground.
  if (c.source.stereo_baseline_mm > 0.0F && c.source.stereo_baseline_mm < kMinBaselineMm) {
    r.fail("source.stereo_baseline_mm", "expected 0 (unknown) or a baseline in [1, 1000] mm, got " +
                                            config_detail::float_text(c.source.stereo_baseline_mm));
  }
  config_detail::read_camera_source(r, c.source);  // src/config/camera_config.cpp

  // The sensor first: its preset fills the effects, and every sim.* key given overrides it.
  SimSensor sensor = c.sim.sensor;
  constexpr SimSensor kSensors[] = {SimSensor::d435, SimSensor::structured_light};
  r.choice("sim.sensor", sensor, kSensors, sim_sensor_name);
  apply_sim_sensor(sensor, c.sim);
  r.integer("sim.width", c.sim.width, 1, 65535);
  r.integer("sim.height", c.sim.height, 1, 65535);
  const std::string size = std::to_string(c.sim.width) + "x" + std::to_string(c.sim.height);
  if (c.sim.sensor == SimSensor::d435 && !d435_depth_intrinsics(c.sim.width, c.sim.height)) {
    r.fail_pair("sim.width", "sim.height", size + " is not a D435 depth resolution; expected 1280x720, 848x480, "
                                          "640x480, 640x360, 480x270 or 424x240");
  }
  if (c.sim.sensor == SimSensor::structured_light && !structured_light_intrinsics(c.sim.width, c.sim.height)) {
    r.fail_pair("sim.width", "sim.height", size + " is not a structured_light depth resolution; expected 640x480, "
                                          "320x240, 160x120 or a D435 one (1280x720, 848x480, 640x360, 480x270, "
                                          "424x240)");
  }
  r.number_in("sim.fps", c.sim.fps, 1.0, 1000.0, " frames/s");
  r.integer("sim.frames", c.sim.frames, 1, kMaxSimFrames);
  r.flag("sim.noise", c.sim.noise);
  // Beyond 10 px of noise the simulated depth is meaningless, and the quantiser's counts overflow.
  r.number("sim.disparity_noise_px", c.sim.disparity_noise_px, Bound::non_negative, 10.0F);
  r.number("sim.baseline_mm", c.sim.baseline_mm, Bound::positive, kMaxBaselineMm);
  if (c.sim.baseline_mm < kMinBaselineMm) {
    r.fail("sim.baseline_mm", "expected a baseline in [1, 1000] mm, got " + config_detail::float_text(c.sim.baseline_mm));
  }
  config_detail::read_sim_effects(r, c.sim);
  read_sim_camera(r, c);

  const YAML::Node objects = r.raw("scene.objects");
  c.scene = config_detail::read_scene_objects(objects, r.where(), "scene.objects");
  r.set_effective("scene.objects", config_detail::scene_objects_node(c.scene));
}

void read_camera_and_filters(KeyReader& r, Config& c) {
  Eigen::Vector3f translation_m = c.pipeline.T_base_camera.translation().cast<float>();
  Eigen::Vector3f rpy_deg = Eigen::Vector3f::Zero();
  r.vec3("camera.T_base_camera.translation_m", translation_m, kMaxCoordinateM);
  r.vec3("camera.T_base_camera.rotation_rpy_deg", rpy_deg, 360.0F);
  c.pipeline.T_base_camera = pose_from_rpy(translation_m, rpy_deg);

  config_detail::read_filters(r, c);
}

void read_segmentation(KeyReader& r, Config& c) {
  BackgroundParams& bg = c.pipeline.background;
  r.integer("background.frames", bg.frames, 1, std::numeric_limits<int>::max());
  r.text("background.path", c.background_path);
  // Only named here: the file is read at start (a missing or damaged one is an error there), so
  // that `hrcsense teach` can write the reference a configuration already names.
  r.text("background.reference", c.background_reference);
  r.number("background.moving_k_sigma", bg.moving_k_sigma, Bound::positive);
  r.number("background.moving_min_spread_m", bg.moving_min_spread_m, Bound::non_negative);
  r.number("background.max_moving_share", bg.max_moving_share, Bound::non_negative);
  if (bg.max_moving_share > 1.0F) r.fail("background.max_moving_share", "expected a share in [0, 1]");
  r.integer("background.motion_min_width_px", bg.motion_min_width_px, 1, 31);
  if (bg.motion_min_width_px % 2 == 0) r.fail("background.motion_min_width_px", "expected an odd width in [1, 31]");
  r.number("background.min_valid_ratio", bg.min_valid_ratio, Bound::non_negative);
  if (bg.min_valid_ratio > 1.0F) r.fail("background.min_valid_ratio", "expected a share in [0, 1]");
  r.integer("background.fill_radius_px", bg.fill_radius_px, 0, 1000);
  r.integer("background.unseen_min_frames", bg.unseen_min_frames, 1, std::numeric_limits<int>::max());
  r.number("background.max_noise_per_z2", bg.max_noise_per_z2, Bound::positive);
  r.number("background.motion_max_distance_m", bg.motion_max_distance_m, Bound::positive, kMaxCoordinateM);

  ForegroundParams& fg = c.pipeline.foreground;
  r.number("foreground.k_sigma", fg.k_sigma, Bound::positive);
  r.number("foreground.min_margin_m", fg.min_margin_m, Bound::non_negative);
  r.number("foreground.min_object_mm", fg.min_object_mm, Bound::non_negative);
  r.vec3("foreground.workspace_base.min", fg.workspace_base.min);
  r.vec3("foreground.workspace_base.max", fg.workspace_base.max);
  if ((fg.workspace_base.min.array() > fg.workspace_base.max.array()).any()) {
    r.fail_pair("foreground.workspace_base.min", "foreground.workspace_base.max", "expected min <= max on every axis");
  }

  // The arm's own pixels (docs/ROBOT.md, "Self-filter"); robot.model points have no body to render.
  SelfFilterParams& sf = c.pipeline.self_filter;
  r.flag("self_filter.enabled", sf.enabled);
  r.number("self_filter.margin_m", sf.margin_m, Bound::non_negative, 1.0F);
  r.integer("self_filter.dilate_px", sf.dilate_px, 0, 64);
  r.integer("self_filter.memory_frames", sf.memory_frames, 1, 30);
}

// `proximity.backend`: the core's backends by their names, and depth_space, which is named in
// the schema (docs/PROXIMITY.md) but refused until it exists.
void read_backend(KeyReader& r, ProximityBackend& backend) {
  std::string name = proximity_backend_name(backend);
  r.choice("proximity.backend", name, {"brute", "kdtree", "octree", "depth_space", "auto"});
  if (name == "depth_space") not_implemented(r, "proximity.backend", name, "brute");
  for (const ProximityBackend option : kProximityBackends) {
    if (name == proximity_backend_name(option)) backend = option;
  }
}

void read_robot_and_safety(KeyReader& r, Config& c) {
  config_detail::read_robot(r, c);  // src/config/robot_config.cpp

  read_backend(r, c.pipeline.backend);
  r.integer("proximity.octree.height", c.pipeline.proximity.octree_height, 1, 10);
  r.integer("proximity.threads", c.pipeline.proximity.threads, 1, 2);

  SafetyParams& safety = c.pipeline.safety;
  r.number("safety.slow_distance_m", safety.slow_distance_m, Bound::non_negative);
  // 0 would not stop for a point touching the robot (distance 0 is not below 0).
  r.number("safety.stop_distance_m", safety.stop_distance_m, Bound::positive);
  r.number_in("safety.max_frame_age_s", safety.max_frame_age_s, kMinFrameAgeS, kMaxFrameAgeS, " s");
  // 0 would switch the check off: a covered camera would then say run.
  r.number("safety.min_valid_share", safety.min_valid_share, Bound::positive, 1.0F);
  if (safety.stop_distance_m > safety.slow_distance_m) {
    r.fail_pair("safety.stop_distance_m", "safety.slow_distance_m",
                "expected stop_distance_m <= slow_distance_m, got " + config_detail::float_text(safety.stop_distance_m) +
                    " > " + config_detail::float_text(safety.slow_distance_m));
  }
}

// S_p's terms (`safety.human_speed_mps` … `safety.robot_uncertainty_m`, docs/SAFETY.md), and
// C's limit on the speckle threshold. Read in both modes, so the schema knows them all.
void read_ssm_terms(KeyReader& r, Config& c) {
  const SafetyParams& safety = c.pipeline.safety;
  SsmParams& ssm = c.pipeline.safety.ssm;
  // Beyond 10 m/s no person walks; a speed of 0 would ignore the person's approach.
  r.number("safety.human_speed_mps", ssm.human_speed_mps, Bound::positive, 10.0F);
  r.number("safety.human_speed_near_mps", ssm.human_speed_near_mps, Bound::positive, 10.0F);
  r.number("safety.human_near_m", ssm.human_near_m, Bound::non_negative, 10.0F);
  if (ssm.human_speed_near_mps < ssm.human_speed_mps) {
    r.fail_pair("safety.human_speed_near_mps", "safety.human_speed_mps",
                "expected the near speed (a reaching hand) >= the walking speed, got " +
                    config_detail::float_text(ssm.human_speed_near_mps) + " < " +
                    config_detail::float_text(ssm.human_speed_mps));
  }
  r.number_in("safety.controller_latency_s", ssm.controller_latency_s, 0.0, 10.0, " s");
  r.number_in("safety.robot_stop_time_s", ssm.robot_stop_time_s, 0.0, 10.0, " s");
  r.number("safety.robot_decel_mps2", ssm.robot_decel_mps2, Bound::non_negative, 1000.0F);
  r.number("safety.detection_mm", ssm.detection_mm, Bound::positive, 1000.0F);
  // Where detection_mm was measured to hold (docs/SAFETY.md, "C and the detection capability"):
  // a statement about the camera and filter chain for the integrator and the effective
  // configuration, not a term of S_p; 0 (the default) leaves it unstated.
  r.number("safety.detection_range_m", ssm.detection_range_m, Bound::non_negative, kMaxCoordinateM);
  r.number("safety.robot_uncertainty_m", ssm.robot_uncertainty_m, Bound::non_negative, 1.0F);
  r.number("safety.robot_max_speed_mps", ssm.robot_max_speed_mps, Bound::positive, 20.0F);
  r.number_in("safety.receiver_timeout_s", ssm.receiver_timeout_s, 0.0, 10.0, " s");
  ssm.source_latency_s = c.source.latency_s;
  config_detail::read_stopping_data(r, c);  // src/config/safety_config.cpp
  // The system cannot detect what it removes as speckle (foreground.min_object_mm), and a test
  // piece of d measures less than d: the mean depth of a sphere's visible cap is nearer than its
  // outline, and edge pixels drop out (35-45 mm for 40 mm on the simulated D435, docs/SAFETY.md,
  // "C and the detection capability"). So the speckle threshold must stay 20 % below d. Checked
  // where C is used, in ssm mode: zones mode never reads detection_mm.
  const float max_min_object_mm = kSpeckleShareOfDetection * ssm.detection_mm;
  if (safety.mode == SafetyParams::Mode::ssm && c.pipeline.foreground.min_object_mm > max_min_object_mm) {
    r.fail_pair("safety.detection_mm", "foreground.min_object_mm",
                "expected min_object_mm <= 0.8 * detection_mm (a test piece of detection_mm measures down to about "
                "0.88 of it, and blobs smaller than min_object_mm are removed as speckle, so they are not "
                "detected), got min_object_mm " + config_detail::float_text(c.pipeline.foreground.min_object_mm) +
                    " > " + config_detail::float_text(max_min_object_mm) + " (detection_mm " +
                    config_detail::float_text(ssm.detection_mm) + ")");
  }
}

// `safety.mode: ssm` and the keys shared by both modes (docs/SAFETY.md for the defaults).
void read_safety_behaviour(KeyReader& r, Config& c) {
  SafetyParams& safety = c.pipeline.safety;
  std::string mode = safety.mode == SafetyParams::Mode::ssm ? "ssm" : "zones";
  r.choice("safety.mode", mode, {"zones", "ssm"});
  safety.mode = mode == "ssm" ? SafetyParams::Mode::ssm : SafetyParams::Mode::zones;
  read_ssm_terms(r, c);
  // Relaxing waits by default in ssm mode (a verdict that flickers between slow and run jerks
  // the arm); zones mode keeps the thesis's frame-by-frame rule unless told otherwise.
  if (safety.mode == SafetyParams::Mode::ssm) {
    safety.hysteresis_m = 0.05F;
    safety.min_hold_s = 0.5;
  }
  r.number("safety.hysteresis_m", safety.hysteresis_m, Bound::non_negative, 10.0F);
  r.number_in("safety.min_hold_s", safety.min_hold_s, 0.0, 60.0, " s");
  constexpr SafetyParams::UnknownPolicy kPolicies[] = {SafetyParams::UnknownPolicy::report,
                                                      SafetyParams::UnknownPolicy::stop_within_m,
                                                      SafetyParams::UnknownPolicy::stop_within_protective};
  r.choice("safety.unknown_policy", safety.unknown_policy, kPolicies, unknown_policy_name);
  r.number("safety.unknown_stop_within_m", safety.unknown_stop_within_m, Bound::non_negative, 10.0F);
  CellCheckParams& checks = c.pipeline.checks;
  // None of the image watchdogs can be switched off by a value: 0 m would never block, a
  // share of 1 would never be exceeded.
  r.number("safety.blocked_depth_m", checks.blocked_depth_m, Bound::positive, 10.0F);
  r.number("safety.blocked_share", checks.blocked_share, Bound::positive, 1.0F);
  r.number("safety.max_envelope_invalid_share", checks.max_envelope_invalid_share, Bound::non_negative, 0.99F);
  r.number("safety.moved_share", checks.moved_share, Bound::positive, 1.0F);
  // The camera pose check (arms only; it does nothing for robot.model points). The threshold
  // must stay below the disagreement a 1 cm or 1 degree error gives (docs/SAFETY.md).
  PoseCheckParams& pose = c.pipeline.pose_check;
  r.flag("safety.pose_check", pose.enabled);
  r.number("safety.pose_check_threshold_m", pose.threshold_m, Bound::positive, 1.0F);
  r.integer("safety.pose_check_min_arm_pixels", pose.min_arm_pixels, 1, 100000);
  r.integer("safety.pose_check_window_frames", pose.window_frames, 1, 30);
  // At least one period (a gap below one period fires between any two frames), at most 100.
  r.number_in("safety.max_frame_gap_periods", safety.max_frame_gap_periods, 1.0, 100.0, " periods");
}

// `calibration.*`: how `hrcsense calibrate` reads the sweep and when it refuses
// (docs/CALIBRATION.md). No value may turn a refusal off: the limits are bounded.
void read_calibration(KeyReader& r, Config& c) {
  CalibrationParams& cal = c.calibration;
  r.integer("calibration.grid_px", cal.grid_px, 1, 16);
  r.number("calibration.candidate_margin_m", cal.candidate_margin_m, Bound::positive, 1.0F);
  r.number("calibration.inlier_gate_m", cal.inlier_gate_m, Bound::positive, 0.2F);
  r.integer("calibration.max_keyframes", cal.max_keyframes, 8, 100000);
  r.integer("calibration.min_arm_samples", cal.min_arm_samples, 100, 100000000);
  r.integer("calibration.min_poses", cal.min_poses, 3, 100000);
  r.number("calibration.max_residual_rms_m", cal.max_residual_rms_m, Bound::positive, 0.1F);
  r.number_in("calibration.max_sigma_translation_m", cal.max_sigma_translation_m, 1e-6, 0.05, " m");
  r.number_in("calibration.max_sigma_rotation_deg", cal.max_sigma_rotation_deg, 1e-6, 2.0, " deg");
}

// `link.*`: the verdict to the controller (docs/SAFETY.md, "The link").
void read_link(KeyReader& r, Config& c) {
  LinkConfig& link = c.link;
  r.text("link.udp.address", link.udp_address);
  if (!link.udp_address.empty()) {
    const size_t colon = link.udp_address.rfind(':');
    const std::string port = colon == std::string::npos ? "" : link.udp_address.substr(colon + 1);
    const bool port_ok = !port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos &&
                         std::stoi(port) >= 1 && std::stoi(port) <= 65535;
    if (colon == 0 || !port_ok) {
      r.fail("link.udp.address", "expected host:port (e.g. 127.0.0.1:30020), not '" + link.udp_address + "'");
    }
  }
  constexpr UdpFormat kUdpFormats[] = {UdpFormat::binary, UdpFormat::json};
  r.choice("link.udp.format", link.udp_format, kUdpFormats, udp_format_name);
  r.number_in("link.heartbeat_hz", link.heartbeat_hz, 0.1, 1000.0, " Hz");
  constexpr RtdeWrite kRtdeWrites[] = {RtdeWrite::off, RtdeWrite::speed_slider, RtdeWrite::input_register};
  r.choice("link.rtde.write", link.rtde_write, kRtdeWrites, rtde_write_name);
  // Registers 0-23 belong to the controller's fieldbus adapters; 24-47 are free for RTDE clients.
  r.integer("link.rtde.register", link.rtde_register, 24, 47);
  r.number_in("link.rtde.min_speed_slider", link.rtde_min_speed_slider, 0.001, 1.0, "");
  r.flag("link.rtde.slider_unguarded_ok", link.rtde_slider_unguarded_ok);
  if (link.rtde_write != RtdeWrite::off && c.robot_state.host.empty()) {
    r.fail_pair("link.rtde.write", "robot.state.host", "link.rtde.write needs the controller's address");
  }
  // The slider is a value the controller keeps: when hrcsense dies (kill -9, a crash, a lost
  // host) it stays where the last write left it, 1.0 after a `run`, and nothing on the robot
  // notices. In ssm mode the scale is the protection against the person, so the slider is
  // refused there until the integrator has guarded it on the robot (docs/SAFETY.md) and says so.
  if (link.rtde_write == RtdeWrite::speed_slider && c.pipeline.safety.mode == SafetyParams::Mode::ssm &&
      !link.rtde_slider_unguarded_ok) {
    r.fail_pair("link.rtde.write", "safety.mode",
                "speed_slider in ssm mode keeps the robot at the last speed written (1.0 after a run) when "
                "hrcsense dies; use link.rtde.write: register with a URScript and rtde_set_watchdog, or guard the "
                "slider on the robot and set link.rtde.slider_unguarded_ok: true (docs/SAFETY.md)");
  }
}

// A ROS 2 name: absolute, '/'-separated tokens of letters, digits and '_' (ROS 2's rules,
// which DDS topic names "rt/..." inherit); "" is allowed where `empty_ok` (derived later).
void ros2_name(KeyReader& r, const std::string& key, std::string& value, bool empty_ok) {
  r.text(key, value);
  if (value.empty() && empty_ok) return;
  bool ok = value.size() >= 2 && value.front() == '/' && value.back() != '/';
  for (size_t i = 0; ok && i < value.size(); ++i) {
    const char ch = value[i];
    const bool token_char = std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_';
    ok = token_char || (ch == '/' && i + 1 < value.size() && value[i + 1] != '/');
  }
  if (!ok) r.fail(key, "expected an absolute ROS 2 name like /camera/camera (letters, digits, '_' between '/'), got '" + value + "'");
}

// A ROS 2 name token: letters, digits and '_', not starting with a digit.
bool ros2_token(const std::string& value) {
  if (value.empty() || std::isdigit(static_cast<unsigned char>(value.front())) != 0) return false;
  return std::all_of(value.begin(), value.end(),
                     [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_'; });
}

void read_ros2(KeyReader& r, Config& c) {
  Ros2SourceConfig& ros2 = c.source.ros2;
  ros2_name(r, "source.ros2.namespace", ros2.node_namespace, false);
  ros2_name(r, "source.ros2.depth_topic", ros2.depth_topic, true);
  ros2_name(r, "source.ros2.color_topic", ros2.color_topic, true);
  ros2_name(r, "source.ros2.extrinsics_topic", ros2.extrinsics_topic, true);
  r.flag("source.ros2.color", ros2.color);
  // DDS maps domain ids 0-232 to UDP ports (ROS 2 allows 0-101 on Linux, 0-232 in general).
  r.integer("source.ros2.domain_id", ros2.domain_id, 0, 232);
  r.number_in("source.ros2.startup_timeout_s", ros2.startup_timeout_s, 0.1, 3600.0, " s");

  PublishConfig& publish = c.publish;
  ros2_name(r, "publish.namespace", publish.node_namespace, false);
  r.integer("publish.domain_id", publish.domain_id, 0, 232);
  r.integer("publish.wait_for_subscribers", publish.wait_for_subscribers, 0, 100);
  r.number_in("publish.wait_timeout_s", publish.wait_timeout_s, 0.1, 3600.0, " s");

  // H1: the outputs, and the domain the ROS 2 joint states are read on.
  Ros2Config& out = c.ros2;
  r.flag("ros2.publish", out.publish);
  r.integer("ros2.domain_id", out.domain_id, 0, 232);
  ros2_name(r, "ros2.namespace", out.node_namespace, false);
  r.number_in("ros2.cloud_hz", out.cloud_hz, 0.0, 100.0, " Hz");
  r.number_in("ros2.preview_hz", out.preview_hz, 0.0, 30.0, " Hz");
  r.integer("ros2.preview_decimation", out.preview_decimation, 1, 16);
  ros2_name(r, "ros2.speed_scaling_topic", out.speed_scaling_topic, true);
  r.text("ros2.camera_name", out.camera_name);
  if (!ros2_token(out.camera_name)) {
    r.fail("ros2.camera_name", "expected a ROS 2 name token (letters, digits, '_', not starting with a digit), got '" +
                                   out.camera_name + "'");
  }

  Ros2JointStateConfig& joints = c.robot_state.ros2;
  ros2_name(r, "robot.state.ros2.topic", joints.topic, false);
  r.text("robot.state.ros2.tf_prefix", joints.tf_prefix);
  if (!joints.tf_prefix.empty() && !ros2_token(joints.tf_prefix)) {
    r.fail("robot.state.ros2.tf_prefix", "expected letters, digits and '_' (e.g. ur_), got '" + joints.tf_prefix + "'");
  }
  ros2_name(r, "robot.state.ros2.speed_scaling_topic", joints.speed_scaling_topic, true);
  constexpr SpeedScalingUnit kUnits[] = {SpeedScalingUnit::percent, SpeedScalingUnit::fraction};
  r.choice("robot.state.ros2.speed_scaling_unit", joints.speed_scaling_unit, kUnits, speed_scaling_unit_name);
}

void read_record(KeyReader& r, Config& c) {
  // Up to 1 TiB per file; a bag's chunk positions are 64-bit, so only the file system limits it.
  r.integer("record.split_mb", c.record.split_mb, 0, int64_t{1} << 20);
  constexpr RecordOnError kOnErrors[] = {RecordOnError::continue_run, RecordOnError::stop_run};
  r.choice("record.on_error", c.record.on_error, kOnErrors, record_on_error_name);
  // Each queued 848x480 depth + colour frame holds about 2 MB: 1024 frames are 2 GB.
  r.integer("record.queue_frames", c.record.queue_frames, 1, 1024);
}

// The table of every key: one typed read per key, in docs/CONFIG.md order.
void read_all(KeyReader& r, Config& c) {
  read_source_and_sim(r, c);
  read_camera_and_filters(r, c);
  read_segmentation(r, c);
  read_robot_and_safety(r, c);
  read_safety_behaviour(r, c);
  read_link(r, c);
  read_record(r, c);
  read_ros2(r, c);
  read_calibration(r, c);
  config_detail::read_cell(r, c);  // src/config/cameras_config.cpp; after foreground.workspace_base
  config_detail::check_ssm_mode(r, c);  // after every key: it weighs keys of several sections
}

// Every key the reader knows, found by reading an empty tree (all reads are unconditional).
const std::set<std::string>& known_keys() {
  static const std::set<std::string> keys = [] {
    KeyReader reader(YAML::Node(YAML::NodeType::Map), "<defaults>");
    Config defaults;
    read_all(reader, defaults);
    return reader.known();
  }();
  return keys;
}

bool is_section(const std::string& key) {
  const std::set<std::string>& known = known_keys();
  const auto next = known.lower_bound(key + ".");
  return next != known.end() && next->compare(0, key.size() + 1, key + ".") == 0;
}

void check_keys(const YAML::Node& map, const std::string& prefix, const std::string& where) {
  for (const auto& entry : map) {
    const std::string key = prefix.empty() ? entry.first.Scalar() : prefix + "." + entry.first.Scalar();
    if (known_keys().count(key) != 0) continue;
    if (!is_section(key)) throw ConfigError(where + ": unknown key '" + key + "'");
    if (entry.second.IsMap()) {
      check_keys(entry.second, key, where);
    } else if (!entry.second.IsNull()) {
      config_detail::fail(where, key, "expected a map of keys");
    }
  }
}

YAML::Node load_file(const std::string& path) {
  if (path.empty()) return YAML::Node(YAML::NodeType::Map);
  const YAML::Node root = config_detail::load_yaml_file(path, "configuration file");
  if (root.IsNull() || !root.IsDefined()) return YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw ConfigError(path + ": expected a map of sections (source, sim, ...) at the top");
  return root;
}

bool valid_key_text(const std::string& key) {
  if (key.empty() || key.front() == '.' || key.back() == '.' || key.find("..") != std::string::npos) {
    return false;
  }
  for (char ch : key) {
    if (std::isalnum(static_cast<unsigned char>(ch)) == 0 && ch != '_' && ch != '.') return false;
  }
  return true;
}

void apply_override(YAML::Node& root, const std::string& text) {
  const size_t eq = text.find('=');
  const std::string key = text.substr(0, eq);
  if (eq == std::string::npos || eq + 1 == text.size() || !valid_key_text(key)) {
    throw ConfigError("--set '" + text + "': expected KEY=VALUE, e.g. safety.stop_distance_m=0.4");
  }
  if (known_keys().count(key) == 0 && !is_section(key)) {
    throw ConfigError("--set '" + text + "': unknown key '" + key + "'");
  }
  // As strict as a file: no duplicate keys, second documents or unknown tags in the value.
  const YAML::Node value = config_detail::parse_yaml_strict(text.substr(eq + 1), "--set '" + text + "'", key, false);
  config_detail::set_path(root, key, value);
}

// The typed read of a whole tree: the unknown-key check, then the table.
Config read_tree(const YAML::Node& root, const std::string& path, const std::string& where) {
  check_keys(root, "", where);
  Config config;
  config.file = path;
  KeyReader reader(root, where);
  try {
    read_all(reader, config);
  } catch (const YAML::Exception& e) {
    // Any yaml-cpp conversion the typed readers did not anticipate still names the file.
    throw ConfigError(where + ": " + e.what());
  }
  YAML::Emitter emitter;
  emitter << reader.effective();
  config.canonical_yaml = emitter.c_str();
  config.canonical_yaml += '\n';
  return config;
}

}  // namespace

Config load_config(const std::string& path, const std::vector<std::string>& overrides, const std::string& camera) {
  const YAML::Node file = load_file(path);
  // The file with the overrides: the top-level keys, and the cameras: list the entries come from.
  YAML::Node root = camera.empty() ? file : YAML::Clone(file);
  for (const std::string& text : overrides) apply_override(root, text);
  const std::string where = path.empty() ? std::string("<defaults>") : path;
  config_detail::check_camera_entries(root, where, known_keys());
  Config config = read_tree(root, path, where);
  const auto read_entry = [&](const YAML::Node& tree) { return read_tree(tree, path, where); };
  std::vector<CameraEntry> cameras = config_detail::read_camera_entries(root, where, read_entry);
  if (!camera.empty()) {
    // The entry over the file's keys, then the overrides again, so that a --set wins over the entry.
    YAML::Node selected = YAML::Clone(file);
    config_detail::lay_camera_over(selected, root, camera, where);
    for (const std::string& text : overrides) apply_override(selected, text);
    config = read_tree(selected, path, where);
    config.camera = camera;
    config.pipeline.seen_free_grid = config.cell.grid;
    config.pipeline.seen_free_grid.enabled = true;
  }
  config.cameras = std::move(cameras);
  return config;
}

std::string config_hash(const Config& config) {
  uint64_t hash = 0xcbf29ce484222325ULL;  // FNV-1a 64 offset basis
  for (unsigned char byte : config.canonical_yaml) {
    hash ^= byte;
    hash *= 0x100000001b3ULL;  // FNV-1a 64 prime
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace hrcsense
