// SPDX-License-Identifier: Apache-2.0
// hrcsense — the RTDE client's reader thread: connect, handshake, drain the socket into the
// robot state history, reconnect with back-off. POSIX sockets; the library never prints, so
// every problem goes into the stats (last_problem) and error().
#include "hrcsense/net/rtde.hpp"
#include "rtde_protocol.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <utility>

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace hrcsense {
namespace {

constexpr int kPollSliceMs = 20;       // the reader looks at the stop request this often
constexpr double kCb3MaxHz = 125.0;    // CB-series controllers (major < 5): 1-125 Hz
constexpr size_t kReceiveChunk = 65536;

int64_t to_ns(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e9)); }

std::string system_error(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

// A DATA_PACKAGE as a robot state at `host_time_ns`, with the controller's own report.
RobotState rtde_robot_state(const rtde::DataSample& data, int64_t host_time_ns, bool tcp_mismatch) {
  RobotState state;
  state.host_time_ns = host_time_ns;
  state.q_rad = data.q;
  state.qd_rad_s = data.qd;
  state.valid = true;
  state.origin = RobotStateOrigin::rtde;
  state.status.known = true;
  state.status.robot_mode = data.robot_mode;
  state.status.safety_mode = data.safety_mode;
  state.status.speed_scaling = data.speed_scaling;
  state.status.target_speed_fraction = data.target_speed_fraction;
  state.status.tcp_pose_mismatch = tcp_mismatch;
  // The arm runs at the slider times the controller's own scaling of its programmed speed
  // (specs/ur-rtde.md). A value outside 0..1 is no reading: the monitor falls back to the
  // last scale it sent.
  const double fraction = data.speed_scaling * data.target_speed_fraction;
  if (fraction >= 0.0 && fraction <= 1.0) state.speed_fraction = fraction;
  return state;
}

}  // namespace

int rtde::connect_tcp(const std::string& host, int port_number, double timeout_s, const std::atomic<bool>& stop,
                      std::string& error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(port_number);
  const std::string where = host + ":" + port;
  if (const int rc = ::getaddrinfo(host.c_str(), port.c_str(), &hints, &found); rc != 0) {
    error = "RTDE " + where + ": " + ::gai_strerror(rc);
    return -1;
  }
  int fd = -1;
  error = "RTDE " + where + ": no address";
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    int rc = ::connect(fd, a->ai_addr, a->ai_addrlen);
    if (rc != 0 && errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      for (int waited = 0; !stop && waited < timeout_s * 1000.0; waited += kPollSliceMs) {
        if ((rc = ::poll(&p, 1, kPollSliceMs)) != 0) break;
      }
      int so_error = ETIMEDOUT;
      socklen_t len = sizeof so_error;
      if (rc > 0) ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &len);
      errno = so_error;
      rc = so_error == 0 ? 0 : -1;
    }
    if (rc != 0) {
      error = "RTDE " + where + ": " + system_error("connect");
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(found);
  return fd;
}

namespace {

// A non-blocking TCP connection with TCP_NODELAY, or -1 with `error`.
int connect_to(const RtdeParams& params, const std::atomic<bool>& stop, std::string& error) {
  return rtde::connect_tcp(params.host, params.port, params.connect_timeout_s, stop, error);
}

}  // namespace

/// One connection: the socket and the bytes received but not yet framed.
struct RtdeRobotState::Connection {
  int fd = -1;
  std::vector<uint8_t> buffer;  // [begin, end) unread
  size_t begin = 0, end = 0;
  int64_t last_byte_ns = 0;  // run clock
  rtde::OutputRecipe recipe;
  SenderClockMap clock_map;
  std::string error;  // why next_frame failed
  // The TCP pose check: the implied flange → TCP offset of the first plausible sample of this
  // connection (the controller's TCP may differ on the next), and whether the last one failed.
  std::optional<Pose> tcp_reference;
  bool tcp_mismatch = false;

