// SPDX-License-Identifier: Apache-2.0
// The link to the controller (UdpLinkSink) on loopback, on the steady clock:
// - Link/frame_to_datagram: from UdpLinkSink::frame() being called to the datagram being
//   received by a socket that a second thread waits on (poll, then recv), p50 and p99 over
//   2000 frames sent 1 ms apart, so that the receiver is asleep at every send as a controller's
//   would be (its wake-up is in the figure). Budget (issue 17): p99 <= 1 ms. The /json variant
//   sends the frame's JSON line.
// - Link/heartbeat_period: heartbeats at the default 20 Hz with no frames; the intervals
//   between their arrivals against the nominal 50 ms (jitter p50, p99, max) and their mean.
#include "../common/percentile.hpp"
#include "hrcsense/net/link.hpp"

#include "hrcsense/clock.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace {

using bench::percentile;

// A socket on 127.0.0.1 (ephemeral port) and a thread that stamps each datagram's arrival on
// the steady clock, until `expected` arrived or 200 ms passed without one.
class StampingReceiver {
 public:
  explicit StampingReceiver(size_t expected) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_in self{};
    self.sin_family = AF_INET;
    self.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ok_ = fd_ >= 0 && ::bind(fd_, reinterpret_cast<const sockaddr*>(&self), sizeof self) == 0;
    socklen_t length = sizeof self;
    if (ok_) ::getsockname(fd_, reinterpret_cast<sockaddr*>(&self), &length);
    port_ = ntohs(self.sin_port);
    arrivals_.reserve(expected);
    thread_ = std::thread([this, expected] {
      const SteadyClock clock;
      char buffer[65536];
      while (ok_ && arrivals_.size() < expected) {
        pollfd fds{fd_, POLLIN, 0};
        if (::poll(&fds, 1, started_.load() ? 200 : 5000) <= 0) break;
        const ssize_t got = ::recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT);
        if (got <= 0) continue;
        arrivals_.push_back(clock.now_ns());
        started_ = true;
      }
    });
  }
  ~StampingReceiver() {
    if (thread_.joinable()) thread_.join();
    if (fd_ >= 0) ::close(fd_);
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  bool ok() const { return ok_; }
  /// Waits for the thread to end, then the arrival times, ns.
  const std::vector<int64_t>& arrivals() {
    if (thread_.joinable()) thread_.join();
    return arrivals_;
  }

 private:
  int fd_ = -1;
  bool ok_ = false;
  uint16_t port_ = 0;
  std::atomic<bool> started_{false};
  std::vector<int64_t> arrivals_;
  std::thread thread_;
};

FrameResult bench_frame(int64_t index, int64_t host_time_ns) {
  FrameResult r;
  r.frame = index;
  r.timestamp_ns = r.host_time_ns = host_time_ns;
  r.valid = true;
  r.verdict.state = VerdictState::slow;
  r.verdict.code = ReasonCode::in_slow_zone;
  r.verdict.reason = "in slow zone (0.812 m < 1.000 m)";
  r.verdict.speed_scale = 0.62F;
  r.verdict.protective_distance_m = 0.5F;
  r.contact.valid = true;
  r.contact.distance_m = 0.812F;
  r.foreground_points = 5321;
  r.robot_state_age_ms = 3.2;
  r.timings = {{"filters", 2100.0}, {"background", 300.0}, {"foreground", 900.0}, {"proximity", 450.0}};
  return r;
}

void BM_FrameToDatagram(benchmark::State& state, UdpLinkParams::Format format) {
  constexpr int kFrames = 2000;
  for (auto _ : state) {
    StampingReceiver receiver(kFrames);
    if (!receiver.ok()) {
      state.SkipWithError("no loopback socket");
      return;
    }
    SteadyClock clock;
    UdpLinkParams params;
    params.address = receiver.address();
    params.format = format;
    params.heartbeat_hz = 1.0;  // frames every 1 ms: no heartbeat is ever due
    std::vector<int64_t> sent_ns(kFrames);
    {
      UdpLinkSink sink(params, clock);
      sink.header(RunHeader{});
      FrameResult result = bench_frame(0, clock.now_ns());
      for (int k = 0; k < kFrames; ++k) {
        result.frame = k;
        result.host_time_ns = result.timestamp_ns = clock.now_ns();
        sent_ns[static_cast<size_t>(k)] = clock.now_ns();
        sink.frame(result);
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      // One final stop more: not timed.
    }
    const std::vector<int64_t>& arrivals = receiver.arrivals();
    std::vector<double> latency_us;
    const size_t n = std::min<size_t>(kFrames, arrivals.size());
    for (size_t k = 0; k < n; ++k) latency_us.push_back(static_cast<double>(arrivals[k] - sent_ns[k]) / 1e3);
    state.counters["p50_us"] = percentile(latency_us, 0.50);
    state.counters["p99_us"] = percentile(latency_us, 0.99);
    state.counters["max_us"] = percentile(latency_us, 1.0);
    state.counters["received_share"] = static_cast<double>(n) / kFrames;
  }
}

void BM_HeartbeatPeriod(benchmark::State& state) {
  constexpr int kHeartbeats = 61;  // 60 intervals, 3 s
  constexpr double kHz = 20.0;
  const double nominal_us = 1e6 / kHz;
  for (auto _ : state) {
    StampingReceiver receiver(kHeartbeats);
    if (!receiver.ok()) {
      state.SkipWithError("no loopback socket");
      return;
    }
    SteadyClock clock;
    UdpLinkParams params;
    params.address = receiver.address();
    params.heartbeat_hz = kHz;
    UdpLinkSink sink(params, clock);
    const std::vector<int64_t>& arrivals = receiver.arrivals();  // the heartbeats only
    std::vector<double> jitter_us;
    double sum_us = 0.0;
    for (size_t k = 1; k < arrivals.size(); ++k) {
      const double interval_us = static_cast<double>(arrivals[k] - arrivals[k - 1]) / 1e3;
      sum_us += interval_us;
      jitter_us.push_back(std::abs(interval_us - nominal_us));
    }
    state.counters["period_mean_ms"] = jitter_us.empty() ? 0.0 : sum_us / static_cast<double>(jitter_us.size()) / 1e3;
    state.counters["jitter_p50_us"] = percentile(jitter_us, 0.50);
    state.counters["jitter_p99_us"] = percentile(jitter_us, 0.99);
    state.counters["jitter_max_us"] = percentile(jitter_us, 1.0);
    state.counters["heartbeats"] = static_cast<double>(arrivals.size());
  }
}

BENCHMARK_CAPTURE(BM_FrameToDatagram, binary, UdpLinkParams::Format::binary)
    ->Name("Link/frame_to_datagram")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FrameToDatagram, json, UdpLinkParams::Format::json)
    ->Name("Link/frame_to_datagram/json")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_HeartbeatPeriod)->Name("Link/heartbeat_period")->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense
