// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — `ros2.publish`: each result as ROS 2 topics over Cyclone DDS (the verdict,
// the speed scaling for the robot's driver, RViz markers, the foreground cloud) and the
// camera's place on /tf_static, without a ROS installation.
#pragma once

#include "dds/ros2_output_messages.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/sink.hpp"

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace hrcsense::ros2 {

struct Ros2OutputParams {
  uint32_t domain_id = 0;                  ///< `ros2.domain_id`
  std::string node_namespace = "/hrcsense";  ///< `ros2.namespace`: topics below it
  /// `ros2.speed_scaling_topic`: absolute ROS name of the speed scaling; empty: <namespace>/speed_scaling.
  std::string speed_scaling_topic;
  double cloud_hz = 10.0;                  ///< foreground clouds per second at most (host steady clock); 0: none
  std::string camera_name = "camera";      ///< `ros2.camera_name`: <camera_name>_link, <camera_name>_depth_optical_frame
  std::string base_frame = "base";         ///< `robot.base_frame`'s ROS name (base_frame_id())
  Pose T_base_camera = Pose::Identity();   ///< `camera.T_base_camera`: base ← camera optical
  RobotParams robot;                       ///< the markers' capsules (robot_model_at each result's joints)
  double max_frame_gap_periods = 2.0;      ///< `safety.max_frame_gap_periods`: the verdict's deadline in periods
  double max_frame_age_s = 0.5;            ///< `safety.max_frame_age_s`: the deadline when the rate is unknown
  /// The camera node publishes `<camera>_link → … → <camera>_depth_optical_frame` itself
  /// (source.type ros2, realsense-ros): only `base → <camera>_link` is published, composed with
  /// the chain read from its /tf_static.
  bool camera_publishes_optical = false;
  double camera_tf_wait_s = 2.0;           ///< how long the constructor waits for that chain
  uint32_t camera_domain_id = 0;           ///< where the camera node's /tf_static is read (`source.ros2.domain_id`)
};

/// The ROS 2 names the sink writes.
struct Ros2OutputTopics {
  std::string verdict, speed_scaling, markers, foreground, tf_static;
};

/// <namespace>/verdict, /speed_scaling (or the absolute override), /markers, /foreground and
/// /tf_static. Throws Ros2Error for a name that is not absolute.
Ros2OutputTopics ros2_output_topics(const std::string& node_namespace, const std::string& speed_scaling_topic);

/// What the outputs wrote (read on the output thread, or after the run).
struct Ros2OutputCounters {
  int64_t verdicts = 0;       ///< Verdict samples written (= the last seq)
  int64_t clouds = 0;         ///< PointCloud2 samples written
  int64_t marker_arrays = 0;  ///< MarkerArray samples written
  int64_t failed_writes = 0;  ///< writes on any topic DDS refused
  std::string last_error;     ///< the last refused write, naming the topic
};

/// Writes, per result (Sink::frame: each JSON Lines `frame` and `verdict` line, the final stop
/// included): an hrcsense_msgs/Verdict (reliable, volatile, keep-last 1, DEADLINE and
/// automatic LIVELINESS lease of max_frame_gap_periods nominal frame periods, or
/// max_frame_age_s when the source's rate is unknown; seq 1 for the first sample, +1 per
/// sample), a control_msgs/SpeedScalingFactor (the speed scale; reliable, transient-local,
/// keep-last 1), a MarkerArray (safety_markers; reliable, volatile, keep-last 1) and, when one
/// is pending, the foreground cloud the processing tap copied (on_processed). header() makes the
/// writers and writes /tf_static once (reliable, transient-local, keep-last 1; stamp 0, as
/// static transforms hold at all times).
/// Writes never throw: a refused write is counted (counters()); a verdict refused for
/// kFailedVerdictsInARow results in a row, or writers that cannot be made, is a persistent
/// failure: failed() then ends the run (its final stop reaches the other sinks).
class Ros2OutputSink final : public Sink {
 public:
  /// Verdicts refused in a row that make the outputs failed().
  static constexpr int kFailedVerdictsInARow = 10;

  /// Joins the domain (one participant per domain per process) and, with
  /// camera_publishes_optical, waits up to camera_tf_wait_s for the camera's /tf_static chain;
  /// without it, the fixed D435 rotation stands in (camera_tf_note() says so). When what it read
  /// there already gives `<camera>_link` a parent, nothing is published on /tf_static (a frame
  /// never gets a second parent; camera_tf_note() says so). Throws Ros2Error when the domain
  /// cannot be joined or a topic name is not absolute.
  explicit Ros2OutputSink(Ros2OutputParams params);
  ~Ros2OutputSink() override;
  Ros2OutputSink(const Ros2OutputSink&) = delete;
  Ros2OutputSink& operator=(const Ros2OutputSink&) = delete;

  void header(const RunHeader& header) override;
  void frame(const FrameResult& result) override;
  /// Nothing more: the run's final stop came as a frame().
  void summary(const RunSummary&) override {}
  bool failed() const override { return !failure_.empty(); }
  std::string failure() const override { return failure_; }

  /// The processing thread's tap (RunOptions::on_processed): when a cloud is due (cloud_hz on
  /// the host's steady clock) and the frame is valid, copies the foreground's base-frame points
  /// for the output thread, which packs and writes them with its next frame(). Never waits for
  /// more than the hand-over of a buffer.
  void on_processed(const Frame& frame, const Pipeline& pipeline, const FrameResult& result);

  const Ros2OutputTopics& topics() const { return topics_; }
  /// What /tf_static holds (written by header()); empty: nothing is written.
  const std::vector<TfEdge>& tf_static_edges() const { return tf_edges_; }
  /// Empty, or why the camera's own link → optical chain was not used (a warning for the log).
  const std::string& camera_tf_note() const { return camera_tf_note_; }
  /// The verdict writer's DEADLINE and liveliness lease (ns), set by header(); 0 before.
  int64_t verdict_deadline_ns() const { return verdict_deadline_ns_; }
  Ros2OutputCounters counters() const { return counters_; }

 private:
  struct Dds;
  struct CloudSlot {
    PointCloud points;  ///< x, y, z only
    int64_t timestamp_ns = 0;
  };
  void read_camera_chain();
  bool write(int32_t writer, const void* sample, const std::string& topic);
  void write_pending_cloud();

  Ros2OutputParams params_;
  Ros2OutputTopics topics_;
  std::unique_ptr<Dds> dds_;
  std::vector<TfEdge> tf_edges_;
  std::string camera_tf_note_;
  int64_t verdict_deadline_ns_ = 0;
  uint32_t session_ = 0;
  uint32_t seq_ = 0;
  int verdicts_failed_in_a_row_ = 0;
  std::string failure_;
  Ros2OutputCounters counters_;
  RobotModel robot_;  ///< capsules of the current result (buffer reused)
  std::vector<MarkerSpec> marker_specs_;  ///< the current result's markers (buffer reused)
  MarkerArrayBuffers marker_buffers_;
  std::vector<uint8_t> cloud_bytes_;

  // The cloud's hand-over: the tap fills tap_cloud_ and swaps it into shared_cloud_; frame()
  // swaps it out into out_cloud_. Three buffers circulate, so nothing allocates once sized.
  int64_t cloud_period_ns_ = 0;    ///< 0: no clouds
  int64_t last_cloud_copy_ns_ = -1;  ///< steady clock, processing thread only; -1: none yet
  CloudSlot tap_cloud_, out_cloud_;
  std::mutex cloud_mutex_;
  CloudSlot shared_cloud_;  ///< guarded by cloud_mutex_
  bool cloud_pending_ = false;  ///< guarded by cloud_mutex_
};

}  // namespace hrcsense::ros2
