// SPDX-License-Identifier: Apache-2.0
// hrcsense — the verdict sent to the robot controller over UDP (`link.udp.*`, docs/SAFETY.md):
// a fixed 45-byte little-endian datagram (version 2, with the sender's session) with a CRC-32,
// or the frame's JSON line.
#pragma once

#include "hrcsense/clock.hpp"
#include "hrcsense/sink.hpp"
#include "hrcsense/types.hpp"

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

struct sockaddr_storage;  // <sys/socket.h>, kept out of this header

namespace hrcsense {

/// The datagram's total size in bytes, CRC included (docs/SAFETY.md has the byte offsets).
inline constexpr size_t kLinkDatagramSize = 45;
/// `version` of the layout below, the only one sent; a receiver rejects any other. Version 1
/// (41 bytes, no session) let a restarted sender pass for the one that died: it is rejected.
inline constexpr uint16_t kLinkVersion = 2;

/// What a datagram stands for (`kind`, u16 at byte 6).
enum class LinkKind : uint16_t {
  frame = 1,       ///< a verdict written by the run: a processed frame, a watchdog stop or the run's last stop
  heartbeat = 2,   ///< the link is alive but no fresh verdict exists: always stop, reason no_frame
  final_stop = 3,  ///< the sender is done (summary or destruction): always stop; nothing follows
};

/// One datagram's values, before encoding or after decoding.
struct LinkDatagram {
  LinkKind kind = LinkKind::frame;
  /// The sender's process_session() (session.hpp): random, never 0 on the wire, one per process
  /// start; a new value means a new sender whose sequence starts again.
  uint32_t session = 0;
  uint32_t sequence = 0;       ///< +1 per datagram of any kind within a session, from 0 (wraps at 2^32)
  int64_t timestamp_ns = 0;    ///< the frame's host time (FrameResult::host_time_ns), ns, >= 0
  VerdictState verdict = VerdictState::stop;
  ReasonCode reason = ReasonCode::no_frame;
  float speed_scale = 0.0F;    ///< 0..1 of the programmed speed; 0 for stop
  /// The contact's distance to the robot, m, >= 0; NaN: no contact.
  float distance_m = std::numeric_limits<float>::quiet_NaN();
  float protective_distance_m = 0.0F;  ///< the distance the verdict compared against, m, >= 0
  uint16_t robot_state_age_ms = 0;     ///< saturates at 65535 (also for an unknown age)
};

using LinkBytes = std::array<uint8_t, kLinkDatagramSize>;

/// CRC-32 as IEEE 802.3 and zlib's crc32() (reflected, polynomial 0xEDB88320, init and final
/// xor 0xFFFFFFFF) of `size` bytes; `bytes` may be null when size is 0.
uint32_t crc32_ieee(const uint8_t* bytes, size_t size);

/// The datagram's bytes: little-endian, packed, the session in bytes 37..40, CRC-32 of bytes
/// 0..40 in bytes 41..44. The values are written as given (no validation:
/// decode_link_datagram is the check).
LinkBytes encode_link_datagram(const LinkDatagram& datagram);

/// What decode_link_datagram made of some bytes.
struct LinkDecodeResult {
  bool ok = false;
  LinkDatagram datagram;  ///< valid only when ok
  /// When !ok: the first problem, naming the field, e.g. "size: expected 45 bytes, got 44",
  /// "crc: 0x1234abcd in the datagram, 0x9f00e1c2 computed", "verdict: 7 is not 0, 1 or 2".
  std::string error;
};

/// Checks and reads one datagram (receivers, tests, the fuzzer): magic and version (another
/// version is another layout, so they come before the size; version 1 is named as the old
/// layout without a session), size, CRC (before any value, so a damaged datagram reads as a CRC
/// error), then every value: kind 1..3, session non-zero, verdict 0..2 and stop for heartbeats
/// and final stops, a reason code hrcsense knows, timestamp >= 0, speed_scale in [0, 1],
/// distance NaN or finite >= 0, protective distance finite >= 0. Never throws; `bytes` may be
/// null when size is 0. It checks one datagram; following a sender (session, sequence,
/// timeout) is LinkReceiver's job (link_receiver.hpp).
LinkDecodeResult decode_link_datagram(const uint8_t* bytes, size_t size);

/// The datagram of a written verdict. Values a receiver would reject are made safe rather than
/// sent: a non-finite speed scale is a stop for non_finite_input, the scale is clamped to
/// [0, 1], a missing, negative or non-finite distance is NaN, a non-finite or negative
/// protective distance 0, the robot state age rounded and saturated (unknown: 65535).
LinkDatagram link_datagram_from(const FrameResult& result, LinkKind kind, uint32_t session, uint32_t sequence);

/// `link.udp.address` as a socket address: numeric IPv4 "a.b.c.d:port" or "[IPv6]:port", port
/// 1..65535 (no name lookup). Throws std::invalid_argument naming link.udp.address otherwise.
sockaddr_storage parse_link_address(const std::string& address, unsigned& length);

/// How UdpLinkSink sends.
struct UdpLinkParams {
  std::string address;  ///< `link.udp.address`, see parse_link_address
  /// `link.udp.format`: binary (the HRCS layout, for a controller) or json (the frame's line, for
  /// logs and dashboards: no sequence on frames, no CRC; every datagram says
  /// `"for_control":false`)
  enum class Format { binary, json } format = Format::binary;
  double heartbeat_hz = 20.0;  ///< `link.heartbeat_hz`, > 0
  /// json format: the proximity backend its lines name when no search ran (`proximity.backend`)
  std::string backend = "brute";
  /// The datagrams' session; 0 (the default): process_session(), the same in the JSON Lines
  /// header. Tests set one to tell two sinks apart.
  uint32_t session = 0;
  /// How long, in real time, the sender thread waits at most before it reads the clock again:
  /// bounds how late a heartbeat is on a clock that jumps (a FakeClock in tests), ns.
  int64_t max_wait_ns = 2'000'000;
};

/// What a UdpLinkSink has sent, for the log and the tests.
struct UdpLinkCounters {
  int64_t frames = 0;        ///< kind 1 datagrams sent
  int64_t heartbeats = 0;    ///< kind 2
  int64_t final_stops = 0;   ///< kind 3 (0 or 1)
  int64_t send_errors = 0;   ///< datagrams not sent (a full socket buffer, no route, nobody listening)
  std::string last_error;    ///< the last send error, naming the address; empty when none
};

/// Sends every verdict the run writes as one datagram, a heartbeat whenever nothing was sent
/// for one heartbeat period (on `clock`), and a final stop from summary() or, when no summary
/// came, from the destructor. Sending never blocks frame(): the socket is non-blocking and a
/// failed send is counted (counters()), never thrown; a sink whose link fails does not end
/// the run (the controller stops on its own when datagrams stop arriving, docs/SAFETY.md).
/// frame() and summary() come from the run's output thread; a sender thread writes the
/// heartbeats; one mutex keeps the sequence in the order the datagrams leave. Every datagram
/// carries the sink's session (json format: a `session` member), so that a receiver takes a
/// restarted process for a new sender rather than for the dead one (LinkReceiver).
class UdpLinkSink final : public Sink {
 public:
  /// Opens the socket and starts the heartbeat thread (its first heartbeat one period from
  /// now). Throws std::invalid_argument naming link.udp.address for a bad address,
  /// std::runtime_error when no socket can be opened. `clock` must outlive the sink.
  UdpLinkSink(const UdpLinkParams& params, const RunClock& clock);
  /// Sends the final stop when summary() did not, stops the sender thread, closes the socket.
  ~UdpLinkSink() override;
  UdpLinkSink(const UdpLinkSink&) = delete;
  UdpLinkSink& operator=(const UdpLinkSink&) = delete;

