// SPDX-License-Identifier: Apache-2.0
// `hrcsense fuse` fed 4 or 16 synthetic cameras at 90 frames/s over loopback DDS (issue H2's scaling
// figure; docs/BENCHMARKS.md, "Cells with several cameras"). This process publishes, the fuser is
// the real command in a child process, configured with the cameras, a UR5 and the default
// 3 × 3 × 2 m grid at 0.05 m (144 000 cubes, 18 kB of bits in every measurement). Each camera's
// measurement is a valid one with three link contacts, stamped now; the fuser ends by itself
// after --frames instants. Reported: the fuser's CPU (its own user + system time over the wall
// time, from getrusage of the child), measurements sent and accepted, instants decided, and the
// fused latency and the fuser's added latency from its JSON Lines (p50, p99).
// Needs CYCLONEDDS_URI set to tests/dds/cyclonedds-loopback.xml (docs/BENCHMARKS.md); with
// HRCSENSE_BENCH_FUSER_FIFO=N the fuser runs under SCHED_FIFO priority N; with
// HRCSENSE_BENCH_FUSER_CPU=N it runs alone on CPU N and this process's threads on the others.
#include "../common/percentile.hpp"
#include "dds/measurement_endpoints.hpp"

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

#include <sched.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hrcsense {
namespace {

constexpr double kFps = 90.0;
constexpr int kInstants = 900;  // 10 s at 90 frames/s

std::string cell_yaml(uint32_t domain, int cameras) {
  std::string yaml = "source: {type: sim}\nsim: {fps: 90, frames: 100000, color: false}\n"
                     "robot: {model: ur5, padding_m: 0.05, joints_rad: [-2.74, -1.0, 1.6, -2.17, -1.57, 0.0]}\nsafety: {mode: ssm}\n"
                     "ros2: {domain_id: " + std::to_string(domain) + ", namespace: /fuser_bench}\ncameras:\n";
  for (int c = 0; c < cameras; ++c) {
    yaml += "  - name: cam" + std::to_string(c) + "\n    T_base_camera: {translation_m: [2.0, " + std::to_string(0.1 * c) +
            ", 1.6], rotation_rpy_deg: [-125, 0, 90]}\n    fps: 90\n";
  }
  return yaml;
}

// User + system time of the children waited for so far, s.
double children_cpu_s() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
}

// Every thread of this process onto `cpus` (Cyclone's own threads included).
void pin_this_process(const cpu_set_t& cpus) {
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    const auto tid = static_cast<pid_t>(std::stol(task.path().filename().string()));
    sched_setaffinity(tid, sizeof(cpus), &cpus);
  }
}

