// SPDX-License-Identifier: Apache-2.0
// hrcsense — LinkReceiver: session, sequence and timeout of the link's datagrams
// (link_receiver.hpp has the rules, docs/SAFETY.md "Receiving" the why).
#include "hrcsense/net/link_receiver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrcsense {

const char* link_take_name(LinkTake take) {
  switch (take) {
    case LinkTake::taken: return "taken";
    case LinkTake::first_session: return "first_session";
    case LinkTake::new_session: return "new_session";
    case LinkTake::malformed: return "malformed";
    case LinkTake::old_sequence: return "old_sequence";
    case LinkTake::after_final_stop: return "after_final_stop";
    case LinkTake::retired_session: return "retired_session";
  }
  return "unknown";
}

bool link_taken(LinkTake take) {
  return take == LinkTake::taken || take == LinkTake::first_session || take == LinkTake::new_session;
}

const char* link_verdict_basis_name(LinkVerdictBasis basis) {
  switch (basis) {
    case LinkVerdictBasis::nothing_taken: return "nothing_taken";
    case LinkVerdictBasis::timed_out: return "timed_out";
    case LinkVerdictBasis::frame: return "frame";
    case LinkVerdictBasis::heartbeat: return "heartbeat";
    case LinkVerdictBasis::final_stop: return "final_stop";
  }
  return "unknown";
}

LinkReceiver::LinkReceiver(const LinkReceiverParams& params) : timeout_ns_(params.timeout_ns) {
  if (timeout_ns_ <= 0) throw std::invalid_argument("LinkReceiver: timeout_ns must be > 0");
}

LinkTake LinkReceiver::take_bytes(const uint8_t* bytes, size_t size, int64_t arrival_ns) {
  const LinkDecodeResult decoded = decode_link_datagram(bytes, size);
  if (!decoded.ok) {
    ++counters_.malformed;
    return LinkTake::malformed;
  }
  return take(decoded.datagram, arrival_ns);
}

LinkTake LinkReceiver::take(const LinkDatagram& d, int64_t arrival_ns) {
  if (d.session == 0) {  // never sent: not a decoded datagram
    ++counters_.malformed;
    return LinkTake::malformed;
  }
  if (session_ == 0) return accept(d, arrival_ns, LinkTake::first_session);  // rule 2
  if (d.session != session_) {  // rule 4
    if (retired(d.session)) {
      ++counters_.retired_session;
      return LinkTake::retired_session;
    }
    retire(session_);
    return accept(d, arrival_ns, LinkTake::new_session);
  }
  // Rule 3. The sender sends nothing after its final stop, so anything later is a replay.
  if (final_taken_) {
    ++counters_.after_final_stop;
    return LinkTake::after_final_stop;
  }
  if (static_cast<int32_t>(d.sequence - last_.sequence) <= 0) {
    ++counters_.old_sequence;
    return LinkTake::old_sequence;
  }
  return accept(d, arrival_ns, LinkTake::taken);
}

LinkTake LinkReceiver::accept(const LinkDatagram& d, int64_t arrival_ns, LinkTake how) {
  if (how != LinkTake::taken) {
    session_ = d.session;
    ++counters_.sessions;
    if (how == LinkTake::new_session) ++counters_.new_sessions;
  }
  final_taken_ = d.kind == LinkKind::final_stop;
  last_ = d;
  last_arrival_ns_ = arrival_ns;
  have_last_ = true;
  ++counters_.taken;
  return how;
}

bool LinkReceiver::retired(uint32_t session) const {
  return std::find(retired_.begin(), retired_.end(), session) != retired_.end();
}

void LinkReceiver::retire(uint32_t session) {
  retired_[retired_next_] = session;
  retired_next_ = (retired_next_ + 1) % retired_.size();
}

LinkReceiverVerdict LinkReceiver::verdict(int64_t now_ns) const {
  LinkReceiverVerdict v;  // stop, nothing taken
  if (!have_last_) return v;
  v.session = last_.session;
  v.sequence = last_.sequence;
  v.age_ns = std::max<int64_t>(0, now_ns - last_arrival_ns_);
  if (v.age_ns >= timeout_ns_) {
    v.basis = LinkVerdictBasis::timed_out;
    return v;
  }
  v.reason = last_.reason;
  switch (last_.kind) {
    case LinkKind::heartbeat: v.basis = LinkVerdictBasis::heartbeat; return v;
    case LinkKind::final_stop: v.basis = LinkVerdictBasis::final_stop; return v;
    case LinkKind::frame: break;
  }
  v.basis = LinkVerdictBasis::frame;
  // A frame's run or slow moves the robot only with a scale that means something: a value the
  // decoder would have refused (take() of a hand-made datagram) stops.
  const float scale = last_.speed_scale;
  if (last_.verdict != VerdictState::stop && std::isfinite(scale) && scale >= 0.0F && scale <= 1.0F) {
    v.state = last_.verdict;
    v.speed_scale = scale;
  }
  return v;
}

}  // namespace hrcsense
