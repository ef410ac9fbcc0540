// SPDX-License-Identifier: Apache-2.0
// H1 over loopback, each side in its own process so that samples cross the loopback interface:
// - Ros2/verdict_to_subscriber: from Ros2OutputSink::frame() (the decided result handed to the
//   ROS 2 outputs; processing is not in it) to the Verdict sample taken by a reader in another
//   process waiting on a waitset, p50 and p99, 2000 results 1 ms apart. The stamp carries the
//   send time on the steady clock (CLOCK_MONOTONIC: one clock for the machine).
// - Ros2/joint_states_500hz: the cost of robot.state.source ros2 reading a 500 Hz JointState
//   stream from another process for 5 s: this process's CPU time (the reader thread and
//   Cyclone's receive threads; the main thread sleeps) as a share of one core and per sample.
// - Ros2/parse_joint_state: parse_joint_state on a UR driver's message (seven names, prefixed,
//   shuffled), per call.
// Needs CYCLONEDDS_URI set to tests/dds/cyclonedds-loopback.xml (docs/BENCHMARKS.md).
#include "../common/percentile.hpp"
#include "dds/dds_entity.hpp"
#include "dds/ros2_joint_state.hpp"
#include "dds/ros2_joint_state_source.hpp"
#include "dds/ros2_outputs.hpp"

#include "hrcsense/clock.hpp"

#include <benchmark/benchmark.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <string>
#include <thread>
#include <vector>

#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace hrcsense {
namespace {

using OutClock = std::chrono::steady_clock;

constexpr int kVerdicts = 2000;
constexpr int kJointStates = 2500;  // 5 s at 500 Hz

int64_t out_steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(OutClock::now().time_since_epoch()).count();
}

bool loopback_uri(benchmark::State& state) {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (uri != nullptr && std::string(uri).find("cyclonedds-loopback.xml") != std::string::npos) return true;
  state.SkipWithError("set CYCLONEDDS_URI=file://<checkout>/tests/dds/cyclonedds-loopback.xml (loopback only)");
  return false;
}

// What the two processes share (an anonymous shared mapping made before fork).
struct Handshake {
  std::atomic<bool> reader_ready{false};
  std::atomic<bool> heard{false};  ///< the reader took a warm-up sample: the writer is matched
  std::atomic<bool> done{false};
};

