// SPDX-License-Identifier: Apache-2.0
// hrcsense apps — the fuser's loop (fuse_session.hpp).
#include "common/fuse_session.hpp"

#include "common/app_errors.hpp"
#include "common/assembly.hpp"
#include "common/console_sink.hpp"
#include "common/fuser_priority.hpp"
#include "common/stop_signals.hpp"
#include "common/tee_sink.hpp"

#include "hrcsense/clock.hpp"
#include "hrcsense/fusion.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/safety.hpp"
#include "hrcsense/session.hpp"
#include "hrcsense/sinks/sinks.hpp"

#if HRCSENSE_HAVE_DDS
#include "dds/measurement_endpoints.hpp"
#include "dds/ros2_cell_clock.hpp"
#include "dds/ros2_joint_state_writer.hpp"
#include "dds/ros2_messages.hpp"  // Ros2Error
#endif

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <vector>

namespace hrcsense::app {

double fuse_wait_s(const Config& config) {
  double fastest_fps = 0.0;
  for (const CameraEntry& entry : config.cameras) fastest_fps = std::max(fastest_fps, entry.fps);
  return fastest_fps > 0.0 ? 0.5 / fastest_fps : 0.0;
}

int64_t cell_clock_epoch_ns(const Config& config, int64_t fuser_start_ns) {
  return config.sim_epoch_ns ? *config.sim_epoch_ns : fuser_start_ns + 1'000'000'000;
}

#if HRCSENSE_HAVE_DDS
namespace {

// The codes a camera's run ends with: once every camera sent one, the cell has ended.
bool is_end_code(ReasonCode code) {
  return code == ReasonCode::source_ended || code == ReasonCode::frame_limit_reached ||
         code == ReasonCode::stop_requested || code == ReasonCode::source_error ||
         code == ReasonCode::processing_error || code == ReasonCode::output_error;
}

RunHeader fused_header(const Config& config) {
  RunHeader header;
  header.config_hash = config_hash(config);
  header.session = process_session();
  header.source.type = "fused";
  std::string names;
  double fastest_fps = 0.0;
  for (const CameraEntry& entry : config.cameras) {
    names += (names.empty() ? "" : ", ") + entry.name;
    fastest_fps = std::max(fastest_fps, entry.fps);
    RunHeader::Camera camera;
    camera.name = entry.name;
    camera.T_base_camera = entry.T_base_camera;
    camera.nominal_fps = entry.fps;
    if (entry.intrinsics) camera.intrinsics = *entry.intrinsics;
    header.cameras.push_back(camera);
  }
  header.source.description = std::to_string(config.cameras.size()) + " cameras fused: " + names;
  header.source.nominal_fps = fastest_fps;
  header.source.frame_count = -1;
  header.robot_state = "cameras";
  if (config.pipeline.safety.mode == SafetyParams::Mode::ssm) {
    header.stopping_data = stopping_data_name(config.pipeline.safety.ssm.stopping_data);
  }
  return header;
}

// The fuser: its memory of the cameras, the one monitor, the reader and the outputs.
class Fuser {
 public:
  Fuser(const Config& config, Sink& sink)
      : config_(config),
        fusion_(cameras_of(config), fusion_params(config)),
        monitor_(config.pipeline.safety, slowest_fps(config), true),
        reader_(static_cast<uint32_t>(config.ros2.domain_id), config.ros2.node_namespace, names_of(config)),
        sink_(sink),
        intake_(config.cameras.size()) {
    double fastest = 0.0;
    for (const CameraEntry& entry : config.cameras) fastest = std::max(fastest, entry.fps);
    wait_ns_ = seconds_to_ns(fuse_wait_s(config));
    // No instant for this long: a line anyway, so the outputs (and the stale rule) never wait on
    // a silent cell.
    watchdog_ns_ = seconds_to_ns(1.0 / fastest);
    for (size_t i = 0; i < config.cameras.size(); ++i) intake_[i].name = config.cameras[i].name;
  }

