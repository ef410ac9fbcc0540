// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense publish`: the configured source (simulator, .bag, folder) as a
// realsense-ros camera's ROS 2 topics over Cyclone DDS, at its recorded rate
// (docs/CAMERAS.md, "Replaying into ROS 2").
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "common/assembly.hpp"

#include "hrcsense/config/config.hpp"

#if HRCSENSE_HAVE_DDS
#include "dds/ros2_publisher.hpp"
#endif

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <thread>

namespace hrcsense::app {

#if HRCSENSE_HAVE_DDS
namespace {

std::atomic<bool> g_publish_stop{false};

extern "C" void on_publish_stop(int signal) {
  g_publish_stop.store(true);
  std::signal(signal, SIG_DFL);  // a second one kills
}

// The wait before a frame, from the step between its timestamp and the previous one: a step
// that is not positive (no timestamps, a loop) is one nominal period, and one longer than a
// second (a jump in the recording) is cut to a second, so a replay never sleeps for long.
std::chrono::nanoseconds publish_step(int64_t step_ns, double nominal_fps) {
  if (step_ns <= 0) step_ns = static_cast<int64_t>(1e9 / std::max(1.0, nominal_fps));
  return std::chrono::nanoseconds(std::min<int64_t>(step_ns, 1'000'000'000));
}

// Sleeps until `due` in slices, so that a stop request ends the wait soon.
void sleep_until_or_stop(std::chrono::steady_clock::time_point due) {
  while (!g_publish_stop.load() && std::chrono::steady_clock::now() < due) {
    std::this_thread::sleep_until(std::min(due, std::chrono::steady_clock::now() + std::chrono::milliseconds(50)));
  }
}

}  // namespace

int publish_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets);
  SourceOptions source_options;
  source_options.with_color = true;
  source_options.stop_requested = &g_publish_stop;
  std::unique_ptr<Source> source = make_source(config, source_options);
  const SourceInfo info = source->info();
  ros2::Ros2PublisherParams params;
  params.node_namespace = config.publish.node_namespace;
  params.domain_id = static_cast<uint32_t>(config.publish.domain_id);
  ros2::Ros2CameraPublisher publisher(params);
  spdlog::info("publishing {} as {} on DDS domain {}", info.description, publisher.topics().depth_image,
               params.domain_id);

  g_publish_stop.store(false);
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, on_publish_stop);
  const int wanted = config.publish.wait_for_subscribers;
  if (wanted > 0 && !publisher.wait_for_subscribers(wanted, config.publish.wait_timeout_s)) {
    for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, SIG_DFL);
    return report_error("publish: fewer than " + std::to_string(wanted) + " subscribers on " +
                            publisher.topics().depth_image + " within " +
                            std::to_string(config.publish.wait_timeout_s) + " s (publish.wait_timeout_s)",
                        kExitRuntime);
  }

  Frame frame;
  int64_t published = 0;
  int64_t previous_ns = 0;
  auto due = std::chrono::steady_clock::now();
  std::string source_error;
  while (!g_publish_stop.load() && (args.frames < 0 || published < args.frames)) {
    const Source::Status status = source->next(frame);
    if (status == Source::Status::end) break;
    if (status == Source::Status::idle) continue;
    if (status == Source::Status::error) {
      source_error = source->error();
      break;
    }
    if (published > 0) due += publish_step(frame.timestamp_ns - previous_ns, info.nominal_fps);
    previous_ns = frame.timestamp_ns;
    sleep_until_or_stop(due);
    if (g_publish_stop.load()) break;
    publisher.publish(frame);  // Ros2Error: the write failed, naming the topic
    ++published;
  }
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, SIG_DFL);
  spdlog::info("published {} frames on {}", published, publisher.topics().depth_image);
  if (!source_error.empty()) return report_error(source_error, kExitRuntime);
  return 0;
}

#else

int publish_command(const CommandArgs&) {
  return report_error("publish: this hrcsense was built without Cyclone DDS; install cyclonedds-dev and "
                      "cyclonedds-tools (scripts/setup does) and rebuild",
                      kExitUsage);
}

#endif

}  // namespace hrcsense::app
