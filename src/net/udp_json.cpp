// SPDX-License-Identifier: Apache-2.0
// hrcsense — the udp_json datagram parser and robot state source.
//
// The parser is hand-written, not nlohmann-json: the format is one flat object of three keys,
// and a small recursive-descent reader over it can (a) stop at the first error with a message
// naming the field and element ("q[3]: expected a number, got a string"), (b) see duplicate keys,
// which nlohmann's DOM silently overwrites, (c) tell an integer token from 1e9 for t_ns, (d) take
// Python's NaN / Infinity tokens in q and qd so that a sender reporting a non-finite joint is
// counted by the history as non-finite rather than as garbage, and (e) allocate nothing on a
// good datagram. It accepts a strict subset of JSON: keys without escapes, nothing nested.
#include "hrcsense/udp_json.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>

namespace hrcsense {
namespace {

std::string size_error(size_t size) {
  return "datagram of " + std::to_string(size) + " bytes: more than " + std::to_string(kUdpJsonMaxBytes);
}

// A cursor over one datagram. Every read either advances past what it read or sets `error`
// (the first error wins) and returns false.
class Reader {
 public:
  Reader(const char* bytes, size_t size) : p_(bytes), end_(bytes + size), begin_(bytes) {}

  bool parse(UdpJsonDatagram& out) {
    skip_ws();
    if (!eat('{')) return fail("expected a JSON object {\"t_ns\": ..., \"q\": [...], \"qd\": [...]}");
    bool seen[4] = {false, false, false, false};
    static const char* const kNames[4] = {"t_ns", "q", "qd", "speed_fraction"};
    skip_ws();
    if (!eat('}')) {
      for (;;) {
        int key = -1;
        if (!read_key(key)) return false;
        if (seen[key]) return fail(std::string("duplicate key '") + kNames[key] + "'");
        seen[key] = true;
        skip_ws();
        if (!eat(':')) return fail_at(std::string(kNames[key]) + ": expected ':'");
        skip_ws();
        const bool read = key == 0   ? read_time(out.t_ns)
                          : key == 3 ? read_fraction(out.speed_fraction)
                                     : read_joints(kNames[key], key == 1 ? out.q_rad : out.qd_rad_s);
        if (!read) return false;
        skip_ws();
        if (eat('}')) break;
        if (!eat(',')) return fail_at(std::string("after ") + kNames[key] + ": expected ',' or '}'");
        skip_ws();
      }
    }
    for (int key = 0; key < 3; ++key) {  // speed_fraction is optional
      if (!seen[key]) return fail(std::string("missing key '") + kNames[key] + "'");
    }
    skip_ws();
    if (p_ != end_) return fail_at("trailing bytes after the object");
    out.ok = !non_finite_;
    out.non_finite = non_finite_;
    if (non_finite_) out.error = non_finite_field_ + ": not a finite number";
    return true;
  }

  std::string error;

 private:
  const char* p_;
  const char* end_;
  const char* begin_;
  bool non_finite_ = false;
  std::string non_finite_field_;