  RunSummary run(int64_t max_frames) {
    const int64_t start_ns = shared_clock();
    last_decision_ns_ = start_ns;
    RunSummary summary;
    summary.end_code = ReasonCode::source_ended;
    summary.end_reason = "every camera ended its run";
    while (true) {
      if (StopSignals::stop_requested()) {
        summary.end_code = ReasonCode::stop_requested;
        summary.end_reason = "stop requested";
        break;
      }
      if (max_frames > 0 && decisions_ >= max_frames) {
        summary.end_code = ReasonCode::frame_limit_reached;
        summary.end_reason = "--frames reached";
        break;
      }
      if (all_ended()) break;
      if (sink_.failed()) {
        summary.end_code = ReasonCode::output_error;
        summary.end_reason = summary.error = "output failed: " + sink_.failure();
        break;
      }
      int64_t now = shared_clock();
      const int64_t wake_at = pending_ ? pending_since_ns_ + wait_ns_ : last_decision_ns_ + watchdog_ns_;
      reader_.wait(std::clamp<int64_t>(wake_at - now, 0, watchdog_ns_));
      now = shared_clock();
      reader_.take([&](size_t topic, const CameraMeasurement& m, const std::string& problem) { receive(topic, m, problem, now); });
      now = shared_clock();
      if (pending_ && (complete() || now >= pending_since_ns_ + wait_ns_)) {
        decide(pending_instant_ns_, pending_frame_, true, now);
        last_instant_ns_ = pending_instant_ns_;
        last_frame_ = pending_frame_;
        pending_ = false;
      } else if (!pending_ && now - last_decision_ns_ >= watchdog_ns_) {
        decide(last_instant_ns_ > 0 ? last_instant_ns_ : now, last_frame_, false, now);
      }
    }
    // The final line: a stop, as every run ends.
    const int64_t now = shared_clock();
    fusion_.fuse(last_instant_ns_ > 0 ? last_instant_ns_ : now, last_frame_, now, result_);
    monitor_.decide(result_, now);
    result_.source_frame = false;
    result_.verdict = stop_verdict(summary.end_code, summary.end_reason);
    write(result_);
    summary.frames_in = decisions_;
    summary.frames_processed = decisions_;
    summary.frames_valid = valid_;
    summary.verdict_run = counts_[0];
    summary.verdict_slow = counts_[1];
    summary.verdict_stop = counts_[2];
    summary.wall_s = static_cast<double>(now - start_ns) * 1e-9;
    summary.fps = summary.wall_s > 0.0 ? static_cast<double>(decisions_) / summary.wall_s : 0.0;
    summary.min_distance_m = min_distance_m_;
    if (!latencies_us_.empty()) {
      std::sort(latencies_us_.begin(), latencies_us_.end());
      summary.latency_p50_us = latencies_us_[latencies_us_.size() / 2];
      summary.latency_p99_us = latencies_us_[std::min(latencies_us_.size() - 1, latencies_us_.size() * 99 / 100)];
    }
    for (size_t i = 0; i < intake_.size(); ++i) {
      RunSummary::CameraIntake& in = intake_[i];
      const FusionCameraCounters& c = fusion_.counters(i);
      in.accepted = c.accepted;
      in.malformed += c.malformed;
      in.out_of_order = c.out_of_order;
      in.clock_ahead = c.clock_ahead;
      in.grid_mismatch = c.grid_mismatch;
      in.sessions = c.sessions;
      if (!c.last_problem.empty()) in.last_problem = c.last_problem;
    }
    summary.cameras = intake_;
    summary.unconfigured_measurement_publishers = reader_.unconfigured_publishers();
    summary.last_unconfigured_measurement_topic = reader_.last_unconfigured_topic();
    if (!added_us_.empty()) {
      std::sort(added_us_.begin(), added_us_.end());
      spdlog::info("fuse: the fuser added p50 {:.0f} µs, p99 {:.0f} µs beyond the last camera's publication "
                   "({} valid instants)",
                   added_us_[added_us_.size() / 2], added_us_[std::min(added_us_.size() - 1, added_us_.size() * 99 / 100)],
                   added_us_.size());
    }
    return summary;
  }

