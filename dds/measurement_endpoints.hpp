// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — the measurements of a cell with several cameras on the wire
// (docs/MULTICAMERA.md): the camera process's writer (a Sink of its run) and the fuser's reader
// of every configured camera's topic.
#pragma once

#include "dds/measurement_messages.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/fusion.hpp"
#include "hrcsense/sink.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hrcsense::ros2 {

struct MeasurementWriterParams {
  uint32_t domain_id = 0;                    ///< `ros2.domain_id`
  std::string node_namespace = "/hrcsense";  ///< `ros2.namespace`
  std::string camera_name;                   ///< `--camera NAME`
  std::string base_frame = "base";           ///< the stamp's frame_id
  double nominal_fps = 30.0;                 ///< the camera's rate (the deadline, the stale rule)
  Pose T_base_camera = Pose::Identity();     ///< the pose it measures with
  double max_frame_gap_periods = 2.0;        ///< the writer's deadline and liveliness lease, in periods
};

/// Writes each result of a camera's run as an hrcsense_msgs/Measurement (reliable, volatile,
/// keep-last 1; DEADLINE and automatic LIVELINESS of max_frame_gap_periods periods, as the
/// verdict's), the session the process's, sequence 1, 2, ... It decides nothing: the run's
/// own verdict is not sent. Writes never throw; a refused write is counted, ten in a row fail
/// the run (failed()).
class MeasurementSink final : public Sink {
 public:
  explicit MeasurementSink(MeasurementWriterParams params);  ///< throws Ros2Error
  ~MeasurementSink() override;
  MeasurementSink(const MeasurementSink&) = delete;
  MeasurementSink& operator=(const MeasurementSink&) = delete;

  void header(const RunHeader& header) override;
  /// Every result: a frame's measurement, or the run's own stop with no new frame (its
  /// watchdog, the end of the run) as a withheld measurement stamped when it is written.
  void frame(const FrameResult& result) override;
  void summary(const RunSummary&) override {}
  bool failed() const override { return !failure_.empty(); }
  std::string failure() const override { return failure_; }

  const std::string& topic() const { return topic_; }
  int64_t written() const { return written_; }
  int64_t failed_writes() const { return failed_writes_; }

 private:
  struct Dds;
  MeasurementWriterParams params_;
  std::string topic_;
  std::unique_ptr<Dds> dds_;
  CameraMeasurement out_;
  MeasurementBuffers buffers_;
  int64_t last_capture_ns_ = 0;  ///< the capture of the last measurement sent
  int64_t written_ = 0;
  int64_t failed_writes_ = 0;
  int failed_in_a_row_ = 0;
  std::string failure_;
};

/// Reads `<namespace>/measurement/<name>` for each configured camera name (best-effort, so
/// that reliable and best-effort writers both match; keep-last 8). Not thread-safe: one
/// thread waits and takes. It also watches DDS discovery (the built-in DCPSPublication topic)
/// for writers on `<namespace>/measurement/<x>` with x no configured camera: they are never
/// read, only counted, so that an operator sees a misnamed or foreign camera in the summary.
class MeasurementReader {
 public:
  MeasurementReader(uint32_t domain_id, const std::string& node_namespace, const std::vector<std::string>& camera_names);
  ~MeasurementReader();
  MeasurementReader(const MeasurementReader&) = delete;
  MeasurementReader& operator=(const MeasurementReader&) = delete;

  /// Waits until a measurement is readable, wake() is called or `timeout_ns` passes.
  void wait(int64_t timeout_ns);
  /// Ends a wait at once (any thread).
  void wake();
  /// Every sample waiting, in arrival order per camera: `received` gets the message read
  /// (`problem` empty), or why it could not be read (`m` then unset), and the index of the topic
  /// it came on. Returns the number of samples.
  size_t take(const std::function<void(size_t topic, const CameraMeasurement& m, const std::string& problem)>& received);
  const std::vector<std::string>& topics() const { return topics_; }
  /// Writers matched on topic `i` now.
  int32_t writers(size_t i) const;
  /// Writers discovered so far on `<namespace>/measurement/<x>`, x no configured camera (each
  /// writer once; updated by take()).
  int64_t unconfigured_publishers() const { return unconfigured_publishers_; }
  /// The ROS topic of the last of them ("/hrcsense/measurement/intruder"), empty before one.
  const std::string& last_unconfigured_topic() const { return last_unconfigured_topic_; }

 private:
  struct Dds;
  void take_publications();
  std::vector<std::string> topics_;
  std::string measurement_prefix_;  ///< the DDS topic names' common start, "rt/hrcsense/measurement/"
  int64_t unconfigured_publishers_ = 0;
  std::string last_unconfigured_topic_;
  std::unique_ptr<Dds> dds_;
  CameraMeasurement scratch_;
};

}  // namespace hrcsense::ros2
