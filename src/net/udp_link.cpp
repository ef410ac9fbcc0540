// SPDX-License-Identifier: Apache-2.0
// hrcsense — the link to the robot controller: the HRCS datagram (encode, decode, CRC-32) and
// UdpLinkSink, which sends one per verdict, heartbeats in silences and a final stop.
//
// Bytes are written and read one at a time by shifts, so the layout is little-endian whatever
// the host's byte order, and nothing depends on struct packing.
#include "hrcsense/net/link.hpp"

#include "hrcsense/safety.hpp"
#include "hrcsense/session.hpp"
#include "hrcsense/sinks/sinks.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <string_view>
#include <system_error>

namespace hrcsense {
namespace {

// Byte offsets (docs/SAFETY.md's version 2 table). Version 2 appends the session to version 1's
// fields, so every other offset stayed where it was.
constexpr size_t kMagicAt = 0, kVersionAt = 4, kKindAt = 6, kSequenceAt = 8, kTimestampAt = 12, kVerdictAt = 20,
                 kReasonAt = 21, kSpeedScaleAt = 23, kDistanceAt = 27, kProtectiveAt = 31, kAgeAt = 35,
                 kSessionAt = 37, kCrcAt = 41;
static_assert(kCrcAt + 4 == kLinkDatagramSize, "the CRC closes the datagram");
constexpr uint16_t kVersionWithoutSession = 1;
constexpr size_t kVersionWithoutSessionSize = 41;
constexpr char kMagic[4] = {'H', 'R', 'C', 'S'};

constexpr std::array<uint32_t, 256> make_crc_table() {
  std::array<uint32_t, 256> table{};
  for (uint32_t n = 0; n < 256; ++n) {
    uint32_t c = n;
    for (int bit = 0; bit < 8; ++bit) c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
    table[n] = c;
  }
  return table;
}
constexpr std::array<uint32_t, 256> kCrcTable = make_crc_table();

void put_le(uint8_t* at, uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) at[i] = static_cast<uint8_t>(value >> (8 * i));
}

uint64_t get_le(const uint8_t* at, int bytes) {
  uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value |= static_cast<uint64_t>(at[i]) << (8 * i);
  return value;
}

uint32_t float_bits(float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

float bits_float(uint64_t bits) {
  const auto narrow = static_cast<uint32_t>(bits);
  float value = 0.0F;
  std::memcpy(&value, &narrow, sizeof value);
  return value;
}

std::string hex32(uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", value);
  return text;
}

std::string float_text(float value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", static_cast<double>(value));
  return text;
}

bool known_reason(uint16_t code) {
  // reason_code_name covers every enumerator (a switch the compiler checks); any other
  // number is "unknown".
  return std::string_view(reason_code_name(static_cast<ReasonCode>(code))) != "unknown";
}

LinkDecodeResult fail(std::string error) {
  LinkDecodeResult result;
  result.error = std::move(error);
  return result;
}

}  // namespace

uint32_t crc32_ieee(const uint8_t* bytes, size_t size) {
  uint32_t crc = 0xFFFFFFFFU;
  for (size_t i = 0; i < size; ++i) crc = kCrcTable[(crc ^ bytes[i]) & 0xFFU] ^ (crc >> 8);
  return crc ^ 0xFFFFFFFFU;
}

LinkBytes encode_link_datagram(const LinkDatagram& d) {
  LinkBytes bytes{};
  std::memcpy(bytes.data() + kMagicAt, kMagic, sizeof kMagic);
  put_le(bytes.data() + kVersionAt, kLinkVersion, 2);
  put_le(bytes.data() + kKindAt, static_cast<uint16_t>(d.kind), 2);
  put_le(bytes.data() + kSequenceAt, d.sequence, 4);
  put_le(bytes.data() + kTimestampAt, static_cast<uint64_t>(d.timestamp_ns), 8);
  bytes[kVerdictAt] = static_cast<uint8_t>(d.verdict);
  put_le(bytes.data() + kReasonAt, static_cast<uint16_t>(d.reason), 2);
  put_le(bytes.data() + kSpeedScaleAt, float_bits(d.speed_scale), 4);
  put_le(bytes.data() + kDistanceAt, float_bits(d.distance_m), 4);
  put_le(bytes.data() + kProtectiveAt, float_bits(d.protective_distance_m), 4);
  put_le(bytes.data() + kAgeAt, d.robot_state_age_ms, 2);
  put_le(bytes.data() + kSessionAt, d.session, 4);
  put_le(bytes.data() + kCrcAt, crc32_ieee(bytes.data(), kCrcAt), 4);
  return bytes;
}

LinkDecodeResult decode_link_datagram(const uint8_t* bytes, size_t size) {
  const auto size_error = [size] {
    return fail("size: expected " + std::to_string(kLinkDatagramSize) + " bytes, got " + std::to_string(size));
  };
  // Magic and version first: another version is another layout, whose size says nothing, and a
  // version 1 sender (no session) should be named as such rather than as 4 bytes short.
  if (size < kKindAt) return size_error();
  if (std::memcmp(bytes + kMagicAt, kMagic, sizeof kMagic) != 0) return fail("magic: expected \"HRCS\"");
  const auto version = static_cast<uint16_t>(get_le(bytes + kVersionAt, 2));
  if (version == kVersionWithoutSession) {
    return fail("version: 1 is the " + std::to_string(kVersionWithoutSessionSize) +
                "-byte layout without a session, which cannot tell a restarted sender from the one that died; "
                "expected " + std::to_string(kLinkVersion) + " (update the sender)");
  }
  if (version != kLinkVersion) {
    return fail("version: " + std::to_string(version) + ", expected " + std::to_string(kLinkVersion));
  }
  if (size != kLinkDatagramSize) return size_error();
  const auto sent_crc = static_cast<uint32_t>(get_le(bytes + kCrcAt, 4));
  const uint32_t crc = crc32_ieee(bytes, kCrcAt);
  if (sent_crc != crc) return fail("crc: " + hex32(sent_crc) + " in the datagram, " + hex32(crc) + " computed");

  LinkDecodeResult result;
  LinkDatagram& d = result.datagram;
  const auto kind = static_cast<uint16_t>(get_le(bytes + kKindAt, 2));
  if (kind < 1 || kind > 3) return fail("kind: " + std::to_string(kind) + " is not 1, 2 or 3");
  d.kind = static_cast<LinkKind>(kind);
  d.session = static_cast<uint32_t>(get_le(bytes + kSessionAt, 4));
  if (d.session == 0) return fail("session: 0 is never sent (a sender draws a non-zero session at start)");
  d.sequence = static_cast<uint32_t>(get_le(bytes + kSequenceAt, 4));
  d.timestamp_ns = static_cast<int64_t>(get_le(bytes + kTimestampAt, 8));
  if (d.timestamp_ns < 0) return fail("timestamp_ns: " + std::to_string(d.timestamp_ns) + " is negative");
  const uint8_t verdict = bytes[kVerdictAt];
  if (verdict > 2) return fail("verdict: " + std::to_string(verdict) + " is not 0, 1 or 2");
  d.verdict = static_cast<VerdictState>(verdict);
  if (d.kind != LinkKind::frame && d.verdict != VerdictState::stop) {
    return fail("verdict: a " + std::string(d.kind == LinkKind::heartbeat ? "heartbeat" : "final stop") +
                " must say stop (2), got " + std::to_string(verdict));
  }
  const auto reason = static_cast<uint16_t>(get_le(bytes + kReasonAt, 2));
  if (!known_reason(reason)) return fail("reason_code: " + std::to_string(reason) + " is not a known code");
  d.reason = static_cast<ReasonCode>(reason);
  d.speed_scale = bits_float(get_le(bytes + kSpeedScaleAt, 4));
  if (!(d.speed_scale >= 0.0F && d.speed_scale <= 1.0F)) {  // NaN fails too
    return fail("speed_scale: " + float_text(d.speed_scale) + " is not in [0, 1]");
  }
  d.distance_m = bits_float(get_le(bytes + kDistanceAt, 4));
  if (!std::isnan(d.distance_m) && !(std::isfinite(d.distance_m) && d.distance_m >= 0.0F)) {
    return fail("distance_m: " + float_text(d.distance_m) + " is neither NaN (no contact) nor a distance >= 0");
  }
  d.protective_distance_m = bits_float(get_le(bytes + kProtectiveAt, 4));
  if (!(std::isfinite(d.protective_distance_m) && d.protective_distance_m >= 0.0F)) {
    return fail("protective_distance_m: " + float_text(d.protective_distance_m) + " is not a distance >= 0");
  }
  d.robot_state_age_ms = static_cast<uint16_t>(get_le(bytes + kAgeAt, 2));
  result.ok = true;
  return result;
}

LinkDatagram link_datagram_from(const FrameResult& result, LinkKind kind, uint32_t session, uint32_t sequence) {
  LinkDatagram d;
  d.kind = kind;
  d.session = session;
  d.sequence = sequence;
  d.timestamp_ns = std::max<int64_t>(0, result.host_time_ns);
  d.verdict = result.verdict.state;
  d.reason = result.verdict.code;
  const float scale = result.verdict.speed_scale;
  if (std::isfinite(scale)) {
    d.speed_scale = std::clamp(scale, 0.0F, 1.0F);
  } else {
    d.verdict = VerdictState::stop;
    d.reason = ReasonCode::non_finite_input;
    d.speed_scale = 0.0F;
  }
  if (d.verdict == VerdictState::stop) d.speed_scale = 0.0F;
  const float distance = result.contact.distance_m;
  d.distance_m = result.contact.valid && std::isfinite(distance) && distance >= 0.0F
                     ? distance
                     : std::numeric_limits<float>::quiet_NaN();
  const float protective = result.verdict.protective_distance_m;
  d.protective_distance_m = std::isfinite(protective) && protective >= 0.0F ? protective : 0.0F;
  const double age = result.robot_state_age_ms;
  d.robot_state_age_ms = std::isnan(age) ? uint16_t{65535}
                                         : static_cast<uint16_t>(std::llround(std::clamp(age, 0.0, 65535.0)));
  return d;
}

sockaddr_storage parse_link_address(const std::string& address, unsigned& length) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("link.udp.address '" + address + "': " + why);
  };
  const size_t colon = address.rfind(':');
  const std::string port_text = colon == std::string::npos ? "" : address.substr(colon + 1);
  unsigned port = 0;
  const std::from_chars_result r = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (port_text.empty() || r.ec != std::errc() || r.ptr != port_text.data() + port_text.size() || port < 1 ||
      port > 65535) {
    throw bad("expected host:port with a port from 1 to 65535");
  }
  std::string host = address.substr(0, colon);
  sockaddr_storage storage{};
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
    auto* v6 = reinterpret_cast<sockaddr_in6*>(&storage);
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons(static_cast<uint16_t>(port));
    if (inet_pton(AF_INET6, host.c_str(), &v6->sin6_addr) != 1) throw bad("not a numeric IPv6 address");
    length = sizeof(sockaddr_in6);
  } else {
    auto* v4 = reinterpret_cast<sockaddr_in*>(&storage);
    v4->sin_family = AF_INET;
    v4->sin_port = htons(static_cast<uint16_t>(port));
    if (inet_pton(AF_INET, host.c_str(), &v4->sin_addr) != 1) {
      throw bad("expected a numeric IPv4 address a.b.c.d:port or [IPv6]:port (no host names)");
    }
    length = sizeof(sockaddr_in);
  }
  return storage;
}

