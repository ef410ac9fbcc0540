// SPDX-License-Identifier: Apache-2.0
// hrcsense — the reference receiver of the link (docs/SAFETY.md, "Receiving"): what a controller
// should do with the datagrams of link.hpp. It follows one sender by its session and sequence,
// takes a restarted hrcsense as a new sender (never as the dead one), and says stop whenever
// nothing was taken within its timeout.
#pragma once

#include "hrcsense/net/link.hpp"
#include "hrcsense/types.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace hrcsense {

/// How LinkReceiver judges silence.
struct LinkReceiverParams {
  /// The verdict is stop once nothing was *taken* for this long, counted from the arrival of the
  /// last taken datagram (not of the last datagram that decoded: a rejected one keeps nothing
  /// alive), ns, > 0. hrcsense sends at least every 1 / link.heartbeat_hz (50 ms by default), so
  /// 100-200 ms tolerates a lost datagram or two.
  int64_t timeout_ns = 200'000'000;
};

/// What LinkReceiver::take did with one datagram.
enum class LinkTake {
  taken,             ///< the current session's next datagram
  first_session,     ///< taken: the first datagram this receiver took; its session becomes current
  new_session,       ///< taken: a session never seen before replaced the current one (a restart)
  malformed,         ///< rejected: the bytes did not decode, or session 0 (take_bytes; take)
  old_sequence,      ///< rejected: not newer than the last taken of its session (replay, duplicate, reordered)
  after_final_stop,  ///< rejected: its session has sent its final stop, nothing may follow
  retired_session,   ///< rejected: a session this receiver has left (a dead sender's late datagram)
};

/// The take's name as the counters and the example print it ("taken", "old_sequence", ...).
const char* link_take_name(LinkTake take);
/// True for taken, first_session and new_session.
bool link_taken(LinkTake take);

/// What a LinkReceiver has seen, for its log.
struct LinkReceiverCounters {
  int64_t taken = 0;             ///< datagrams taken, new sessions included
  int64_t sessions = 0;          ///< sessions followed: the first one and every new_session
  int64_t new_sessions = 0;      ///< restarts taken (new_session)
  int64_t malformed = 0;
  int64_t old_sequence = 0;
  int64_t after_final_stop = 0;
  int64_t retired_session = 0;
};

/// Where LinkReceiver's verdict comes from.
enum class LinkVerdictBasis {
  nothing_taken,  ///< no datagram taken yet: stop
  timed_out,      ///< nothing taken for timeout_ns: stop
  frame,          ///< the last taken datagram, a frame: its verdict and scale
  heartbeat,      ///< the last taken datagram, a heartbeat: stop
  final_stop,     ///< the last taken datagram, the sender's final stop: stop
};

/// The name of a basis ("nothing_taken", "timed_out", "frame", "heartbeat", "final_stop").
const char* link_verdict_basis_name(LinkVerdictBasis basis);

/// What the robot should do now, by the datagrams taken so far.
struct LinkReceiverVerdict {
  VerdictState state = VerdictState::stop;
  float speed_scale = 0.0F;  ///< 0..1 of the programmed speed; 0 for stop
  /// The last taken datagram's reason; no_frame when nothing was taken or it timed out.
  ReasonCode reason = ReasonCode::no_frame;
  LinkVerdictBasis basis = LinkVerdictBasis::nothing_taken;
  uint32_t session = 0;   ///< the last taken datagram's session; 0 when none was taken
  uint32_t sequence = 0;  ///< the last taken datagram's sequence
  int64_t age_ns = -1;    ///< since the last taken datagram arrived, ns; -1 when none was taken
};

/// Follows the datagrams of one hrcsense at a time. Rules (docs/SAFETY.md, "Receiving"):
/// 1. Only decoded datagrams count (take_bytes decodes; anything that fails is malformed).
/// 2. The first datagram taken starts the first session, whatever its sequence.
/// 3. Same session: taken when its sequence is newer than the last taken, with wrap-around
///    ((int32_t)(sequence - last) > 0), and the session has not sent its final stop; otherwise
///    rejected (old_sequence, after_final_stop).
/// 4. Another session: a process start draws a new one, so a session never seen before is a
///    restarted (or replacing) sender: taken at once as new_session, whatever its sequence, and
///    the current session is retired. A retired session is never taken again (retired_session):
///    a dead process's datagrams arriving late cannot bring its last `run` back. The receiver
///    remembers the last kRetiredSessions sessions it left.
/// 5. The verdict is stop when nothing was taken yet, when nothing was taken for timeout_ns
///    (counted from the arrival of the last taken datagram), and when the last taken datagram
///    is a heartbeat, a final stop or a frame saying stop; otherwise the last taken frame's
///    verdict and speed scale.
/// Two hrcsense processes sending to one receiver is a configuration error: the one that started
/// last is followed and the other's datagrams are counted as retired_session.
/// Not thread-safe; no allocation; arrival and verdict times on one monotonic clock, ns.
class LinkReceiver {
 public:
  /// How many left sessions are remembered (rule 4).
  static constexpr size_t kRetiredSessions = 16;

  /// Throws std::invalid_argument when params.timeout_ns is not > 0.
  explicit LinkReceiver(const LinkReceiverParams& params = {});

  /// Judges one decoded datagram (decode_link_datagram's ok result) that arrived at
  /// `arrival_ns`. A datagram with session 0 is malformed (never sent).
  LinkTake take(const LinkDatagram& datagram, int64_t arrival_ns);
  /// Decodes `size` bytes (decode_link_datagram) and takes them; malformed when they do not
  /// decode. `bytes` may be null when size is 0.
  LinkTake take_bytes(const uint8_t* bytes, size_t size, int64_t arrival_ns);

  /// The verdict at `now_ns` (rule 5). A `now_ns` before the last taken arrival (two clocks
  /// mixed up) reads as age 0.
  LinkReceiverVerdict verdict(int64_t now_ns) const;

  const LinkReceiverCounters& counters() const { return counters_; }
  /// The session followed now; 0 before the first datagram is taken.
  uint32_t session() const { return session_; }

 private:
  bool retired(uint32_t session) const;
  void retire(uint32_t session);
  LinkTake accept(const LinkDatagram& datagram, int64_t arrival_ns, LinkTake how);

  int64_t timeout_ns_;
  uint32_t session_ = 0;        ///< 0: none yet
  bool final_taken_ = false;    ///< the current session's final stop was taken
  bool have_last_ = false;
  LinkDatagram last_;           ///< the last taken datagram
  int64_t last_arrival_ns_ = 0; ///< when it arrived
  std::array<uint32_t, kRetiredSessions> retired_{};  ///< ring of left sessions (0: empty slot)
  size_t retired_next_ = 0;
  LinkReceiverCounters counters_;
};

}  // namespace hrcsense