  // Sends all of `bytes`; false on a socket error.
  bool send(const std::vector<uint8_t>& bytes) {
    size_t sent = 0;
    for (int tries = 0; sent < bytes.size() && tries < 50; ++tries) {
      const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n > 0) {
        sent += static_cast<size_t>(n);
      } else if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        break;
      } else {
        pollfd p{fd, POLLOUT, 0};
        ::poll(&p, 1, kPollSliceMs);
      }
    }
    if (sent < bytes.size()) error = system_error("send");
    return sent == bytes.size();
  }
};

RtdeRobotState::RtdeRobotState(RtdeParams params, RunClock& clock) : params_(std::move(params)), clock_(clock) {
  history_.params = params_.history;
  thread_ = std::thread([this] { run(); });
}

RtdeRobotState::~RtdeRobotState() {
  // Every wait of the reader (poll, connect, back-off) looks at stop_ at least every 20 ms.
  stop_ = true;
  thread_.join();
}

bool RtdeRobotState::state_at(int64_t host_time_ns, RobotState& out) {
  std::lock_guard<std::mutex> lock(mutex_);
  out = history_.at(host_time_ns).state;
  out.origin = RobotStateOrigin::rtde;
  return out.valid;
}

std::string RtdeRobotState::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

RobotStateStats RtdeRobotState::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  RobotStateStats out = stats_;
  out.samples = history_.counts();
  return out;
}

bool RtdeRobotState::set_sample_listener(RobotStateListener listener) {
  std::lock_guard<std::mutex> lock(mutex_);  // on_data adds under it: no call is under way now
  history_.listener = std::move(listener);
  return true;
}

RtdeStatus RtdeRobotState::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

void RtdeRobotState::problem(const std::string& what, bool malformed) {
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.last_problem = what;
  if (malformed) ++stats_.malformed;
}

void RtdeRobotState::record_error_locked(const std::string& error) {
  error_ = error;
  if (!error.empty()) stats_.last_problem = error;
}

void RtdeRobotState::run() {
  double backoff_s = params_.backoff_initial_s;
  while (!stop_) {
    Connection connection;
    connection.buffer.resize(2 * kReceiveChunk);
    std::string error;
    connection.fd = connect_to(params_, stop_, error);
    if (connection.fd >= 0) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.connections;
      }
      const bool streamed = session(connection);
      ::close(connection.fd);
      error = connection.error;
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.disconnects;
      status_.streaming = false;
      history_.clear();  // no valid state from a connection that is gone
      // Under the same lock as the disconnect: stats() never shows one without its reason.
      if (!stop_) record_error_locked(error);
      if (streamed) backoff_s = params_.backoff_initial_s;
    } else if (!stop_) {
      std::lock_guard<std::mutex> lock(mutex_);
      record_error_locked(error);
    }
    if (stop_) break;
    // Back off: a reconnect loop can lock the pendant (ur-rtde.md, known field problems).
    clock_.sleep_until(clock_.now_ns() + to_ns(backoff_s), &stop_);
    backoff_s = std::min(params_.backoff_max_s, 2.0 * backoff_s);
  }
}

namespace {

// The next package of the connection, reading as needed. False (with connection.error) on
// end of stream, a socket error, silence for longer than `timeout_ns`, a stop request or an
// unframeable stream (`malformed` set).
bool next_frame(int fd, std::vector<uint8_t>& buffer, size_t& begin, size_t& end, int64_t& last_byte_ns,
                RunClock& clock, int64_t timeout_ns, const std::atomic<bool>& stop, rtde::Package& frame,
                std::string& error, bool& malformed) {
  while (!stop) {
    const rtde::PackageSplit split = rtde::split_package(buffer.data() + begin, end - begin);
    if (split.status == rtde::SplitStatus::package) {
      frame = split.package;
      begin += split.consumed;
      return true;
    }
    if (split.status == rtde::SplitStatus::malformed) {
      error = "RTDE: " + split.error;
      malformed = true;
      return false;
    }
    if (begin > 0 && buffer.size() - end < kReceiveChunk) {  // keep room for a full read
      std::memmove(buffer.data(), buffer.data() + begin, end - begin);
      end -= begin;
      begin = 0;
    }
    pollfd p{fd, POLLIN, 0};
    const int rc = ::poll(&p, 1, kPollSliceMs);
    if (rc < 0 && errno != EINTR) {
      error = "RTDE: " + system_error("poll");
      return false;
    }
    if (rc <= 0) {
      if (clock.now_ns() - last_byte_ns > timeout_ns) {
        error = "RTDE: no data from the controller for " + std::to_string(timeout_ns / 1'000'000) + " ms";
        return false;
      }
      continue;
    }
    const ssize_t n = ::recv(fd, buffer.data() + end, buffer.size() - end, 0);
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
      if (n < 0) {
        error = "RTDE: " + system_error("recv");
      } else if (end > begin) {
        const uint8_t type = end - begin >= 3 ? buffer[begin + 2] : 0;
        error = std::string("RTDE: connection closed inside a package (truncated ") +
                (end - begin >= 3 ? rtde::package_type_name(type) : "header") + ")";
        malformed = true;
      } else {
        error = "RTDE: connection closed by the controller";
      }
      return false;
    }
    if (n > 0) {
      end += static_cast<size_t>(n);
      last_byte_ns = clock.now_ns();
    }
  }
  error = "";  // stopped: not a problem
  return false;
}

}  // namespace