// ---- UdpLinkSink

// The json format's frame lines: JsonLinesSink writing into a reused string (its capacity stays,
// so a frame allocates nothing once the longest line has been seen). Every json datagram says
// `"for_control":false`: frame lines carry no sequence and no CRC (docs/SAFETY.md, "The json
// format"), so they are for logs and dashboards, not for a controller to act on.
class UdpLinkSink::JsonFrames {
 public:
  JsonFrames(const std::string& backend, uint32_t session)
      : stream_(&buffer_),
        sink_(stream_, backend),
        session_member_("\"session\":" + std::to_string(session) + ",\"for_control\":false,") {}
  void header(const RunHeader& header) {
    sink_.header(header);  // the sink learns what frames carry (robot_status); the line is not sent
    buffer_.text.clear();
  }
  /// The frame's line without its newline, with `"session":N,"for_control":false` after its
  /// first member (`type`), so that a json receiver can tell a restarted sender too and no one
  /// takes the line for a control datagram. The line is the JSON Lines sink's, whose first
  /// member is always `"type":"frame"` or `"type":"verdict"` (no comma inside), so the first
  /// comma ends it.
  std::string_view line(const FrameResult& result) {
    buffer_.text.clear();
    stream_.clear();
    sink_.frame(result);
    const size_t first_comma = buffer_.text.find(',');
    if (first_comma != std::string::npos) buffer_.text.insert(first_comma + 1, session_member_);
    std::string_view text = buffer_.text;
    if (!text.empty() && text.back() == '\n') text.remove_suffix(1);
    return text;
  }

