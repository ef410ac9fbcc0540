// SPDX-License-Identifier: Apache-2.0
// Test support: an RtdeRobotState and the fake controller it talks to (fake_rtde_controller.hpp)
// on one FakeClock, shared by the RTDE client, status and acceptance tests.
#pragma once

#include "fake_rtde_controller.hpp"

#include "hrcsense/net/rtde.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <thread>

namespace hrcsense::test {

// Waits (real time, at most `seconds`) until `done()`; false on the deadline.
inline bool wait_until(const std::function<bool()>& done, double seconds = 10.0) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::yield();
  }
  return true;
}

// A client and the fake controller it talks to, on one FakeClock. `check` runs on the fake's
// thread after the client has read each data package (the clock then stands at its arrival).
struct Rig {
  FakeClock clock{1'000'000'000'000};  // 1000 s
  FakeRtdeController fake;
  std::unique_ptr<RtdeRobotState> client;
  std::atomic<bool> stopping{false};
  std::function<void(int64_t)> check;

  /// `adjust` may change the client's parameters (an arm for the TCP pose check) before it starts.
  Rig(const FakeRtdeScript& script, double frequency_hz, const std::function<void(RtdeParams&)>& adjust = {})
      : fake(script, clock) {
    RtdeParams params;
    params.host = "127.0.0.1";
    params.port = fake.port();
    params.frequency_hz = frequency_hz;
    if (adjust) adjust(params);
    client = std::make_unique<RtdeRobotState>(params, clock);
    fake.start([this](int64_t sent) {
      const bool read = wait_until([&] { return stopping || client->status().data_packages >= sent; });
      if (read && !stopping && check) check(sent);
    });
  }
  ~Rig() {
    stopping = true;
    fake.stop();     // no more calls into the client
    client.reset();  // joins the reader thread
  }
  bool consumed(int64_t packages) {
    return wait_until([&] { return fake.data_sent() >= packages && client->status().data_packages >= packages; });
  }
  // The fake's q of joint j at host time t_ns (its controller clock is the FakeClock + offset).
  static double expected_q(int64_t t_ns, int j) {
    return fake_q(static_cast<double>(t_ns) * 1e-9 + FakeRtdeScript{}.controller_offset_s, j);
  }
  // Valid, and q matches the trajectory at `t_ns` within `tolerance_rad`.
  bool matches_at(int64_t t_ns, double tolerance_rad = 1e-5) {
    RobotState state;
    if (!client->state_at(t_ns, state) || state.origin != RobotStateOrigin::rtde) return false;
    for (int j = 0; j < kJointCount; ++j) {
      if (!(std::fabs(state.q_rad[j] - expected_q(t_ns, j)) <= tolerance_rad)) return false;
    }
    return true;
  }
  bool valid_now() {
    RobotState state;
    return client->state_at(clock.now_ns(), state);
  }
};

}  // namespace hrcsense::test
