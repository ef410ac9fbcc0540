// SPDX-License-Identifier: Apache-2.0
// A participant of the DDS Security tests (dds_security_test.cpp), one per process: Cyclone
// takes its security settings from CYCLONEDDS_URI when a process makes its first participant,
// so a secure and an unsecured participant on one domain need two processes. It uses the
// project's own endpoints (MeasurementSink, MeasurementReader), configured by nothing but
// CYCLONEDDS_URI, as `hrcsense run --camera` and `hrcsense fuse` are.
//
//   dds_security_peer write DOMAIN NAMESPACE CAMERA SESSION SECONDS
//     writes a measurement of CAMERA, session SESSION, every 50 ms for SECONDS;
//   dds_security_peer read DOMAIN NAMESPACE CAMERA SECONDS
//     reads CAMERA's topic for SECONDS.
// Each prints "ready" once its endpoint exists, or "error <why>" and exits 3. The reader prints
// "session <n>" the first time it receives a session, "writers <n>" when the count of writers
// matched changes and "unconfigured <n>" when the count of writers discovered on other cameras'
// measurement topics does (MeasurementReader::unconfigured_publishers). Every line is flushed; every loop ends after SECONDS (at most 60).
#include "dds/measurement_endpoints.hpp"
#include "dds/ros2_messages.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace {

using SteadyClock = std::chrono::steady_clock;

void say(const std::string& line) {
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

SteadyClock::time_point deadline_after(const std::string& seconds) {
  const double s = std::clamp(std::stod(seconds), 0.0, 60.0);
  return SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(s));
}

int write_measurements(uint32_t domain, const std::string& ns, const std::string& camera, uint32_t session,
                       const std::string& seconds) {
  hrcsense::ros2::MeasurementWriterParams params;
  params.domain_id = domain;
  params.node_namespace = ns;
  params.camera_name = camera;
  params.nominal_fps = 20.0;
  hrcsense::ros2::MeasurementSink sink(params);
  hrcsense::RunHeader header;
  header.session = session;
  sink.header(header);
  say("ready");
  hrcsense::FrameResult result;
  result.valid = true;
  result.clocked = true;
  result.foreground_points = 0;
  const SteadyClock::time_point end = deadline_after(seconds);
  for (int64_t frame = 1; SteadyClock::now() < end; ++frame) {
    result.frame = frame;
    result.seen_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now().time_since_epoch()).count();
    sink.frame(result);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

int read_measurements(uint32_t domain, const std::string& ns, const std::string& camera, const std::string& seconds) {
  hrcsense::ros2::MeasurementReader reader(domain, ns, {camera});
  say("ready");
  std::set<uint32_t> sessions;
  int32_t writers = 0;
  int64_t unconfigured = 0;
  const SteadyClock::time_point end = deadline_after(seconds);
  while (SteadyClock::now() < end) {
    reader.wait(50'000'000);
    reader.take([&](size_t, const hrcsense::CameraMeasurement& m, const std::string& problem) {
      if (problem.empty() && sessions.insert(m.session).second) say("session " + std::to_string(m.session));
    });
    const int32_t now_matched = reader.writers(0);
    if (now_matched != writers) say("writers " + std::to_string(now_matched));
    writers = now_matched;
    if (reader.unconfigured_publishers() != unconfigured) {
      unconfigured = reader.unconfigured_publishers();
      say("unconfigured " + std::to_string(unconfigured));
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv, argv + argc);
  try {
    if (args.size() == 7 && args[1] == "write") {
      return write_measurements(static_cast<uint32_t>(std::stoul(args[2])), args[3], args[4],
                                static_cast<uint32_t>(std::stoul(args[5])), args[6]);
    }
    if (args.size() == 6 && args[1] == "read") {
      return read_measurements(static_cast<uint32_t>(std::stoul(args[2])), args[3], args[4], args[5]);
    }
    say("error usage: dds_security_peer write DOMAIN NAMESPACE CAMERA SESSION SECONDS | read DOMAIN NAMESPACE CAMERA SECONDS");
    return 2;
  } catch (const std::exception& e) {
    say(std::string("error ") + e.what());
    return 3;
  }
}
