// SPDX-License-Identifier: Apache-2.0
// Test support: an in-process UR controller speaking RTDE on 127.0.0.1 (ephemeral port), written
// from ../shared/specs/ur-rtde.md independently of src/net/. It plays a joint trajectory at the
// frequency the client asks for, with its timestamps on a schedule of the clock it is given
// (the controller's clock is that clock plus an offset), and misbehaves on request. On a
// FakeClock, after each data package it calls the test's `after_send` (which waits until the
// client has read it), so a 30 s trajectory plays in well under a second and every arrival time
// is exact; on the steady clock it streams in real time, for a client in another process.
// A client that sets up inputs instead of outputs (link.rtde.write) gets an input session: the
// fake answers the setup with this controller's types (IN_USE for the inputs the script says
// another client owns), then records every input DATA_PACKAGE it receives, decoded by those
// types, and counts the ones that do not fit the recipe.
#pragma once

#include "hrcsense/clock.hpp"
#include "hrcsense/types.hpp"

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace hrcsense::test {

enum class RtdeFault { none, close, stall, truncated, oversized, unknown_type, wrong_recipe, nan_joints,
                       huge_joint,  // joint 2 is 1e300 in one package: finite, but no pose of any arm
                       not_found, protocol1_only,
                       // input sessions: the setup reply has no recipe id (an empty payload); the
                       // connection is closed after fault_at input packages; closed so, and the
                       // next client is not served before release()
                       malformed_input_reply, close_inputs, close_inputs_hold };

/// One input DATA_PACKAGE the fake received, decoded by its recipe's types.
struct FakeInputWrite {
  int64_t connection = 0;       ///< which connection (from 1)
  std::vector<double> values;   ///< in the recipe's order (UINT32 and INT32 as numbers)
};

/// The fake's default trajectory at controller time t_s: joint j = 0.5 sin(2π·0.2·t + j) + 0.1 j.
inline double fake_q(double t_s, int j) { return 0.5 * std::sin(2.0 * M_PI * 0.2 * t_s + j) + 0.1 * j; }
inline double fake_qd(double t_s, int j) { return 0.5 * 2.0 * M_PI * 0.2 * std::cos(2.0 * M_PI * 0.2 * t_s + j); }

/// What the fake's controller says of itself in one data package.
struct FakeModes {
  int32_t robot_mode = 7;   ///< running
  int32_t safety_mode = 1;  ///< normal
  double speed_scaling = 1.0;
  double target_speed_fraction = 1.0;  ///< the speed slider
};

struct FakeRtdeScript {
  uint32_t major = 5, minor = 12;          ///< controller version (major < 5: a CB3)
  int64_t samples_per_connection = 200;    ///< then silent, connection kept open
  RtdeFault fault = RtdeFault::none;       ///< on the first connection only
  int64_t fault_at = 100;                  ///< data package index of the fault
  double controller_offset_s = 1234.5;     ///< controller clock = FakeClock + this
  /// actual_q and actual_qd at controller time t_s; empty: fake_q and fake_qd.
  std::function<void(double t_s, JointAngles& q, JointAngles& qd)> joints;
  /// actual_TCP_pose (x, y, z m, rotation vector rad) for the joints q; empty: 0.1·j.
  std::function<std::array<double, 6>(const JointAngles& q)> tcp_pose;
  /// robot_mode, safety_mode and speed_scaling of data package k (from 0, per connection);
  /// empty: running, normal, 1.0.
  std::function<FakeModes(int64_t k)> modes;
  /// Inputs another client owns: the input setup reply says IN_USE for them (every connection).
  std::vector<std::string> in_use;
};

class FakeRtdeController {
 public:
  FakeRtdeController(FakeRtdeScript script, RunClock& clock) : script_(script), clock_(clock) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = 0;
    socklen_t length = sizeof address;
    if (listen_fd_ < 0 || ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::listen(listen_fd_, 4) != 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
      ADD_FAILURE() << "fake RTDE controller: cannot listen on 127.0.0.1: " << std::strerror(errno);
    }
    port_ = ntohs(address.sin_port);
  }
  ~FakeRtdeController() {
    stop();
    ::close(listen_fd_);
  }
  /// Stops serving (bounded: every wait of the fake looks at the stop flag every 20 ms).
  void stop() {
    stop_ = true;
    release();
    if (thread_.joinable()) thread_.join();
  }

  int port() const { return port_; }
  /// Starts serving; `after_send(n)` runs after the n-th data package (n counts all connections).
  void start(std::function<void(int64_t)> after_send) {
    after_send_ = std::move(after_send);
    thread_ = std::thread([this] { serve_all(); });
  }
  bool faulted() const { return faulted_; }
  /// Ends the hold after a fault: a stalled stream resumes, a closed one accepts the next client.
  void release() {
    std::lock_guard<std::mutex> lock(mutex_);
    released_ = true;
    cv_.notify_all();
  }
  int64_t data_sent() const { return data_sent_; }
  int64_t connections() const { return connections_; }
  /// Input sessions: each setup's requested names, the writes received, and the input packages
  /// that did not fit the recipe (wrong id, wrong size, another type).
  std::vector<std::string> input_setups() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return input_setups_;
  }
  std::vector<FakeInputWrite> inputs() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return inputs_;
  }
  int64_t input_errors() const { return input_errors_; }
  /// The recipe id the fake gives input recipes (not 1, so that a client must use the reply's).
  static constexpr uint8_t kInputRecipeId = 3;
  /// The frequency each connection's setup asked for.
  std::vector<double> frequencies() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frequencies_;
  }

 private:
  FakeRtdeScript script_;
  RunClock& clock_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::function<void(int64_t)> after_send_;
  std::atomic<bool> stop_{false}, faulted_{false};
  std::atomic<int64_t> data_sent_{0}, connections_{0};
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool released_ = false;
  std::vector<double> frequencies_;
  std::vector<std::string> input_setups_;
  std::vector<FakeInputWrite> inputs_;
  std::atomic<int64_t> input_errors_{0};
  std::thread thread_;

  static void be16(std::vector<uint8_t>& b, uint16_t v) { b.push_back(v >> 8); b.push_back(v & 0xFF); }
  static void be32(std::vector<uint8_t>& b, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(v >> s));
  }
  static void be_double(std::vector<uint8_t>& b, double v) {
    uint64_t u;
    std::memcpy(&u, &v, 8);
    for (int s = 56; s >= 0; s -= 8) b.push_back(static_cast<uint8_t>(u >> s));
  }
  static std::vector<uint8_t> pack(char type, const std::vector<uint8_t>& payload) {
    std::vector<uint8_t> b;
    be16(b, static_cast<uint16_t>(payload.size() + 3));
    b.push_back(static_cast<uint8_t>(type));
    b.insert(b.end(), payload.begin(), payload.end());
    return b;
  }
  bool send_all(int fd, const std::vector<uint8_t>& b, size_t count = SIZE_MAX) {
    const size_t n = std::min(count, b.size());
    return ::send(fd, b.data(), n, MSG_NOSIGNAL) == static_cast<ssize_t>(n);
  }
  // Reads exactly n bytes within 5 s (real time); false on EOF, error, timeout or stop.
  bool read_exact(int fd, uint8_t* out, size_t n) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    size_t got = 0;
    while (got < n && !stop_ && std::chrono::steady_clock::now() < deadline) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const ssize_t r = ::recv(fd, out + got, n - got, 0);
      if (r <= 0) return false;
      got += static_cast<size_t>(r);
    }
    return got == n;
  }
  bool read_package(int fd, char& type, std::vector<uint8_t>& payload) {
    uint8_t header[3];
    if (!read_exact(fd, header, 3)) return false;
    const size_t size = (size_t{header[0]} << 8) | header[1];
    if (size < 3) return false;
    type = static_cast<char>(header[2]);
    payload.assign(size - 3, 0);
    return payload.empty() || read_exact(fd, payload.data(), payload.size());
  }
  void hold() {
    faulted_ = true;
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [this] { return released_ || stop_; });
  }
  // Reads and drops what the client sends until it closes or the fake stops.
  void drain_until_closed(int fd) {
    uint8_t bytes[256];
    while (!stop_) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 20) > 0 && ::recv(fd, bytes, sizeof bytes, 0) <= 0) return;
    }
  }
  // True when the client has closed its end (what it sent before is dropped).
  static bool peer_closed(int fd) {
    // The client's close may not have reached this end yet (loopback under load): wait up to
    // 100 ms for it before taking the peer as still there; else the stream would go on into a
    // dead connection and wait for reads that never come.
    uint8_t bytes[256];
    for (int wait_ms = 100;; wait_ms = 0) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, wait_ms) <= 0) return false;
      if (::recv(fd, bytes, sizeof bytes, 0) <= 0) return true;
    }
  }
  // After a refusal: waits for the client to close, then holds.
  void refuse_and_hold(int fd) {
    drain_until_closed(fd);
    ::close(fd);
    hold();
  }

  void serve_all() {
    while (!stop_) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const int fd = ::accept(listen_fd_, nullptr, nullptr);
      if (fd < 0) continue;
      const bool first = connections_++ == 0;
      if (serve(fd, first)) ::close(fd);
    }
  }

  // One connection; false when it closed the socket itself.
  bool serve(int fd, bool first) {
    const RtdeFault fault = first ? script_.fault : RtdeFault::none;
    char type = 0;
    std::vector<uint8_t> in;
    if (!read_package(fd, type, in) || type != 'V' || in.size() != 2) return true;
    const bool v2 = in[0] == 0 && in[1] == 2 && fault != RtdeFault::protocol1_only;
    send_all(fd, pack('V', {static_cast<uint8_t>(v2 ? 1 : 0)}));
    if (!v2) return refuse_and_hold(fd), false;
    if (!read_package(fd, type, in) || type != 'v' || !in.empty()) return true;
    std::vector<uint8_t> version;
    for (uint32_t v : {script_.major, script_.minor, 0U, 0U}) be32(version, v);
    send_all(fd, pack('v', version));
    if (!read_package(fd, type, in)) return true;
    if (type == 'I') return serve_inputs(fd, in, fault, connections_.load());
    if (type != 'O' || in.size() < 8) return true;
    uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits = (bits << 8) | in[i];
    double frequency_hz;
    std::memcpy(&frequency_hz, &bits, 8);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      frequencies_.push_back(frequency_hz);
    }
    // The names, and this controller's types for them.
    std::vector<std::string> names;
    std::string all(in.begin() + 8, in.end()), types;
    for (size_t at = 0; at <= all.size();) {
      size_t comma = all.find(',', at);
      if (comma == std::string::npos) comma = all.size();
      names.push_back(all.substr(at, comma - at));
      at = comma + 1;
    }
    bool not_found = false;
    for (const std::string& name : names) {
      std::string t = name == "timestamp" || name == "speed_scaling" || name == "target_speed_fraction" ? "DOUBLE"
                      : name == "robot_mode" || name == "safety_mode" ? "INT32"
                      : name == "actual_q" || name == "actual_qd" || name == "actual_TCP_pose" ? "VECTOR6D"
                                                                                              : "NOT_FOUND";
      if (fault == RtdeFault::not_found && name == "actual_TCP_pose") t = "NOT_FOUND";
      not_found = not_found || t == "NOT_FOUND";
      types += (types.empty() ? "" : ",") + t;
    }
    std::vector<uint8_t> reply{1};
    reply.insert(reply.end(), types.begin(), types.end());
    send_all(fd, pack('O', reply));
    if (not_found) return refuse_and_hold(fd), false;
    if (!read_package(fd, type, in) || type != 'S' || !in.empty()) return true;
    // A text message may come at any time (v2: len, message, len, source, level).
    const std::string message = "Program running", source = "fake";
    std::vector<uint8_t> text{static_cast<uint8_t>(message.size())};
    text.insert(text.end(), message.begin(), message.end());
    text.push_back(static_cast<uint8_t>(source.size()));
    text.insert(text.end(), source.begin(), source.end());
    text.push_back(3);
    send_all(fd, pack('M', text));
    send_all(fd, pack('S', {1}));
    return stream(fd, names, frequency_hz, fault);
  }

  static double be_value(const uint8_t* p, const std::string& type) {
    uint64_t bits = 0;
    const size_t n = type == "DOUBLE" ? 8 : 4;
    for (size_t i = 0; i < n; ++i) bits = (bits << 8) | p[i];
    if (type == "UINT32") return static_cast<double>(static_cast<uint32_t>(bits));
    if (type == "INT32") return static_cast<double>(static_cast<int32_t>(static_cast<uint32_t>(bits)));
    double v;
    std::memcpy(&v, &bits, 8);
    return v;
  }

  // An input session (the client asked for inputs after the version): the setup reply, then
  // the client's DATA_PACKAGEs recorded until it closes or the fake stops. False when it
  // closed the socket itself.
  bool serve_inputs(int fd, const std::vector<uint8_t>& in, RtdeFault fault, int64_t connection) {
    const std::string all(in.begin(), in.end());
    {
      std::lock_guard<std::mutex> lock(mutex_);
      input_setups_.push_back(all);
    }
    if (fault == RtdeFault::malformed_input_reply) {
      send_all(fd, pack('I', {}));  // no recipe id
      drain_until_closed(fd);
      return true;
    }
    std::vector<std::string> types;
    std::string reply_types;
    bool refused = false;
    for (size_t at = 0; at <= all.size();) {
      size_t comma = all.find(',', at);
      if (comma == std::string::npos) comma = all.size();
      const std::string name = all.substr(at, comma - at);
      at = comma + 1;
      std::string t = "NOT_FOUND";
      if (name == "speed_slider_mask") t = "UINT32";
      if (name == "speed_slider_fraction") t = "DOUBLE";
      for (int r = 0; r < 48; ++r) {
        if (name == "input_double_register_" + std::to_string(r)) t = "DOUBLE";
        if (name == "input_int_register_" + std::to_string(r)) t = "INT32";
      }
      for (const std::string& owned : script_.in_use) {
        if (name == owned) t = "IN_USE";
      }
      refused = refused || t == "NOT_FOUND" || t == "IN_USE";
      types.push_back(t);
      reply_types += (reply_types.empty() ? "" : ",") + t;
    }
    std::vector<uint8_t> reply{kInputRecipeId};
    reply.insert(reply.end(), reply_types.begin(), reply_types.end());
    send_all(fd, pack('I', reply));
    if (refused) {
      drain_until_closed(fd);
      return true;
    }
    char type = 0;
    std::vector<uint8_t> payload;
    if (!read_package(fd, type, payload) || type != 'S' || !payload.empty()) return true;
    send_all(fd, pack('S', {1}));
    size_t expected = 1;
    for (const std::string& t : types) expected += t == "DOUBLE" ? 8 : 4;
    int64_t received = 0;
    while (!stop_) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      if (!read_package(fd, type, payload)) return true;  // the client closed
      if (type != 'U' || payload.size() != expected || payload[0] != kInputRecipeId) {
        ++input_errors_;
        continue;
      }
      FakeInputWrite write;
      write.connection = connection;
      const uint8_t* at = payload.data() + 1;
      for (const std::string& t : types) {
        write.values.push_back(be_value(at, t));
        at += t == "DOUBLE" ? 8 : 4;
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        inputs_.push_back(write);
      }
      const bool closes = fault == RtdeFault::close_inputs || fault == RtdeFault::close_inputs_hold;
      if (closes && ++received == script_.fault_at) {
        faulted_ = true;
        ::close(fd);
        if (fault == RtdeFault::close_inputs_hold) hold();
        return false;
      }
    }
    return true;
  }

  bool stream(int fd, const std::vector<std::string>& names, double frequency_hz, RtdeFault fault) {
    const int64_t period_ns = static_cast<int64_t>(std::llround(1e9 / frequency_hz));
    int64_t t_ns = clock_.now_ns();
    for (int64_t k = 0; k < script_.samples_per_connection && !stop_; ++k) {
      if (k > 0) t_ns += period_ns;
      clock_.sleep_until(t_ns, nullptr);  // later only: the schedule, or now if that has passed
      t_ns = clock_.now_ns();
      const double t_s = static_cast<double>(t_ns) * 1e-9 + script_.controller_offset_s;
      const bool here = k == script_.fault_at;
      std::vector<uint8_t> payload{static_cast<uint8_t>(here && fault == RtdeFault::wrong_recipe ? 7 : 1)};
      JointAngles q{}, qd{};
      if (script_.joints) {
        script_.joints(t_s, q, qd);
      } else {
        for (int j = 0; j < 6; ++j) {
          q[static_cast<size_t>(j)] = fake_q(t_s, j);
          qd[static_cast<size_t>(j)] = fake_qd(t_s, j);
        }
      }
      std::array<double, 6> tcp{0.0, 0.1, 0.2, 0.3, 0.4, 0.5};
      if (script_.tcp_pose) tcp = script_.tcp_pose(q);
      const FakeModes modes = script_.modes ? script_.modes(k) : FakeModes{};
      for (const std::string& name : names) {
        if (name == "timestamp") be_double(payload, t_s);
        if (name == "speed_scaling") be_double(payload, modes.speed_scaling);
        if (name == "target_speed_fraction") be_double(payload, modes.target_speed_fraction);
        if (name == "robot_mode") be32(payload, static_cast<uint32_t>(modes.robot_mode));
        if (name == "safety_mode") be32(payload, static_cast<uint32_t>(modes.safety_mode));
        for (size_t j = 0; j < 6; ++j) {
          const bool nan = here && fault == RtdeFault::nan_joints && j == 2;
          const bool huge = here && fault == RtdeFault::huge_joint && j == 1;
          if (name == "actual_q") be_double(payload, nan ? std::nan("") : huge ? 1e300 : q[j]);
          if (name == "actual_qd") be_double(payload, qd[j]);
          if (name == "actual_TCP_pose") be_double(payload, tcp[j]);
        }
      }
      if (here && fault == RtdeFault::oversized) payload.insert(payload.end(), 8, 0xAB);
      const std::vector<uint8_t> package = pack('U', payload);
      if (here && (fault == RtdeFault::close || fault == RtdeFault::truncated)) {
        if (fault == RtdeFault::truncated) send_all(fd, package, package.size() / 2);
        ::close(fd);
        hold();
        return false;
      }
      if (here && fault == RtdeFault::stall) {
        hold();
        if (peer_closed(fd)) return true;  // the client gave up during the stall: serve its next connection
      }
      if (here && fault == RtdeFault::unknown_type) send_all(fd, pack('X', {1, 2, 3, 4, 5}));
      if (!send_all(fd, package)) return true;
      if (after_send_) after_send_(++data_sent_);
    }
    drain_until_closed(fd);
    return true;
  }
};

}  // namespace hrcsense::test
