// SPDX-License-Identifier: Apache-2.0
// hrcsense — UdpJsonRobotState: the socket that receives udp_json datagrams, and the robot states they give.

#include "hrcsense/net/udp_json.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace hrcsense {
namespace {

[[noreturn]] void throw_listen(const std::string& listen, const std::string& why) {
  throw std::invalid_argument("udp_json: robot.state.listen '" + listen + "': " + why);
}

// "a.b.c.d:port" or "[v6]:port", numeric only (no name lookup at start-up).
sockaddr_storage parse_listen(const std::string& listen, socklen_t& length) {
  const size_t colon = listen.rfind(':');
  const std::string port_text = colon == std::string::npos ? "" : listen.substr(colon + 1);
  unsigned port = 0;
  const std::from_chars_result r = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (port_text.empty() || r.ec != std::errc() || r.ptr != port_text.data() + port_text.size() || port > 65535) {
    throw_listen(listen, "expected host:port with a port from 0 to 65535");
  }
  std::string host = listen.substr(0, colon);
  sockaddr_storage address{};
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
    auto* v6 = reinterpret_cast<sockaddr_in6*>(&address);
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons(static_cast<uint16_t>(port));
    if (inet_pton(AF_INET6, host.c_str(), &v6->sin6_addr) != 1) throw_listen(listen, "not a numeric IPv6 address");
    length = sizeof(sockaddr_in6);
  } else {
    auto* v4 = reinterpret_cast<sockaddr_in*>(&address);
    v4->sin_family = AF_INET;
    v4->sin_port = htons(static_cast<uint16_t>(port));
    if (inet_pton(AF_INET, host.c_str(), &v4->sin_addr) != 1) {
      throw_listen(listen, "expected a numeric IPv4 address a.b.c.d:port or [IPv6]:port");
    }
    length = sizeof(sockaddr_in);
  }
  return address;
}

std::string address_name(const sockaddr_storage& address) {
  char text[INET6_ADDRSTRLEN] = "?";
  if (address.ss_family == AF_INET6) {
    const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&address);
    inet_ntop(AF_INET6, &v6->sin6_addr, text, sizeof text);
    return "[" + std::string(text) + "]:" + std::to_string(ntohs(v6->sin6_port));
  }
  const auto* v4 = reinterpret_cast<const sockaddr_in*>(&address);
  inet_ntop(AF_INET, &v4->sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(v4->sin_port));
}

uint16_t address_port(const sockaddr_storage& address) {
  if (address.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&address)->sin6_port);
  return ntohs(reinterpret_cast<const sockaddr_in*>(&address)->sin_port);
}

std::string errno_text(int error) { return std::system_category().message(error); }

std::string milliseconds(double ms) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", ms);
  return text;
}

}  // namespace

UdpJsonRobotState::UdpJsonRobotState(const UdpJsonParams& params, const RunClock& clock)
    : clock_(clock), listen_(params.listen), clock_map_(params.clock_window_ns) {
  history_.params = params.history;
  socklen_t length = 0;
  const sockaddr_storage address = parse_listen(listen_, length);
  fd_ = ::socket(address.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error("udp_json: socket for " + listen_ + ": " + errno_text(errno));
  int fds[2] = {-1, -1};
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), length) != 0 ||
      ::pipe2(fds, O_NONBLOCK | O_CLOEXEC) != 0) {
    const int error = errno;
    ::close(fd_);
    throw std::runtime_error("udp_json: robot.state.listen '" + listen_ + "': cannot bind: " + errno_text(error));
  }
  wake_read_fd_ = fds[0];
  wake_write_fd_ = fds[1];
  sockaddr_storage bound{};
  socklen_t bound_length = sizeof bound;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&bound), &bound_length);
  bound_port_ = address_port(bound);
  listen_ = address_name(bound);  // port 0 becomes the port chosen; messages name the real one
  try {
    reader_ = std::thread([this] { read_loop(); });
  } catch (...) {
    ::close(fd_);
    ::close(wake_read_fd_);
    ::close(wake_write_fd_);
    throw;
  }
}

UdpJsonRobotState::~UdpJsonRobotState() {
  stop_ = true;
  const char byte = 0;
  (void)!::write(wake_write_fd_, &byte, 1);  // the reader's poll returns at once
  reader_.join();
  ::close(fd_);
  ::close(wake_read_fd_);
  ::close(wake_write_fd_);
}