template <typename T>
T* shared_new() {
  void* mapping = mmap(nullptr, sizeof(T), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  return mapping == MAP_FAILED ? nullptr : new (mapping) T();
}

// A result as the monitor decides one in the moving cell: slow, a contact on link 3.
FrameResult slow_result() {
  FrameResult r;
  r.valid = true;
  r.verdict.state = VerdictState::slow;
  r.verdict.code = ReasonCode::speed_limited;
  r.verdict.speed_scale = 0.6F;
  r.verdict.protective_distance_m = 0.9F;
  r.contact.valid = true;
  r.contact.distance_m = 1.1F;
  r.contact.closest_base = Eigen::Vector3f(0.8F, 0.4F, 0.9F);
  r.contact.closest_robot_base = Eigen::Vector3f(0.2F, 0.1F, 0.6F);
  r.governing_link = 3;
  r.links.push_back({3, r.contact, 0.4F, 0.02F});
  r.link_protective_distance_m.push_back(0.9F);
  r.robot_state.valid = true;
  r.robot_state.q_rad = {-0.94, -1.5, 1.4, -1.7, -1.57, 0.0};
  return r;
}

[[noreturn]] void write_verdicts_in_child(Handshake& shake, uint32_t domain) {
  {
    ros2::Ros2OutputParams params;
    params.domain_id = domain;
    params.node_namespace = "/bench";
    params.cloud_hz = 0.0;
    params.robot.arm = builtin_robot(BuiltinArm::ur5);
    ros2::Ros2OutputSink sink(params);
    RunHeader header;
    header.source.nominal_fps = 30.0;
    sink.header(header);
    FrameResult result = slow_result();
    for (int i = 0; i < 5000 && !shake.reader_ready.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    result.timestamp_ns = 1;  // warm-up: not measured
    for (int i = 0; i < 5000 && !shake.heard.load(); ++i) {
      sink.frame(result);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const OutClock::time_point start = OutClock::now();
    for (int i = 0; i < kVerdicts; ++i) {
      std::this_thread::sleep_until(start + std::chrono::milliseconds(i));
      result.timestamp_ns = out_steady_ns();
      sink.frame(result);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // let the last samples out
    shake.done.store(true);
  }
  std::_Exit(0);
}

void BM_VerdictToSubscriber(benchmark::State& state) {
  if (!loopback_uri(state)) return;
  const uint32_t domain = 202;
  for (auto _ : state) {
    Handshake* shake = shared_new<Handshake>();
    if (shake == nullptr) {
      state.SkipWithError("mmap failed");
      return;
    }
    const pid_t child = fork();  // before this process makes any DDS entity of this iteration
    if (child == 0) write_verdicts_in_child(*shake, domain);
    std::vector<double> latency_us;
    {
      ros2::ParticipantScope scope(domain);
      const dds_entity_t topic = scope.own(dds_create_topic(scope.participant(), &hrcsense_msgs_msg_dds__Verdict__desc,
                                                            "rt/bench/verdict", nullptr, nullptr),
                                           "topic");
      const ros2::QosHandle qos(ros2::EndpointQos{true, false, 64});
      const dds_entity_t reader = scope.own(dds_create_reader(scope.participant(), topic, qos.get(), nullptr), "reader");
      const dds_entity_t waitset = scope.own(dds_create_waitset(scope.participant()), "waitset");
      const dds_entity_t condition = scope.own(dds_create_readcondition(reader, DDS_ANY_STATE), "condition");
      dds_waitset_attach(waitset, condition, condition);
      shake->reader_ready.store(true);
      int idle_after_done = 0;
      while (static_cast<int>(latency_us.size()) < kVerdicts && idle_after_done < 5) {
        if (dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(100)) <= 0) {
          idle_after_done += shake->done.load() ? 1 : 0;
          continue;
        }
        void* samples[16] = {};
        dds_sample_info_t infos[16];
        const int32_t n = dds_take(reader, samples, infos, 16, 16);
        const int64_t now_ns = out_steady_ns();
        for (int32_t i = 0; i < n; ++i) {
          if (!infos[i].valid_data) continue;
          const auto& v = *static_cast<const hrcsense_msgs_msg_dds__Verdict_*>(samples[i]);
          const int64_t sent_ns = ros2::stamp_ns(v.header.stamp);
          if (sent_ns <= 1) {
            shake->heard.store(true);
            continue;
          }
          latency_us.push_back(static_cast<double>(now_ns - sent_ns) / 1e3);
        }
        if (n > 0) dds_return_loan(reader, samples, n);
      }
    }
    waitpid(child, nullptr, 0);
    state.counters["p50_us"] = bench::percentile(latency_us, 0.50);
    state.counters["p99_us"] = bench::percentile(latency_us, 0.99);
    state.counters["received_share"] = static_cast<double>(latency_us.size()) / kVerdicts;
    shake->~Handshake();
    munmap(shake, sizeof(Handshake));
  }
}

[[noreturn]] void publish_joint_states_in_child(Handshake& shake, uint32_t domain) {
  {
    ros2::ParticipantScope scope(domain);
    const dds_entity_t topic = scope.own(dds_create_topic(scope.participant(), &sensor_msgs_msg_dds__JointState__desc,
                                                          "rt/bench/joint_states", nullptr, nullptr),
                                         "topic");
    const ros2::QosHandle qos(ros2::EndpointQos{true, false, 10});  // ROS's default QoS, as joint_state_broadcaster
    const dds_entity_t writer = scope.own(dds_create_writer(scope.participant(), topic, qos.get(), nullptr), "writer");
    for (int i = 0; i < 5000 && !shake.reader_ready.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));  // discovery
    const char* names[] = {"ur_wrist_3_joint", "ur_elbow_joint", "ur_gripper_joint", "ur_shoulder_lift_joint",
                           "ur_wrist_1_joint", "ur_shoulder_pan_joint", "ur_wrist_2_joint"};
    double position[7] = {0.0, 1.4, 0.0, -1.5, -1.7, -0.94, -1.57};
    double velocity[7] = {0.1, 0.1, 0.0, 0.1, 0.1, 0.1, 0.1};
    const OutClock::time_point start = OutClock::now();
    for (int i = 0; i < kJointStates; ++i) {
      std::this_thread::sleep_until(start + std::chrono::microseconds(2000 * i));
      for (double& q : position) q += 0.1 * 0.002;  // moving at 0.1 rad/s
      const int64_t wall_ns =
          std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
              .count();
      sensor_msgs_msg_dds__JointState_ msg{};
      msg.header.stamp = ros2::stamp_from_ns(wall_ns);
      msg.header.frame_id = const_cast<char*>("");
      msg.name._buffer = const_cast<char**>(names);
      msg.name._length = msg.name._maximum = 7;
      msg.position._buffer = position;
      msg.position._length = msg.position._maximum = 7;
      msg.velocity._buffer = velocity;
      msg.velocity._length = msg.velocity._maximum = 7;
      dds_write(writer, &msg);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    shake.done.store(true);
  }
  std::_Exit(0);
}

double process_cpu_s() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

void BM_JointStates500Hz(benchmark::State& state) {
  if (!loopback_uri(state)) return;
  const uint32_t domain = 203;
  for (auto _ : state) {
    Handshake* shake = shared_new<Handshake>();
    if (shake == nullptr) {
      state.SkipWithError("mmap failed");
      return;
    }
    const pid_t child = fork();
    if (child == 0) publish_joint_states_in_child(*shake, domain);
    SteadyClock clock;
    int64_t accepted = 0;
    double cpu_s = 0.0, wall_s = 0.0;
    {
      ros2::Ros2JointStateParams params;
      params.topic = "/bench/joint_states";
      params.tf_prefix = "ur_";
      params.speed_scaling_topic.clear();
      params.domain_id = domain;
      ros2::Ros2JointStateSource source(params, clock);
      shake->reader_ready.store(true);
      // From the first accepted sample to the publisher's end, this thread asleep.
      for (int i = 0; i < 10000 && source.stats().samples.accepted == 0; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      const double cpu0 = process_cpu_s();
      const auto wall0 = OutClock::now();
      const int64_t accepted0 = source.stats().samples.accepted;
      for (int i = 0; i < 200 && !shake->done.load(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      cpu_s = process_cpu_s() - cpu0;
      wall_s = std::chrono::duration<double>(OutClock::now() - wall0).count();
      accepted = source.stats().samples.accepted - accepted0;
    }
    waitpid(child, nullptr, 0);
    state.counters["cpu_percent_of_a_core"] = wall_s > 0.0 ? 100.0 * cpu_s / wall_s : 0.0;
    state.counters["cpu_us_per_sample"] = accepted > 0 ? 1e6 * cpu_s / static_cast<double>(accepted) : 0.0;
    state.counters["accepted_share"] = static_cast<double>(accepted) / kJointStates;
    shake->~Handshake();
    munmap(shake, sizeof(Handshake));
  }
}

void BM_ParseJointState(benchmark::State& state) {
  char* names[] = {const_cast<char*>("ur_wrist_3_joint"), const_cast<char*>("ur_elbow_joint"),
                   const_cast<char*>("ur_gripper_joint"), const_cast<char*>("ur_shoulder_lift_joint"),
                   const_cast<char*>("ur_wrist_1_joint"), const_cast<char*>("ur_shoulder_pan_joint"),
                   const_cast<char*>("ur_wrist_2_joint")};
  double position[7] = {0.0, 1.4, 0.0, -1.5, -1.7, -0.94, -1.57};
  double velocity[7] = {};
  sensor_msgs_msg_dds__JointState_ msg{};
  msg.header.stamp.sec = 1'700'000'000;
  msg.header.frame_id = const_cast<char*>("");
  msg.name._buffer = names;
  msg.name._length = msg.name._maximum = 7;
  msg.position._buffer = position;
  msg.position._length = msg.position._maximum = 7;
  msg.velocity._buffer = velocity;
  msg.velocity._length = msg.velocity._maximum = 7;
  const ros2::JointNames joint_names = ros2::ur_joint_names("ur_");
  for (auto _ : state) benchmark::DoNotOptimize(ros2::parse_joint_state(msg, joint_names));
}

BENCHMARK(BM_VerdictToSubscriber)->Name("Ros2/verdict_to_subscriber")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_JointStates500Hz)->Name("Ros2/joint_states_500hz")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ParseJointState)->Name("Ros2/parse_joint_state");

}  // namespace
}  // namespace hrcsense
