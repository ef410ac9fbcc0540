// SPDX-License-Identifier: Apache-2.0
// hrcsense — `robot.state.source: udp_json`: joint states from any robot, one JSON datagram per
// state ({"t_ns": ..., "q": [6], "qd": [6]}, docs/ROBOT.md), received on a UDP socket.
#pragma once

#include "hrcsense/clock.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/robot_state_history.hpp"
#include "hrcsense/types.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

struct sockaddr_storage;  // <sys/socket.h>, kept out of this header

namespace hrcsense {

/// A datagram longer than this is rejected unread (a state is about 250 bytes).
inline constexpr size_t kUdpJsonMaxBytes = 1024;
/// The largest `t_ns` accepted (2^62 ns, 146 years): sender and host times then stay far from
/// int64 overflow in the clock map.
inline constexpr int64_t kUdpJsonMaxTimeNs = int64_t{1} << 62;

/// One datagram, parsed.
struct UdpJsonDatagram {
  bool ok = false;          ///< every field present, well-formed and finite
  /// Well-formed, but a joint angle or velocity is NaN or ±Infinity (Python's json.dumps
  /// writes them as NaN, Infinity, -Infinity): the fields below hold the values as sent, so
  /// that the history rejects and counts the sample as non-finite. ok is false.
  bool non_finite = false;
  int64_t t_ns = 0;         ///< `t_ns`: when the state held, on the sender's clock, ns (0..2^62)
  JointAngles q_rad{};      ///< `q`: joint angles, rad, joint 1 first
  JointAngles qd_rad_s{};   ///< `qd`: joint velocities, rad/s
  /// `speed_fraction` (optional): the share of its programmed speed the robot runs at, 0..1
  /// (the slider times the controller's own scaling). NaN when the datagram has none.
  double speed_fraction = std::numeric_limits<double>::quiet_NaN();
  /// When !ok: what is wrong, naming the field and, for syntax, the byte offset, e.g.
  /// "q: expected 6 numbers, got 5", "t_ns: expected an integer", "duplicate key 'q'".
  std::string error;
};

/// Parses one datagram of `size` bytes. Strict: one JSON object with exactly the keys t_ns (an
/// integer, no fraction or exponent, 0..2^62), q and qd (arrays of exactly 6 numbers) and
/// optionally speed_fraction (a number from 0 to 1), in any order, each once; keys spelt without escapes; nothing but whitespace after the object; at
/// most kUdpJsonMaxBytes. Anything else is an error, never an exception. Pure; `bytes` may be
/// null when size is 0.
UdpJsonDatagram parse_udp_json_state(const char* bytes, size_t size);

/// How UdpJsonRobotState listens and keeps its samples.
struct UdpJsonParams {
  /// `robot.state.listen`: numeric IPv4 "a.b.c.d:port" or IPv6 "[addr]:port". Loopback by
  /// default: another machine's sender needs an explicit address. Port 0: any free port (tests).
  std::string listen = "127.0.0.1:30010";
  RobotStateHistoryParams history;         ///< `robot.state.max_age_s`, jump tolerance
  int64_t clock_window_ns = 5'000'000'000;  ///< SenderClockMap's window
};

/// Receives udp_json datagrams on a reader thread that drains the socket as they come (it never
/// lets the socket's buffer back up), maps each `t_ns` to the host clock (SenderClockMap, the
/// arrival time read from `clock` at reception) and keeps the accepted states in a
/// RobotStateHistory. Malformed datagrams are counted (stats().malformed) and otherwise ignored;
/// a datagram not later than the previous one (a duplicate or UDP reordering, up to max_age_s
/// back on the sender's clock) is counted as backwards without touching the clock map, a larger
/// step back is a restarted sender. All members are thread-safe.
class UdpJsonRobotState final : public RobotStateSource {
 public:
  /// Binds the socket and starts the reader. Throws std::invalid_argument naming the key and
  /// the address when it is not a numeric address with a port (a configuration error), and
  /// std::runtime_error naming them when it cannot be bound (in use, not local).
  /// `clock` must outlive this object.
  UdpJsonRobotState(const UdpJsonParams& params, const RunClock& clock);
  /// Stops the reader (at once: it is woken, not waited out) and closes the socket.
  ~UdpJsonRobotState() override;
  UdpJsonRobotState(const UdpJsonRobotState&) = delete;
  UdpJsonRobotState& operator=(const UdpJsonRobotState&) = delete;

  RobotStateOrigin origin() const override { return RobotStateOrigin::udp_json; }
  /// The history's lookup at `host_time_ns` (same clock as `clock`); false, with out.valid
  /// false, when nothing was received yet or the newest state is older than max_age_s.
  bool state_at(int64_t host_time_ns, RobotState& out) override;
  /// Why the last state_at failed ("" after a valid one), or the reader's fatal error.
  std::string error() const override;
  /// samples: the history's counters; malformed: datagrams rejected by the parser (too long,
  /// not the format); last_problem: the last rejection with the sender's address.
  RobotStateStats stats() const override;
  /// Each accepted datagram's state, as the reader thread accepts it.
  bool set_sample_listener(RobotStateListener listener) override;
  /// The port actually bound (the listen port, or the one chosen for port 0).
  uint16_t bound_port() const { return bound_port_; }

 private:
  void read_loop();
  void handle(const char* bytes, size_t size, int64_t arrival_ns, const sockaddr_storage& peer);

  const RunClock& clock_;
  std::string listen_;
  int fd_ = -1;
  int wake_read_fd_ = -1;   ///< a pipe: the destructor writes to wake the reader's poll
  int wake_write_fd_ = -1;
  uint16_t bound_port_ = 0;
  std::atomic<bool> stop_{false};

  mutable std::mutex mutex_;  // guards everything below
  RobotStateHistory history_;
  SenderClockMap clock_map_;
  bool have_last_ = false;     ///< last_t_ns_/last_host_ns_ hold the newest mapped datagram
  int64_t last_t_ns_ = 0;
  int64_t last_host_ns_ = 0;
  int64_t malformed_ = 0;
  std::string last_problem_;   ///< the latest problem: a datagram's or a lookup's
  std::string sample_problem_; ///< the latest malformed or rejected datagram
  std::string error_;          ///< the reader's fatal error
  std::string lookup_error_;   ///< why the last state_at failed

  std::thread reader_;  // last: started once everything above exists
};

}  // namespace hrcsense