 private:
  struct Buffer final : std::streambuf {
    std::string text;
    int_type overflow(int_type ch) override {
      if (ch != traits_type::eof()) text += static_cast<char>(ch);
      return traits_type::not_eof(ch);
    }
    std::streamsize xsputn(const char* s, std::streamsize n) override {
      text.append(s, static_cast<size_t>(n));
      return n;
    }
  };
  Buffer buffer_;
  std::ostream stream_;
  JsonLinesSink sink_;
  std::string session_member_;  ///< `"session":N,"for_control":false,`
};

UdpLinkSink::UdpLinkSink(const UdpLinkParams& params, const RunClock& clock)
    : clock_(clock),
      address_(params.address),
      format_(params.format),
      period_ns_(std::max<int64_t>(1, std::llround(1e9 / params.heartbeat_hz))),
      max_wait_ns_(std::max<int64_t>(1, params.max_wait_ns)),
      session_(params.session != 0 ? params.session : process_session()) {
  if (!(params.heartbeat_hz > 0.0) || !std::isfinite(params.heartbeat_hz)) {
    throw std::invalid_argument("link.heartbeat_hz: expected a positive rate");
  }
  unsigned length = 0;
  const sockaddr_storage destination = parse_link_address(address_, length);
  if (format_ == UdpLinkParams::Format::json) json_ = std::make_unique<JsonFrames>(params.backend, session_);
  fd_ = ::socket(destination.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    throw std::runtime_error("link.udp.address '" + address_ + "': socket: " + std::system_category().message(errno));
  }
  // Connected: the kernel looks the route up once, and a receiver that is not there shows as
  // ECONNREFUSED on a later send (counted) instead of going unnoticed.
  if (::connect(fd_, reinterpret_cast<const sockaddr*>(&destination), static_cast<socklen_t>(length)) != 0) {
    const int error = errno;
    ::close(fd_);
    throw std::runtime_error("link.udp.address '" + address_ + "': " + std::system_category().message(error));
  }
  last_frame_ns_ = clock_.now_ns();
  try {
    sender_ = std::thread([this] { heartbeat_loop(); });
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

UdpLinkSink::~UdpLinkSink() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    // No summary: the run did not end normally. The controller still hears a last stop.
    if (!final_sent_) send_final_locked(ReasonCode::no_frame);
    stop_ = true;
  }
  wake_.notify_all();
  sender_.join();
  ::close(fd_);
}