bool RtdeRobotState::handshake(Connection& c) {
  bool malformed = false;
  rtde::Package frame;
  const int64_t timeout_ns = to_ns(params_.receive_timeout_s);
  // The reply of type `type`, skipping text messages and anything else on the way.
  auto reply = [&](rtde::PackageType type) {
    while (next_frame(c.fd, c.buffer, c.begin, c.end, c.last_byte_ns, clock_, timeout_ns, stop_, frame, c.error,
                      malformed)) {
      if (frame.type == static_cast<uint8_t>(type)) return true;
      if (frame.type == static_cast<uint8_t>(rtde::PackageType::text_message)) on_text(frame);
    }
    if (malformed) problem(c.error, true);
    return false;
  };
  bool accepted = false;
  if (!c.send(rtde::encode_request_protocol_version(2)) || !reply(rtde::PackageType::request_protocol_version)) {
    return false;
  }
  if (!rtde::parse_accepted(frame, rtde::PackageType::request_protocol_version, accepted, c.error)) return false;
  if (!accepted) {
    c.error = "REQUEST_PROTOCOL_VERSION: the controller refused protocol version 2 (it speaks only protocol 1: "
              "UR software older than 3.3/5.0?); hrcsense needs protocol 2";
    return false;
  }
  rtde::ControllerVersion version;
  if (!c.send(rtde::encode_get_urcontrol_version()) || !reply(rtde::PackageType::get_urcontrol_version) ||
      !rtde::parse_controller_version(frame, version, c.error)) {
    return false;
  }
  const bool cb3 = version.major < 5;
  const double frequency_hz = cb3 ? std::min(params_.frequency_hz, kCb3MaxHz) : params_.frequency_hz;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    status_.controller = version;
    status_.frequency_hz = frequency_hz;
    status_.frequency_clamped = frequency_hz < params_.frequency_hz;
    if (status_.frequency_clamped) {
      stats_.last_problem = "RTDE: CB-series controller " + std::to_string(version.major) + "." +
                            std::to_string(version.minor) + ": frequency lowered from " +
                            std::to_string(params_.frequency_hz) + " to 125 Hz";
    }
  }
  rtde::SetupReply setup;
  if (!c.send(rtde::encode_setup_outputs(frequency_hz, rtde::kOutputVariables)) ||
      !reply(rtde::PackageType::setup_outputs) ||
      !rtde::parse_setup_reply(frame, rtde::PackageType::setup_outputs, setup, c.error) ||
      !rtde::make_output_recipe(setup, rtde::kOutputVariables, c.recipe, c.error)) {
    return false;
  }
  if (!c.send(rtde::encode_start()) || !reply(rtde::PackageType::start) ||
      !rtde::parse_accepted(frame, rtde::PackageType::start, accepted, c.error)) {
    return false;
  }
  if (!accepted) c.error = "CONTROL_PACKAGE_START: refused by the controller";
  return accepted;
}