void UdpJsonRobotState::read_loop() {
  // One byte more than a datagram may have; MSG_TRUNC makes recvfrom report the full length of
  // a longer one, which is then rejected unread.
  char buffer[kUdpJsonMaxBytes + 1];
  while (!stop_) {
    pollfd fds[2] = {{fd_, POLLIN, 0}, {wake_read_fd_, POLLIN, 0}};
    // The timeout only bounds a lost wake-up; the pipe ends the wait on destruction.
    const int ready = ::poll(fds, 2, 200);
    if (ready < 0 && errno != EINTR) {
      const std::lock_guard<std::mutex> lock(mutex_);
      error_ = "udp_json on " + listen_ + ": poll: " + errno_text(errno);
      return;
    }
    if (ready <= 0 || (fds[1].revents & POLLIN) != 0) continue;
    while (!stop_) {  // drain everything queued: the socket must never back up
      sockaddr_storage peer{};
      socklen_t peer_length = sizeof peer;
      const ssize_t got = ::recvfrom(fd_, buffer, sizeof buffer, MSG_TRUNC | MSG_DONTWAIT,
                                     reinterpret_cast<sockaddr*>(&peer), &peer_length);
      if (got < 0) {
        if (errno == EINTR) continue;
        break;  // EAGAIN: drained; anything else (ICMP errors on some stacks) is not fatal for UDP
      }
      handle(buffer, static_cast<size_t>(got), clock_.now_ns(), peer);
    }
  }
}

void UdpJsonRobotState::handle(const char* bytes, size_t size, int64_t arrival_ns, const sockaddr_storage& peer) {
  // The parse runs outside the lock: state_at must not wait for it.
  // An oversized datagram (MSG_TRUNC reports its full length) is rejected unread.
  const UdpJsonDatagram datagram = parse_udp_json_state(bytes, size);
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!datagram.ok && !datagram.non_finite) {
    ++malformed_;
    sample_problem_ = "from " + address_name(peer) + ": " + datagram.error;
    last_problem_ = sample_problem_;
    return;
  }
  RobotState sample;
  sample.q_rad = datagram.q_rad;
  sample.qd_rad_s = datagram.qd_rad_s;
  sample.speed_fraction = datagram.speed_fraction;
  sample.valid = true;
  sample.origin = RobotStateOrigin::udp_json;
  const auto reorder_ns = static_cast<int64_t>(history_.params.max_age_s * 1e9);
  if (have_last_ && datagram.t_ns <= last_t_ns_ && last_t_ns_ - datagram.t_ns <= reorder_ns) {
    // A duplicate or a datagram overtaken by a later one: its place on the current map is not
    // after the newest, so the history rejects it as backwards; the map stays as it is (feeding
    // it a smaller t_ns would reset it as for a restarted sender).
    sample.host_time_ns = last_host_ns_ - (last_t_ns_ - datagram.t_ns);
  } else {
    sample.host_time_ns = clock_map_.to_host(datagram.t_ns, arrival_ns);
    have_last_ = true;
    last_t_ns_ = datagram.t_ns;
    last_host_ns_ = sample.host_time_ns;
  }
  if (history_.add(sample)) return;
  // A non-finite datagram's parser names the field; every other rejection the history names.
  const std::string& why = datagram.non_finite ? datagram.error : history_.last_rejection();
  sample_problem_ = "from " + address_name(peer) + ": t_ns " + std::to_string(datagram.t_ns) + " rejected: " + why;
  last_problem_ = sample_problem_;
}

bool UdpJsonRobotState::state_at(int64_t host_time_ns, RobotState& out) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const RobotStateLookup lookup = history_.at(host_time_ns);
  out = lookup.state;
  out.origin = RobotStateOrigin::udp_json;
  if (lookup.state.valid) {
    lookup_error_.clear();
  } else {
    if (lookup.code == ReasonCode::robot_state_stale) {
      lookup_error_ = "udp_json on " + listen_ + ": newest state " + milliseconds(lookup.age_ms) + " old (max " +
                      milliseconds(history_.params.max_age_s * 1e3) + ")";
    } else {
      lookup_error_ = "udp_json on " + listen_ + ": no robot state accepted";
    }
    // What was received instead (a datagram rejected, malformed) is why; nothing at all is
    // said as such, so that a silent or wrong-port sender shows in the output and the summary.
    if (!sample_problem_.empty()) {
      lookup_error_ += "; last datagram problem: " + sample_problem_;
    } else if (lookup.code == ReasonCode::no_robot_state) {
      lookup_error_ += "; no datagram received";
    }
    last_problem_ = lookup_error_;
  }
  return lookup.state.valid;
}

std::string UdpJsonRobotState::error() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return error_.empty() ? lookup_error_ : error_;
}

bool UdpJsonRobotState::set_sample_listener(RobotStateListener listener) {
  const std::lock_guard<std::mutex> lock(mutex_);  // handle() adds under it: no call is under way now
  history_.listener = std::move(listener);
  return true;
}

RobotStateStats UdpJsonRobotState::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  RobotStateStats stats;
  stats.samples = history_.counts();
  stats.malformed = malformed_;
  stats.last_problem = last_problem_;
  return stats;
}

}  // namespace hrcsense
