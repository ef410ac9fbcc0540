// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense echo TOPIC`: what hrcsense publishes over ROS 2, read back without a
// ROS installation (docs/ROS2.md).
#include "commands.hpp"
#include "common/app_errors.hpp"

#if HRCSENSE_HAVE_DDS
#include "dds/ros2_echo.hpp"
#include "dds/ros2_messages.hpp"
#endif

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <iostream>
#include <string>

namespace hrcsense::app {

#if HRCSENSE_HAVE_DDS
namespace {

std::atomic<bool> g_echo_stop{false};

extern "C" void on_echo_stop(int signal) {
  g_echo_stop.store(true);
  std::signal(signal, SIG_DFL);  // a second one kills
}

// --domain, else ROS_DOMAIN_ID as a ROS 2 tool would, else 0; -1 for a ROS_DOMAIN_ID that is no domain.
int echo_domain(int flag) {
  if (flag >= 0) return flag;
  const char* env = std::getenv("ROS_DOMAIN_ID");
  if (env == nullptr || *env == '\0') return 0;
  char* end = nullptr;
  const long domain = std::strtol(env, &end, 10);
  return *end == '\0' && domain >= 0 && domain <= 232 ? static_cast<int>(domain) : -1;
}

}  // namespace

int echo_command(const EchoArgs& args) {
  ros2::EchoParams params;
  params.topic = args.topic;
  const std::optional<ros2::EchoType> type =
      args.type.empty() ? ros2::echo_type_of_topic(args.topic) : ros2::echo_type_named(args.type);
  if (!type) {
    return report_error("echo: " + (args.type.empty() ? "no type known for " + args.topic + "; give --type"
                                                      : "--type '" + args.type + "'") +
                            " (verdict, speed_scaling, markers, point_cloud, tf, joint_state or float64)",
                        kExitUsage);
  }
  params.type = *type;
  const int domain = echo_domain(args.domain);
  if (domain < 0) return report_error("echo: ROS_DOMAIN_ID is not a domain from 0 to 232", kExitUsage);
  params.domain_id = static_cast<uint32_t>(domain);
  params.count = args.count;
  params.timeout_s = args.timeout_s;
  params.stop_requested = &g_echo_stop;
  try {
    ros2::dds_topic_name(args.topic);  // a name that is not absolute is the user's error
  } catch (const ros2::Ros2Error& e) {
    return report_error(std::string("echo: ") + e.what(), kExitUsage);
  }
  g_echo_stop.store(false);
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, on_echo_stop);
  ros2::echo_topic(params, std::cout);
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, SIG_DFL);
  return 0;
}

#else

int echo_command(const EchoArgs&) {
  return report_error("echo: this hrcsense was built without Cyclone DDS; install cyclonedds-dev and "
                      "cyclonedds-tools (scripts/setup does) and rebuild",
                      kExitUsage);
}

#endif

}  // namespace hrcsense::app