 private:
  static std::vector<FusionCamera> cameras_of(const Config& config) {
    std::vector<FusionCamera> cameras;
    for (const CameraEntry& entry : config.cameras) cameras.push_back({entry.name, entry.fps});
    return cameras;
  }
  static std::vector<std::string> names_of(const Config& config) {
    std::vector<std::string> names;
    for (const CameraEntry& entry : config.cameras) names.push_back(entry.name);
    return names;
  }
  static FusionParams fusion_params(const Config& config) {
    FusionParams params;
    params.safety = config.pipeline.safety;
    params.robot = config.pipeline.robot;
    params.grid = config.cell.grid;
    params.clock_offset_max_ns = seconds_to_ns(config.cell.clock_offset_max_s);
    return params;
  }
  // T_r counts one period of the slowest camera: an intrusion can begin just after its capture.
  static double slowest_fps(const Config& config) {
    double slowest = 0.0;
    for (const CameraEntry& entry : config.cameras) slowest = slowest > 0.0 ? std::min(slowest, entry.fps) : entry.fps;
    return slowest;
  }
  static int64_t shared_clock() { return shared_clock_ns(); }

  void receive(size_t topic, const CameraMeasurement& m, const std::string& problem, int64_t now) {
    RunSummary::CameraIntake& in = intake_[topic];
    if (!problem.empty()) {
      ++in.malformed;
      in.last_problem = problem;
      return;
    }
    if (m.camera_name != config_.cameras[topic].name) {
      // Only the configured camera may speak on its topic.
      ++in.name_mismatch;
      in.last_problem = "a measurement named '" + m.camera_name + "' on " + reader_.topics()[topic];
      return;
    }
    if (fusion_.add(m, now) != FusionIntake::accepted) return;
    if (m.capture_ns <= last_instant_ns_) return;
    if (!pending_) {
      pending_ = true;
      pending_since_ns_ = now;
      pending_instant_ns_ = m.capture_ns;
      pending_frame_ = m.frame;
    } else if (m.capture_ns > pending_instant_ns_) {
      pending_instant_ns_ = m.capture_ns;
      pending_frame_ = m.frame;
    }
  }

  // Every camera has spoken for the pending instant, or is too late to wait for.
  bool complete() const {
    for (size_t i = 0; i < config_.cameras.size(); ++i) {
      const CameraMeasurement* m = fusion_.newest(i);
      if (m == nullptr) continue;  // never heard: stale, nothing to wait for
      const double period_ns = 1e9 / m->nominal_fps;
      const auto behind_ns = static_cast<double>(pending_instant_ns_ - m->capture_ns);
      // Within most of a period of the instant: its newest frame stands for it. Far behind: late
      // or dead, and not waited for (the stale rule judges it).
      if (behind_ns > 0.75 * period_ns && behind_ns < 2.0 * period_ns) return false;
    }
    return true;
  }

  bool all_ended() const {
    for (size_t i = 0; i < config_.cameras.size(); ++i) {
      const CameraMeasurement* m = fusion_.newest(i);
      if (m == nullptr || m->valid || !is_end_code(m->reason_code)) return false;
    }
    return true;
  }

  void decide(int64_t instant_ns, int64_t frame, bool source_frame, int64_t now) {
    fusion_.fuse(instant_ns, frame, now, result_);
    result_.source_frame = source_frame;
    monitor_.decide(result_, now);
    result_.closest_camera_name = fusion_.camera_of_link(result_.governing_link);
    // The fused latency: capture of the oldest contributing frame to this decision; what the
    // fuser added: from the last contributing camera's publication (its capture + its latency)
    // to this decision, transport included.
    const int64_t done_ns = shared_clock();
    result_.latency_us = static_cast<double>(done_ns - result_.seen_ns) * 1e-3;
    double published_ns = 0.0;
    for (size_t i = 0; i < config_.cameras.size(); ++i) {
      const CameraMeasurement* m = fusion_.newest(i);
      if (m != nullptr) published_ns = std::max(published_ns, static_cast<double>(m->capture_ns) + m->latency_us * 1e3);
    }
    result_.timings.push_back({"fusion_added", (static_cast<double>(done_ns) - published_ns) * 1e-3});
    result_.timings.push_back({"fuse_decide", static_cast<double>(done_ns - now) * 1e-3});
    if (source_frame && result_.valid) {
      latencies_us_.push_back(result_.latency_us);
      added_us_.push_back(result_.timings.front().us);
    }
    write(result_);
    last_decision_ns_ = now;
  }