void UdpLinkSink::header(const RunHeader& header) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (json_) json_->header(header);
}

void UdpLinkSink::frame(const FrameResult& result) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (final_sent_) return;
  last_timestamp_ns_ = std::max<int64_t>(0, result.host_time_ns);
  send_locked(LinkKind::frame, &result, result.verdict.code);
}

void UdpLinkSink::summary(const RunSummary& summary) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!final_sent_) send_final_locked(summary.end_code);
  }
  wake_.notify_all();
}

UdpLinkCounters UdpLinkSink::counters() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

void UdpLinkSink::heartbeat_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  int64_t due_ns = last_frame_ns_ + period_ns_;
  while (!stop_ && !final_sent_) {
    // A frame since the last look moves the deadline: one period after it.
    due_ns = std::max(due_ns, last_frame_ns_ + period_ns_);
    const int64_t now_ns = clock_.now_ns();
    if (now_ns >= due_ns) {
      send_locked(LinkKind::heartbeat, nullptr, ReasonCode::no_frame);
      // The next one a period after this one was due, so the rate does not drift with the
      // thread's wake-up delay; after a stall longer than a period, one period from now.
      due_ns = now_ns - due_ns >= period_ns_ ? now_ns + period_ns_ : due_ns + period_ns_;
      continue;
    }
    // Real-time wait, at most max_wait_ns_: the clock decides (a fake one too).
    wake_.wait_for(lock, std::chrono::nanoseconds(std::min(due_ns - now_ns, max_wait_ns_)));
  }
}

