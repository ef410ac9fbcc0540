// SPDX-License-Identifier: Apache-2.0
// What the interop tests share: a domain per test process, Cyclone on loopback, endpoints with
// the QoS a ROS 2 node would use, a reader that keeps every sample it takes, and the hrcsense
// child's JSON Lines. Types come from idl/ros2_spec_types.idl (written from the spec).
#pragma once

#include "ros2_spec_types.h"

#include <dds/dds.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense::test {

/// 1-200 from the pid, odd, so that domain + 1 is free for a "wrong domain" reader and
/// parallel test processes do not hear each other.
inline uint32_t interop_domain() { return 1U + 2U * (static_cast<uint32_t>(getpid()) % 100U); }

inline bool interop_loopback() {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  return uri != nullptr && std::string(uri).find("cyclonedds-loopback.xml") != std::string::npos;
}
inline constexpr const char* kInteropNoLoopback =
    "CYCLONEDDS_URI is not the tests' loopback configuration (tests/dds/cyclonedds-loopback.xml; ctest sets it)";

/// The reason codes by name, as docs/OUTPUT.md numbers them.
inline const std::map<std::string, int>& reason_numbers() {
  static const std::map<std::string, int> numbers = {
      {"clear", 0}, {"no_foreground", 1}, {"in_slow_zone", 2}, {"in_stop_zone", 3}, {"inside_robot", 4},
      {"non_finite_input", 5}, {"learning_background", 6}, {"checking_background", 7}, {"no_valid_depth", 8},
      {"low_valid_share", 9}, {"background_mismatch", 10}, {"no_robot_model", 11}, {"no_robot_state", 12},
      {"robot_state_stale", 13}, {"foreground_failed", 14}, {"stale_frame", 15}, {"no_frame", 16},
      {"source_ended", 17}, {"frame_limit_reached", 18}, {"stop_requested", 19}, {"source_error", 20},
      {"processing_error", 21}, {"output_error", 22}, {"camera_disconnected", 23}, {"unknown_space", 24},
      {"envelope_invalid", 25}, {"camera_blocked", 26}, {"camera_moved", 27}, {"below_protective_distance", 28},
      {"speed_limited", 29}, {"holding", 30}, {"background_not_empty", 31}, {"camera_pose_mismatch", 33}};
  return numbers;
}

/// A participant on one domain, deleting everything made on it when it goes.
class Participant {
 public:
  explicit Participant(uint32_t domain) : entity_(dds_create_participant(domain, nullptr, nullptr)) {
    EXPECT_GT(entity_, 0) << dds_strretcode(entity_);
  }
  ~Participant() {
    if (entity_ > 0) dds_delete(entity_);
  }
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;
  dds_entity_t get() const { return entity_; }

  /// A reader (writer) on ROS topic `ros_topic` ("rt" + it on DDS).
  dds_entity_t endpoint(bool writer, const dds_topic_descriptor_t& type, const std::string& ros_topic, bool reliable,
                        bool transient_local, int32_t depth, dds_duration_t deadline = DDS_INFINITY) const {
    const std::string name = "rt" + ros_topic;
    const dds_entity_t topic = dds_create_topic(entity_, &type, name.c_str(), nullptr, nullptr);
    EXPECT_GT(topic, 0) << name << ": " << dds_strretcode(topic);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_MSECS(100));
    dds_qset_durability(qos, transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
    if (deadline != DDS_INFINITY) dds_qset_deadline(qos, deadline);
    const dds_entity_t endpoint =
        writer ? dds_create_writer(entity_, topic, qos, nullptr) : dds_create_reader(entity_, topic, qos, nullptr);
    dds_delete_qos(qos);
    EXPECT_GT(endpoint, 0) << name << ": " << dds_strretcode(endpoint);
    return endpoint;
  }

 private:
  dds_entity_t entity_;
};

/// Takes every valid sample of `reader` and hands each to `on_sample`; returns how many.
template <typename T>
int take_all(dds_entity_t reader, const std::function<void(const T&)>& on_sample) {
  constexpr int kBatch = 16;
  int total = 0;
  for (;;) {
    void* samples[kBatch] = {};
    dds_sample_info_t infos[kBatch];
    const int32_t n = dds_take(reader, samples, infos, kBatch, kBatch);
    if (n <= 0) return total;
    for (int32_t i = 0; i < n; ++i) {
      if (infos[i].valid_data) {
        on_sample(*static_cast<const T*>(samples[i]));
        ++total;
      }
    }
    dds_return_loan(reader, samples, n);
  }
}

inline int64_t stamp_ns(const builtin_interfaces_msg_dds__Time_& stamp) {
  return int64_t{stamp.sec} * 1'000'000'000 + stamp.nanosec;
}

/// The JSON lines of a file (a line being written at the end is left out).
inline std::vector<nlohmann::json> json_lines(const std::string& path) {
  std::vector<nlohmann::json> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    try {
      lines.push_back(nlohmann::json::parse(line));
    } catch (const nlohmann::json::exception&) {
      break;
    }
  }
  return lines;
}

/// Polls `done` every 5 ms until it holds or `timeout` passes; returns whether it held.
inline bool poll_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return done();
}

}  // namespace hrcsense::test