  void write(const FrameResult& result) {
    sink_.frame(result);
    ++decisions_;
    if (result.valid) ++valid_;
    ++counts_[verdict_strictness(result.verdict.state)];
    if (result.contact.valid && (min_distance_m_ < 0.0F || result.contact.distance_m < min_distance_m_)) {
      min_distance_m_ = result.contact.distance_m;
    }
  }

  const Config& config_;
  CellFusion fusion_;
  SafetyMonitor monitor_;
  ros2::MeasurementReader reader_;
  Sink& sink_;
  std::vector<RunSummary::CameraIntake> intake_;
  FrameResult result_;
  int64_t wait_ns_ = 0;
  int64_t watchdog_ns_ = 0;
  bool pending_ = false;
  int64_t pending_since_ns_ = 0;
  int64_t pending_instant_ns_ = 0;
  int64_t pending_frame_ = 0;
  int64_t last_instant_ns_ = 0;
  int64_t last_frame_ = 0;
  int64_t last_decision_ns_ = 0;
  int64_t decisions_ = 0;
  int64_t valid_ = 0;
  int64_t counts_[3] = {};
  float min_distance_m_ = -1.0F;
  std::vector<double> latencies_us_;
  std::vector<double> added_us_;  ///< per valid fused instant: what the fuser added (fusion_added)
};

// The live robot state the fuser owns and republishes on <ns>/joint_states, with its speed
// fraction on <ns>/robot_speed_scaling, for the cameras (docs/MULTICAMERA.md, "Robot state");
// nothing for a simulated, fixed or recorded arm, which every camera process plays or reads itself.
class RobotStateRelay {
 public:
  explicit RobotStateRelay(const Config& config) {
    if (!robot_state_is_live(config)) {
      spdlog::info("fuse: robot.state.source {}: each camera process has the arm itself (the simulator's on the "
                   "scene clock); nothing is republished",
                   robot_state_origin_name(config.robot_state.source));
      return;
    }
    ros2::JointStateWriterParams params;
    params.domain_id = static_cast<uint32_t>(config.ros2.domain_id);
    params.topic = ros2::cell_joint_states_topic(config.ros2.node_namespace);
    params.speed_scaling_topic = ros2::cell_robot_speed_scaling_topic(config.ros2.node_namespace);
    params.tf_prefix = config.robot_state.ros2.tf_prefix;
    if (config.ros2.speed_scaling_topic == params.speed_scaling_topic) {
      // Two writers of two types on one topic: hrcsense's commanded scale and the robot's reading.
      throw ConfigError(config_where(config) + ": ros2.speed_scaling_topic: " + params.speed_scaling_topic +
                        " is where hrcsense fuse republishes the robot's own speed fraction; choose another name");
    }
    if (config.robot_state.source == RobotStateOrigin::ros2) {
      // It would read its own samples back.
      const Ros2JointStateConfig& driver = config.robot_state.ros2;
      if (driver.topic == params.topic) {
        throw ConfigError(config_where(config) + ": robot.state.ros2.topic: " + params.topic +
                          " is where hrcsense fuse republishes the robot state; read the driver's topic (e.g. "
                          "/joint_states)");
      }
      if (driver.speed_scaling_topic == params.speed_scaling_topic) {
        throw ConfigError(config_where(config) + ": robot.state.ros2.speed_scaling_topic: " +
                          params.speed_scaling_topic + " is where hrcsense fuse republishes the robot's speed "
                          "fraction; read the driver's topic (e.g. /speed_scaling_state_broadcaster/speed_scaling)");
      }
    }
    states_ = make_robot_state_source(config, &clock_);
    relay_ = std::make_unique<ros2::JointStateRelay>(*states_, params);
    spdlog::info("fuse: robot state from {} republished on {} and its speed fraction on {} (domain {}) for the "
                 "cameras",
                 robot_state_origin_name(config.robot_state.source), params.topic, params.speed_scaling_topic,
                 config.ros2.domain_id);
  }
  // What went out, and what the source refused, for the log.
  void report() const {
    if (!relay_) return;
    const ros2::JointStateRelayCounters c = relay_->counters();
    const RobotStateStats stats = states_->stats();
    const int64_t rejected = stats.samples.rejected() + stats.malformed;
    const bool failed = c.refused > 0 || c.dropped > 0 || c.published == 0;
    spdlog::log(failed ? spdlog::level::warn : spdlog::level::info,
                "fuse: {} of the {} robot states the source accepted republished on {} ({} with a speed fraction), "
                "{} not written{}, {} dropped by a writer that fell behind, {} writes waited for a reliable "
                "reader; the source rejected {}{}",
                c.published, stats.samples.accepted, relay_->topic(), c.speed_published, c.refused,
                c.last_error.empty() ? "" : " (last: " + c.last_error + ")", c.dropped, c.write_waits, rejected,
                rejected == 0 || stats.last_problem.empty() ? "" : " (last: " + stats.last_problem + ")");
  }