  bool fail(std::string message) {
    error = std::move(message);
    return false;
  }
  bool fail_at(const std::string& message) {
    if (p_ == end_) return fail(message + " at byte " + std::to_string(p_ - begin_) + " (end of datagram)");
    return fail(message + " at byte " + std::to_string(p_ - begin_));
  }
  void skip_ws() {
    while (p_ != end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\n' || *p_ == '\r')) ++p_;
  }
  bool eat(char c) {
    if (p_ == end_ || *p_ != c) return false;
    ++p_;
    return true;
  }
  bool starts_with(const char* word) const {
    const size_t n = std::strlen(word);
    return static_cast<size_t>(end_ - p_) >= n && std::memcmp(p_, word, n) == 0;
  }
  // What kind of JSON value starts here, for "expected X, got Y".
  const char* kind() const {
    if (p_ == end_) return "the end of the datagram";
    switch (*p_) {
      case '"': return "a string";
      case '[': return "an array";
      case '{': return "an object";
      case 't': return starts_with("true") ? "true" : "an invalid token";
      case 'f': return starts_with("false") ? "false" : "an invalid token";
      case 'n': return starts_with("null") ? "null" : "an invalid token";
      default: return (*p_ == '-' || (*p_ >= '0' && *p_ <= '9')) ? "a number" : "an invalid token";
    }
  }

  // A key: t_ns (0), q (1), qd (2) or speed_fraction (3), spelt plainly.
  bool read_key(int& key) {
    const char* const start = p_;
    if (!eat('"')) return fail_at("expected a key (\"t_ns\", \"q\" or \"qd\")");
    const char* const name = p_;
    while (p_ != end_ && *p_ != '"') {
      const auto c = static_cast<unsigned char>(*p_);
      if (c == '\\' || c < 0x20) return fail_at("key: escapes and control characters are not accepted in keys");
      ++p_;
    }
    if (p_ == end_) return fail_at("unterminated key");
    const std::string_view text(name, static_cast<size_t>(p_ - name));
    ++p_;
    if (text == "t_ns") key = 0;
    else if (text == "q") key = 1;
    else if (text == "qd") key = 2;
    else if (text == "speed_fraction") key = 3;
    else {
      const bool printable = text.size() <= 32 && std::all_of(text.begin(), text.end(), [](char c) {
                               return c >= 0x20 && c < 0x7F;
                             });
      const std::string shown = printable ? "'" + std::string(text) + "'" : "at byte " + std::to_string(start - begin_);
      return fail("unknown key " + shown + " (expected t_ns, q, qd, speed_fraction)");
    }
    return true;
  }

  // The digits of a JSON number: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?. Sets `integer`
  // when there is neither fraction nor exponent. Does not move on failure.
  bool scan_number(const char*& number_end, bool& integer) const {
    const char* q = p_;
    if (q != end_ && *q == '-') ++q;
    if (q == end_ || !(*q >= '0' && *q <= '9')) return false;
    if (*q == '0') {
      ++q;
    } else {
      while (q != end_ && *q >= '0' && *q <= '9') ++q;
    }
    integer = true;
    if (q != end_ && *q == '.') {
      ++q;
      if (q == end_ || !(*q >= '0' && *q <= '9')) return false;
      while (q != end_ && *q >= '0' && *q <= '9') ++q;
      integer = false;
    }
    if (q != end_ && (*q == 'e' || *q == 'E')) {
      ++q;
      if (q != end_ && (*q == '+' || *q == '-')) ++q;
      if (q == end_ || !(*q >= '0' && *q <= '9')) return false;
      while (q != end_ && *q >= '0' && *q <= '9') ++q;
      integer = false;
    }
    number_end = q;
    return true;
  }

  bool read_time(int64_t& t_ns) {
    const char* number_end = nullptr;
    bool integer = false;
    if (!scan_number(number_end, integer)) {
      return fail(std::string("t_ns: expected an integer, got ") + kind());
    }
    int64_t value = 0;
    const std::from_chars_result r = std::from_chars(p_, number_end, value);
    if (!integer || r.ec != std::errc() || r.ptr != number_end || value < 0 || value > kUdpJsonMaxTimeNs) {
      return fail("t_ns: expected an integer from 0 to " + std::to_string(kUdpJsonMaxTimeNs) + ", got " +
                  std::string(p_, std::min<size_t>(32, static_cast<size_t>(number_end - p_))));
    }
    t_ns = value;
    p_ = number_end;
    return true;
  }

  // speed_fraction: a plain JSON number from 0 to 1 (a non-finite or larger one says nothing
  // a scale could be computed against: the datagram is malformed).
  bool read_fraction(double& fraction) {
    const char* number_end = nullptr;
    bool integer = false;
    double value = 0.0;
    if (!scan_number(number_end, integer)) return fail(std::string("speed_fraction: expected a number, got ") + kind());
    const std::from_chars_result r = std::from_chars(p_, number_end, value);
    if (r.ec != std::errc() || r.ptr != number_end || !(value >= 0.0 && value <= 1.0)) {
      return fail("speed_fraction: expected a number from 0 to 1, got " +
                  std::string(p_, std::min<size_t>(32, static_cast<size_t>(number_end - p_))));
    }
    fraction = value;
    p_ = number_end;
    return true;
  }

  // One element of q or qd: a JSON number, or Python's NaN, Infinity, -Infinity.
  // `name`[`index`] names it in messages (built only on failure: a good datagram allocates nothing).
  bool read_joint(const char* name, size_t index, double& value) {
    const auto field = [&] { return std::string(name) + "[" + std::to_string(index) + "]"; };
    for (const auto& [word, v] : {std::pair<const char*, double>{"NaN", std::numeric_limits<double>::quiet_NaN()},
                                  {"Infinity", std::numeric_limits<double>::infinity()},
                                  {"-Infinity", -std::numeric_limits<double>::infinity()}}) {
      if (starts_with(word)) {
        p_ += std::strlen(word);
        value = v;
        if (!non_finite_) non_finite_field_ = field();
        non_finite_ = true;
        return true;
      }
    }
    const char* number_end = nullptr;
    bool integer = false;
    if (!scan_number(number_end, integer)) return fail(field() + ": expected a number, got " + kind());
    // from_chars: locale-independent and correctly rounded, unlike strtod.
    const std::from_chars_result r = std::from_chars(p_, number_end, value);
    if (r.ec != std::errc() || r.ptr != number_end) {
      return fail(field() + ": number out of range: " +
                  std::string(p_, std::min<size_t>(32, static_cast<size_t>(number_end - p_))));
    }
    p_ = number_end;
    return true;
  }

  bool read_joints(const char* name, JointAngles& values) {
    const auto field = [&] { return std::string(name); };
    if (!eat('[')) {
      return fail(field() + ": expected an array of " + std::to_string(kJointCount) + " numbers, got " + kind());
    }
    size_t count = 0;
    skip_ws();
    if (!eat(']')) {
      for (;;) {
        double value = 0.0;
        if (!read_joint(name, count, value)) return false;
        if (count < kJointCount) values[count] = value;
        ++count;
        skip_ws();
        if (eat(']')) break;
        if (!eat(',')) return fail_at(field() + ": expected ',' or ']'");
        skip_ws();
      }
    }
    if (count != kJointCount) {
      return fail(field() + ": expected " + std::to_string(kJointCount) + " numbers, got " + std::to_string(count));
    }
    return true;
  }
};

}  // namespace

UdpJsonDatagram parse_udp_json_state(const char* bytes, size_t size) {
  UdpJsonDatagram out;
  if (size == 0) {
    out.error = "empty datagram";
    return out;
  }
  if (size > kUdpJsonMaxBytes) {
    out.error = size_error(size);
    return out;
  }
  Reader reader(bytes, size);
  if (!reader.parse(out)) {
    out = UdpJsonDatagram{};
    out.error = std::move(reader.error);
  }
  return out;
}

// ---- UdpJsonRobotState

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
  UdpJsonDatagram datagram;
  if (size > kUdpJsonMaxBytes) {
    datagram.error = size_error(size);
  } else {
    datagram = parse_udp_json_state(bytes, size);
  }
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

RobotStateStats UdpJsonRobotState::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  RobotStateStats stats;
  stats.samples = history_.counts();
  stats.malformed = malformed_;
  stats.last_problem = last_problem_;
  return stats;
}

}  // namespace hrcsense