void BM_Fuser90Hz(benchmark::State& state) {
  const auto cameras = static_cast<int>(state.range(0));
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (uri == nullptr || std::string(uri).find("cyclonedds-loopback.xml") == std::string::npos) {
    state.SkipWithError("set CYCLONEDDS_URI=file://<checkout>/tests/dds/cyclonedds-loopback.xml (loopback only)");
    return;
  }
  const uint32_t domain = 204;
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("hrcsense_fuser_bench_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string config = (dir / "cell.yaml").string();
  const std::string out = (dir / "fused.jsonl").string();
  std::ofstream(config) << cell_yaml(domain, cameras);

  for (auto _ : state) {
    std::vector<std::string> args = {"hrcsense", "fuse", "--config", config, "--frames", std::to_string(kInstants), "--out", out};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    // Children's CPU accumulates over the process: this run's fuser is the difference.
    const double cpu_before_s = children_cpu_s();
    pid_t fuser = -1;
    // HRCSENSE_BENCH_FUSER_FIFO=N: the fuser under SCHED_FIFO priority N (root), as a decision
    // host would run it (`chrt -f N hrcsense fuse`); the publishers stay at normal priority.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    if (const char* fifo = std::getenv("HRCSENSE_BENCH_FUSER_FIFO")) {
      sched_param priority{};
      priority.sched_priority = std::atoi(fifo);
      posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSCHEDULER);
      posix_spawnattr_setschedpolicy(&attributes, SCHED_FIFO);
      posix_spawnattr_setschedparam(&attributes, &priority);
    }
    // HRCSENSE_BENCH_FUSER_CPU=N: the child inherits the spawning thread's CPUs, so the thread
    // moves to N for the spawn and the whole process to the other CPUs after it.
    cpu_set_t all_cpus;
    sched_getaffinity(0, sizeof(all_cpus), &all_cpus);
    const char* fuser_cpu = std::getenv("HRCSENSE_BENCH_FUSER_CPU");
    if (fuser_cpu != nullptr) {
      cpu_set_t only;
      CPU_ZERO(&only);
      CPU_SET(std::atoi(fuser_cpu), &only);
      sched_setaffinity(0, sizeof(only), &only);
    }
    const int spawned = posix_spawn(&fuser, HRCSENSE_BENCH_CLI, nullptr, &attributes, argv.data(), environ);
    posix_spawnattr_destroy(&attributes);
    if (fuser_cpu != nullptr) {
      cpu_set_t rest = all_cpus;
      CPU_CLR(std::atoi(fuser_cpu), &rest);
      pin_this_process(CPU_COUNT(&rest) > 0 ? rest : all_cpus);
    }
    if (spawned != 0) {
      state.SkipWithError("cannot start hrcsense fuse");
      return;
    }
    // The cameras: one writer each in this process, a valid measurement every 1/90 s.
    std::vector<std::unique_ptr<ros2::MeasurementSink>> sinks;
    for (int c = 0; c < cameras; ++c) {
      ros2::MeasurementWriterParams params;
      params.domain_id = domain;
      params.node_namespace = "/fuser_bench";
      params.camera_name = "cam" + std::to_string(c);
      params.nominal_fps = kFps;
      sinks.push_back(std::make_unique<ros2::MeasurementSink>(params));
      RunHeader header;
      header.session = 1000U + static_cast<uint32_t>(c);
      sinks.back()->header(header);
    }
    FrameResult result;
    result.valid = true;
    result.clocked = true;
    result.foreground_points = 2000;
    result.robot_state.valid = true;
    result.robot_state.q_rad = {-2.74, -1.0, 1.6, -2.17, -1.57, 0.0};
    for (int link = 1; link <= 3; ++link) {
      LinkContact l;
      l.link = link;
      l.contact.valid = true;
      l.contact.distance_m = 1.2F + 0.1F * static_cast<float>(link);
      l.speed_towards_mps = 0.2F;
      l.distance_uncertainty_m = 0.03F;
      result.links.push_back(l);
    }
    result.contact = result.links.front().contact;
    result.seen_free.reset(144000);
    std::mt19937 random(5);
    for (size_t i = 0; i < result.seen_free.cells; ++i) {
      if (random() % 4 != 0) result.seen_free.set(i);
    }
    // Give discovery a second, then publish until the fuser has its instants (bounded).
    std::this_thread::sleep_for(std::chrono::seconds(1));
    const auto period = std::chrono::nanoseconds(static_cast<int64_t>(1e9 / kFps));
    auto next = std::chrono::steady_clock::now();
    int64_t sent = 0;
    int status = 0;
    const auto deadline = next + std::chrono::seconds(30);
    while (waitpid(fuser, &status, WNOHANG) == 0 && std::chrono::steady_clock::now() < deadline) {
      result.seen_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
      result.host_time_ns = result.seen_ns;
      ++result.frame;
      for (auto& sink : sinks) sink->frame(result);
      sent += cameras;
      next += period;
      std::this_thread::sleep_until(next);
    }
    if (fuser_cpu != nullptr) pin_this_process(all_cpus);
    if (waitpid(fuser, &status, WNOHANG) == 0) {
      kill(fuser, SIGKILL);
      waitpid(fuser, &status, 0);
      state.SkipWithError("the fuser did not end within 30 s");
      return;
    }
    const double cpu_s = children_cpu_s() - cpu_before_s;
    std::vector<double> latency_us, added_us;
    double wall_s = 0.0;
    int64_t accepted = 0;
    std::ifstream in(out);
    for (std::string line; std::getline(in, line);) {
      const nlohmann::json j = nlohmann::json::parse(line);
      if (j["type"] == "frame" && j["valid"].get<bool>()) {
        latency_us.push_back(j["latency_us"].get<double>());
        added_us.push_back(j["timings_us"]["fusion_added"].get<double>());
      } else if (j["type"] == "summary") {
        wall_s = j["wall_s"].get<double>();
        for (const auto& c : j["cameras"]) accepted += c["accepted"].get<int64_t>();
      }
    }
    state.counters["fuser_cpu_share"] = wall_s > 0.0 ? cpu_s / wall_s : 0.0;
    state.counters["sent"] = static_cast<double>(sent);
    state.counters["accepted"] = static_cast<double>(accepted);
    state.counters["valid_instants"] = static_cast<double>(latency_us.size());
    state.counters["latency_p50_us"] = bench::percentile(latency_us, 0.5);
    state.counters["latency_p99_us"] = bench::percentile(latency_us, 0.99);
    state.counters["added_p50_us"] = bench::percentile(added_us, 0.5);
    state.counters["added_p99_us"] = bench::percentile(added_us, 0.99);
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_Fuser90Hz)
    ->Name("Fuser/90fps/loopback")
    ->ArgName("cams")
    ->Arg(4)
    ->Arg(16)
    ->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