 private:
  SteadyClock clock_;  // stateless: the time the live sources stamp with
  std::unique_ptr<RobotStateSource> states_;
  std::unique_ptr<ros2::JointStateRelay> relay_;  // after states_: stops listening before the source goes
};

}  // namespace

int fuse_session(const Config& config, const FuseOptions& options) {
  if (config.cameras.empty()) {
    throw ConfigError(config_where(config) + ": hrcsense fuse needs the cameras: list of a cell with several cameras "
                                             "(docs/MULTICAMERA.md)");
  }
  // Before any thread starts (DDS, the links, the relay): they inherit it.
  if (const std::string refused = run_under_fifo(config.cell.fuser_priority); !refused.empty()) {
    throw ConfigError(config_where(config) + ": " + refused);
  }
  if (config.cell.fuser_priority > 0) {
    spdlog::info("fuse: every thread under SCHED_FIFO at priority {} (cell.fuser_priority)", config.cell.fuser_priority);
  }
  const StopSignals signals;
  std::ofstream file;
  if (!options.out.empty()) {
    const std::filesystem::path parent = std::filesystem::path(options.out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    file.open(options.out, std::ios::out | std::ios::trunc);
    if (!file) return report_error(options.out + ": cannot open for writing", kExitRuntime);
  }
  std::ostream& out = options.out.empty() ? std::cout : file;
  // The controller's links first, as in `hrcsense run`; then the ROS 2 outputs, the file, the console.
  const std::unique_ptr<UdpLinkSink> udp = make_udp_link_sink(config);
  const std::unique_ptr<RtdeLinkSink> rtde = make_rtde_link_sink(config);
  Ros2Outputs ros2 = make_ros2_output_sink(config);
  JsonLinesSink jsonl(out, proximity_backend_name(config.pipeline.backend));
  ConsoleSink console;
  TeeSink tee({udp.get(), rtde.get(), ros2.sink.get(), &jsonl, &console});
  try {
    // The scene clock first: simulated cameras started with the fuser wait for it.
    const ros2::CellClockPublisher cell_clock(static_cast<uint32_t>(config.ros2.domain_id), config.ros2.node_namespace,
                                              cell_clock_epoch_ns(config, shared_clock_ns()));
    spdlog::info("fuse: the scene clock's epoch on {} (domain {}){}", cell_clock.topic(), config.ros2.domain_id,
                 config.sim_epoch_ns ? ": sim.epoch" : ": a second from now");
    const RobotStateRelay robot_state(config);
    Fuser fuser(config, tee);
    spdlog::info("fuse: {} cameras on {}/measurement/* (domain {}); waits {:.1f} ms for an instant's stragglers",
                 config.cameras.size(), config.ros2.node_namespace, config.ros2.domain_id, fuse_wait_s(config) * 1e3);
    tee.header(fused_header(config));
    const RunSummary summary = fuser.run(options.frames);
    tee.summary(summary);
    robot_state.report();
    if (StopSignals::stop_requested()) spdlog::info("signal received: the fuser ended with a stop");
    out.flush();
    if (!out) return report_error((options.out.empty() ? "stdout" : options.out) + ": write failed", kExitRuntime);
    if (!summary.error.empty()) return report_error(summary.error, kExitRuntime);
    return 0;
  } catch (const ros2::Ros2Error& e) {
    throw ConfigError(config_where(config) + ": hrcsense fuse: " + e.what());
  }
}
#else
int fuse_session(const Config& config, const FuseOptions&) {
  throw ConfigError(config_where(config) + ": hrcsense fuse: this hrcsense was built without Cyclone DDS; install "
                                           "cyclonedds-dev and cyclonedds-tools (scripts/setup does) and rebuild");
}
#endif

}  // namespace hrcsense::app