bool RtdeRobotState::session(Connection& c) {
  c.last_byte_ns = clock_.now_ns();
  if (!handshake(c)) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    status_.streaming = true;
    error_.clear();
  }
  bool malformed = false;
  rtde::Package frame;
  const int64_t timeout_ns = to_ns(params_.receive_timeout_s);
  while (next_frame(c.fd, c.buffer, c.begin, c.end, c.last_byte_ns, clock_, timeout_ns, stop_, frame, c.error,
                    malformed)) {
    if (frame.type == static_cast<uint8_t>(rtde::PackageType::data)) {
      on_data(frame, c);
      continue;
    }
    if (frame.type == static_cast<uint8_t>(rtde::PackageType::text_message)) {
      on_text(frame);
    } else {
      std::lock_guard<std::mutex> lock(mutex_);
      ++status_.skipped_packages;
      stats_.last_problem = "RTDE: skipped package type " + std::to_string(frame.type) + " (" +
                            rtde::package_type_name(frame.type) + ", " + std::to_string(frame.payload_size + 3) +
                            " bytes)";
    }
  }
  if (malformed) problem(c.error, true);
  return true;
}

void RtdeRobotState::on_text(const rtde::Package& frame) {
  rtde::TextMessage text;
  std::string error;
  const bool parsed = rtde::parse_text_message(frame, text, error);
  std::lock_guard<std::mutex> lock(mutex_);
  if (parsed) {
    ++status_.text_messages;
    status_.last_text_message = text.source + ": " + text.message;
  } else {
    ++stats_.malformed;
    stats_.last_problem = "RTDE: " + error;
  }
}

void RtdeRobotState::on_data(const rtde::Package& frame, Connection& c) {
  rtde::DataSample data;
  std::string error;
  const bool parsed = rtde::parse_data_package(frame, c.recipe, data, error);
  const int64_t arrival_ns = clock_.now_ns();
  // The forward kinematics check, outside the lock (the reader alone owns the connection).
  bool tcp_mismatch = false;
  std::string tcp_problem;  // set when a mismatch starts
  if (parsed && params_.arm && all_finite(data.q)) {
    const Pose* reference = c.tcp_reference ? &*c.tcp_reference : nullptr;
    const TcpPoseCheck check = check_tcp_pose(*params_.arm, data.q, data.tcp_pose, reference, params_.tcp_check);
    tcp_mismatch = !check.consistent;
    if (check.consistent && !c.tcp_reference) c.tcp_reference = check.T_flange_tcp;
    if (tcp_mismatch && !c.tcp_mismatch) {
      char when[64];
      std::snprintf(when, sizeof when, "%.3f", data.timestamp_s);
      tcp_problem = std::string("RTDE: actual_TCP_pose at controller time ") + when + " s " +
                    tcp_pose_problem(params_.arm->name, check, params_.tcp_check);
    }
    c.tcp_mismatch = tcp_mismatch;
  }
  // A timestamp that is not a finite, non-negative number of seconds (or beyond int64 ns) cannot
  // be placed on the host clock.
  const bool timestamp_ok = parsed && std::isfinite(data.timestamp_s) && data.timestamp_s >= 0.0 &&
                            data.timestamp_s < 9.0e9;
  std::lock_guard<std::mutex> lock(mutex_);
  ++status_.data_packages;
  if (!timestamp_ok) {
    ++stats_.malformed;
    stats_.last_problem = parsed ? "RTDE: DATA_PACKAGE: timestamp " + std::to_string(data.timestamp_s) +
                                       " s is not a time" : "RTDE: " + error;
    return;
  }
  if (tcp_mismatch) ++status_.tcp_pose_mismatches;
  if (!tcp_problem.empty()) stats_.last_problem = tcp_problem;
  status_.robot_mode = data.robot_mode;
  status_.safety_mode = data.safety_mode;
  status_.speed_scaling = data.speed_scaling;
  status_.target_speed_fraction = data.target_speed_fraction;
  const int64_t host_time_ns = c.clock_map.to_host(to_ns(data.timestamp_s), arrival_ns);
  const RobotState state = rtde_robot_state(data, host_time_ns, tcp_mismatch);
  if (!history_.add(state)) {
    stats_.last_problem = "RTDE: DATA_PACKAGE at controller time " + std::to_string(data.timestamp_s) +
                          " s rejected: " + history_.last_rejection();
  }
}

}  // namespace hrcsense