  void header(const RunHeader& header) override;
  void frame(const FrameResult& result) override;
  /// Sends the final stop (reason: the summary's end code); nothing is sent after it.
  void summary(const RunSummary& summary) override;

  UdpLinkCounters counters() const;
  const std::string& address() const { return address_; }
  /// The session every datagram of this sink carries (never 0).
  uint32_t session() const { return session_; }

 private:
  void heartbeat_loop();
  // The callers hold mutex_.
  void send_locked(LinkKind kind, const FrameResult* result, ReasonCode reason);
  void send_final_locked(ReasonCode reason);
  void send_bytes_locked(const void* bytes, size_t size, LinkKind kind);

  const RunClock& clock_;
  std::string address_;
  UdpLinkParams::Format format_;
  int64_t period_ns_;
  int64_t max_wait_ns_;
  uint32_t session_;
  int fd_ = -1;

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  bool stop_ = false;
  bool final_sent_ = false;
  uint32_t sequence_ = 0;
  int64_t last_frame_ns_ = 0;       ///< clock time of the last frame datagram (or of construction)
  int64_t last_timestamp_ns_ = 0;   ///< the last frame's host time, for heartbeats and the final stop
  UdpLinkCounters counters_;
  class JsonFrames;  // json format: the frame lines (JsonLinesSink into a buffer)
  std::unique_ptr<JsonFrames> json_;  ///< null for the binary format
  std::string json_scratch_;        ///< heartbeat and final stop objects

  std::thread sender_;  // last: started once everything above exists
};

}  // namespace hrcsense