void UdpLinkSink::send_final_locked(ReasonCode reason) {
  final_sent_ = true;
  send_locked(LinkKind::final_stop, nullptr, reason);
}

void UdpLinkSink::send_locked(LinkKind kind, const FrameResult* result, ReasonCode reason) {
  const uint32_t sequence = sequence_++;
  if (json_ && kind == LinkKind::frame) {
    const std::string_view line = json_->line(*result);
    send_bytes_locked(line.data(), line.size(), kind);
    return;
  }
  if (json_) {
    // {"type":"heartbeat"|"final_stop","session":S,"for_control":false,"sequence":N,"timestamp_ns":T,
    //  "verdict":"stop","reason_code":"..."}
    char text[256];
    const int n = std::snprintf(text, sizeof text,
                                "{\"type\":\"%s\",\"session\":%u,\"for_control\":false,\"sequence\":%u,"
                                "\"timestamp_ns\":%lld,\"verdict\":\"stop\",\"reason_code\":\"%s\"}",
                                kind == LinkKind::heartbeat ? "heartbeat" : "final_stop", session_, sequence,
                                static_cast<long long>(last_timestamp_ns_), reason_code_name(reason));
    send_bytes_locked(text, static_cast<size_t>(std::clamp(n, 0, static_cast<int>(sizeof text) - 1)), kind);
    return;
  }
  LinkDatagram d;
  if (result != nullptr) {
    d = link_datagram_from(*result, kind, session_, sequence);
  } else {
    // Heartbeat and final stop: fail safe. The link is alive, but no fresh verdict exists, so
    // the datagram says stop, stamped with the last frame's time so that a receiver can tell
    // how old the last real verdict is.
    d.kind = kind;
    d.session = session_;
    d.sequence = sequence;
    d.timestamp_ns = last_timestamp_ns_;
    d.verdict = VerdictState::stop;
    d.reason = reason;
  }
  const LinkBytes bytes = encode_link_datagram(d);
  send_bytes_locked(bytes.data(), bytes.size(), kind);
}

void UdpLinkSink::send_bytes_locked(const void* bytes, size_t size, LinkKind kind) {
  // Frames push the next heartbeat back; heartbeats keep their own schedule (heartbeat_loop).
  if (kind == LinkKind::frame) last_frame_ns_ = clock_.now_ns();
  ssize_t sent = -1;
  int error = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {  // EINTR only; bounded
    sent = ::send(fd_, bytes, size, MSG_DONTWAIT | MSG_NOSIGNAL);
    error = sent < 0 ? errno : 0;
    if (error != EINTR) break;
  }
  if (sent == static_cast<ssize_t>(size)) {
    switch (kind) {
      case LinkKind::frame: ++counters_.frames; break;
      case LinkKind::heartbeat: ++counters_.heartbeats; break;
      case LinkKind::final_stop: ++counters_.final_stops; break;
    }
    return;
  }
  ++counters_.send_errors;
  counters_.last_error = "link.udp.address '" + address_ + "': " +
                         (sent < 0 ? std::system_category().message(error) : std::string("short send"));
}

}  // namespace hrcsense
