// SPDX-License-Identifier: Apache-2.0
// The link to the controller: the HRCS datagram (version 2, with the session) against bytes laid
// out by hand from the layout in docs/SAFETY.md (CRC values from zlib's crc32), its decoder
// against every kind of damage and against version 1, and UdpLinkSink against a receiver socket
// in this process on 127.0.0.1 (ephemeral ports, every wait bounded), on a fake clock; then
// `hrcsense run` with the link on.
#include "hrcsense/net/link.hpp"

#include "hrcsense/clock.hpp"
#include "hrcsense/safety.hpp"
#include "hrcsense/session.hpp"
#include "hrcsense/sinks/sinks.hpp"

#include "../support/loopback.hpp"
#include "../support/units.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace {

using test::kMs;

// A frame datagram laid out by hand: magic "HRCS", version 2, kind 1, sequence 0x01020304,
// timestamp 0x0011223344556677, verdict 1 (slow), reason 2 (in_slow_zone), speed_scale 0.5
// (0x3F000000), distance 1.25 (0x3FA00000), protective 0.75 (0x3F400000), age 12 ms, session
// 0x89ABCDEF, then zlib.crc32 of those 41 bytes, 0xA82F0729.
constexpr std::array<uint8_t, 45> kHandLaid = {
    0x48, 0x52, 0x43, 0x53,                          //  0 magic
    0x02, 0x00,                                      //  4 version
    0x01, 0x00,                                      //  6 kind
    0x04, 0x03, 0x02, 0x01,                          //  8 sequence
    0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11, 0x00,  // 12 timestamp_ns
    0x01,                                            // 20 verdict
    0x02, 0x00,                                      // 21 reason code
    0x00, 0x00, 0x00, 0x3F,                          // 23 speed_scale
    0x00, 0x00, 0xA0, 0x3F,                          // 27 distance_m
    0x00, 0x00, 0x40, 0x3F,                          // 31 protective_distance_m
    0x0C, 0x00,                                      // 35 robot state age, ms
    0xEF, 0xCD, 0xAB, 0x89,                          // 37 session
    0x29, 0x07, 0x2F, 0xA8,                          // 41 CRC-32
};
constexpr uint32_t kHandLaidCrc = 0xA82F0729U;

// The same frame in version 1's 41-byte layout (no session; zlib.crc32 of 37 bytes, 0x760D0479):
// what a sender before version 2 sent. It must be refused, by name.
constexpr std::array<uint8_t, 41> kVersion1 = {
    0x48, 0x52, 0x43, 0x53, 0x01, 0x00, 0x01, 0x00, 0x04, 0x03, 0x02, 0x01, 0x77, 0x66,
    0x55, 0x44, 0x33, 0x22, 0x11, 0x00, 0x01, 0x02, 0x00, 0x00, 0x00, 0x00, 0x3F, 0x00,
    0x00, 0xA0, 0x3F, 0x00, 0x00, 0x40, 0x3F, 0x0C, 0x00, 0x79, 0x04, 0x0D, 0x76,
};

LinkDatagram hand_laid_values() {
  LinkDatagram d;
  d.kind = LinkKind::frame;
  d.session = 0x89ABCDEFU;
  d.sequence = 0x01020304U;
  d.timestamp_ns = 0x0011223344556677LL;
  d.verdict = VerdictState::slow;
  d.reason = ReasonCode::in_slow_zone;
  d.speed_scale = 0.5F;
  d.distance_m = 1.25F;
  d.protective_distance_m = 0.75F;
  d.robot_state_age_ms = 12;
  return d;
}

LinkDecodeResult decode(const std::vector<uint8_t>& bytes) { return decode_link_datagram(bytes.data(), bytes.size()); }

// kHandLaid with bytes [at, at + patch.size()) replaced and the CRC made right again, so that
// the value itself is what the decoder sees.
std::vector<uint8_t> patched(size_t at, const std::vector<uint8_t>& patch) {
  std::vector<uint8_t> bytes(kHandLaid.begin(), kHandLaid.end());
  std::copy(patch.begin(), patch.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at));
  const uint32_t crc = crc32_ieee(bytes.data(), 41);  // checked against zlib's value below
  for (int i = 0; i < 4; ++i) bytes[41 + static_cast<size_t>(i)] = static_cast<uint8_t>(crc >> (8 * i));
  return bytes;
}

std::vector<uint8_t> float_le(float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return {static_cast<uint8_t>(bits), static_cast<uint8_t>(bits >> 8), static_cast<uint8_t>(bits >> 16),
          static_cast<uint8_t>(bits >> 24)};
}

// ---- CRC, encoding, decoding

TEST(UdpLinkCrc, MatchesTheStandardCheckValues) {
  const std::string check = "123456789";
  EXPECT_EQ(crc32_ieee(reinterpret_cast<const uint8_t*>(check.data()), check.size()), 0xCBF43926U);
  EXPECT_EQ(crc32_ieee(nullptr, 0), 0U);
  EXPECT_EQ(crc32_ieee(kHandLaid.data(), 41), kHandLaidCrc);
  EXPECT_EQ(crc32_ieee(kVersion1.data(), 37), 0x760D0479U);
}

TEST(UdpLinkEncode, EveryFieldAtItsHandWrittenOffset) {
  const LinkBytes bytes = encode_link_datagram(hand_laid_values());
  ASSERT_EQ(bytes.size(), 45U);
  for (size_t i = 0; i < bytes.size(); ++i) EXPECT_EQ(bytes[i], kHandLaid[i]) << "byte " << i;
}

TEST(UdpLinkEncode, NanDistanceAndSaturatedFields) {
  LinkDatagram d;
  d.kind = LinkKind::heartbeat;
  d.session = 0xFFFFFFFFU;
  d.sequence = 0xFFFFFFFFU;
  d.timestamp_ns = 1;
  d.reason = ReasonCode::no_frame;  // 16
  d.robot_state_age_ms = 65535;
  const LinkBytes b = encode_link_datagram(d);
  EXPECT_EQ(b[6], 0x02);
  EXPECT_EQ(b[7], 0x00);
  for (size_t i = 8; i < 12; ++i) EXPECT_EQ(b[i], 0xFF);
  EXPECT_EQ(b[12], 0x01);
  EXPECT_EQ(b[20], 0x02);  // stop
  EXPECT_EQ(b[21], 16);
  EXPECT_EQ(b[22], 0);
  // quiet NaN, 0x7FC00000
  EXPECT_EQ(b[27], 0x00);
  EXPECT_EQ(b[28], 0x00);
  EXPECT_EQ(b[29], 0xC0);
  EXPECT_EQ(b[30], 0x7F);
  EXPECT_EQ(b[35], 0xFF);
  EXPECT_EQ(b[36], 0xFF);
  for (size_t i = 37; i < 41; ++i) EXPECT_EQ(b[i], 0xFF) << "session byte " << i;
}

TEST(UdpLinkDecode, ReadsTheHandLaidDatagram) {
  const LinkDecodeResult r = decode_link_datagram(kHandLaid.data(), kHandLaid.size());
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.datagram.kind, LinkKind::frame);
  EXPECT_EQ(r.datagram.session, 0x89ABCDEFU);
  EXPECT_EQ(r.datagram.sequence, 0x01020304U);
  EXPECT_EQ(r.datagram.timestamp_ns, 0x0011223344556677LL);
  EXPECT_EQ(r.datagram.verdict, VerdictState::slow);
  EXPECT_EQ(r.datagram.reason, ReasonCode::in_slow_zone);
  EXPECT_EQ(r.datagram.speed_scale, 0.5F);
  EXPECT_EQ(r.datagram.distance_m, 1.25F);
  EXPECT_EQ(r.datagram.protective_distance_m, 0.75F);
  EXPECT_EQ(r.datagram.robot_state_age_ms, 12);
}

TEST(UdpLinkDecode, WrongLengthIsRejected) {
  EXPECT_EQ(decode_link_datagram(nullptr, 0).error, "size: expected 45 bytes, got 0");
  EXPECT_EQ(decode_link_datagram(kHandLaid.data(), 5).error, "size: expected 45 bytes, got 5");
  EXPECT_EQ(decode_link_datagram(kHandLaid.data(), 41).error, "size: expected 45 bytes, got 41");
  EXPECT_EQ(decode_link_datagram(kHandLaid.data(), 44).error, "size: expected 45 bytes, got 44");
  std::vector<uint8_t> longer(kHandLaid.begin(), kHandLaid.end());
  longer.push_back(0);
  EXPECT_EQ(decode(longer).error, "size: expected 45 bytes, got 46");
}

TEST(UdpLinkDecode, VersionOneIsRejectedByName) {
  // A version 1 sender cannot be told from its restarted self: refused however long it is.
  const std::string expected =
      "version: 1 is the 41-byte layout without a session, which cannot tell a restarted sender from the one "
      "that died; expected 2 (update the sender)";
  EXPECT_EQ(decode_link_datagram(kVersion1.data(), kVersion1.size()).error, expected);
  EXPECT_EQ(decode(patched(4, {1, 0})).error, expected);  // 45 bytes saying version 1
  EXPECT_EQ(decode(patched(4, {3, 0})).error, "version: 3, expected 2");
  EXPECT_EQ(decode(patched(4, {0, 0})).error, "version: 0, expected 2");
}

TEST(UdpLinkDecode, EveryFlippedBitAndByteIsRejected) {
  const auto expect_rejected = [](const std::vector<uint8_t>& bytes, const std::string& what) {
    const LinkDecodeResult r = decode(bytes);
    ASSERT_FALSE(r.ok) << what;
    // Magic and version are read before the CRC (another protocol, another layout); anything
    // else damaged is a CRC mismatch.
    const bool named = r.error.rfind("crc: ", 0) == 0 || r.error.rfind("magic: ", 0) == 0 ||
                       r.error.rfind("version: ", 0) == 0;
    EXPECT_TRUE(named) << what << ": " << r.error;
  };
  for (size_t i = 0; i < kHandLaid.size(); ++i) {
    std::vector<uint8_t> bytes(kHandLaid.begin(), kHandLaid.end());
    bytes[i] ^= 0xFF;
    expect_rejected(bytes, "byte " + std::to_string(i));
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> one(kHandLaid.begin(), kHandLaid.end());
      one[i] ^= static_cast<uint8_t>(1U << bit);
      expect_rejected(one, "byte " + std::to_string(i) + " bit " + std::to_string(bit));
    }
  }
  std::vector<uint8_t> crc_flipped(kHandLaid.begin(), kHandLaid.end());
  crc_flipped[41] ^= 0x01;
  EXPECT_EQ(decode(crc_flipped).error, "crc: 0xa82f0728 in the datagram, 0xa82f0729 computed");
  std::vector<uint8_t> session_flipped(kHandLaid.begin(), kHandLaid.end());
  session_flipped[37] ^= 0x01;  // the CRC covers the session
  EXPECT_EQ(decode(session_flipped).error.rfind("crc: ", 0), 0U);
}

TEST(UdpLinkDecode, EachBadValueWithAGoodCrcNamesItsField) {
  const auto error_of = [](size_t at, const std::vector<uint8_t>& patch) { return decode(patched(at, patch)).error; };
  EXPECT_EQ(error_of(0, {'H', 'R', 'C', 'X'}), "magic: expected \"HRCS\"");
  EXPECT_EQ(error_of(4, {9, 0}), "version: 9, expected 2");
  EXPECT_EQ(error_of(6, {0, 0}), "kind: 0 is not 1, 2 or 3");
  EXPECT_EQ(error_of(6, {4, 0}), "kind: 4 is not 1, 2 or 3");
  EXPECT_EQ(error_of(37, {0, 0, 0, 0}), "session: 0 is never sent (a sender draws a non-zero session at start)");
  EXPECT_EQ(error_of(12, {0, 0, 0, 0, 0, 0, 0, 0x80}), "timestamp_ns: -9223372036854775808 is negative");
  EXPECT_EQ(error_of(20, {3}), "verdict: 3 is not 0, 1 or 2");
  EXPECT_EQ(error_of(6, {2, 0}), "verdict: a heartbeat must say stop (2), got 1");
  EXPECT_EQ(error_of(6, {3, 0}), "verdict: a final stop must say stop (2), got 1");
  EXPECT_EQ(error_of(21, {0xE7, 0x03}), "reason_code: 999 is not a known code");
  EXPECT_EQ(error_of(23, float_le(1.5F)), "speed_scale: 1.5 is not in [0, 1]");
  EXPECT_EQ(error_of(23, float_le(-0.25F)), "speed_scale: -0.25 is not in [0, 1]");
  EXPECT_EQ(error_of(23, float_le(std::numeric_limits<float>::quiet_NaN())), "speed_scale: nan is not in [0, 1]");
  EXPECT_EQ(error_of(27, float_le(-1.0F)), "distance_m: -1 is neither NaN (no contact) nor a distance >= 0");
  EXPECT_EQ(error_of(27, float_le(std::numeric_limits<float>::infinity())),
            "distance_m: inf is neither NaN (no contact) nor a distance >= 0");
  EXPECT_EQ(error_of(31, float_le(std::numeric_limits<float>::quiet_NaN())),
            "protective_distance_m: nan is not a distance >= 0");
  // The edges that are fine: a NaN distance, scale 0 and 1, the highest numbered code (30).
  EXPECT_TRUE(decode(patched(27, float_le(std::numeric_limits<float>::quiet_NaN()))).ok);
  EXPECT_TRUE(decode(patched(23, float_le(0.0F))).ok);
  EXPECT_TRUE(decode(patched(23, float_le(1.0F))).ok);
  EXPECT_TRUE(decode(patched(21, {30, 0})).ok);
  EXPECT_EQ(decode(patched(37, {1, 0, 0, 0})).datagram.session, 1U);
  EXPECT_EQ(decode(patched(37, {0xFF, 0xFF, 0xFF, 0xFF})).datagram.session, 0xFFFFFFFFU);
}

TEST(UdpLinkDecode, FuzzSeedsDecodeAsNamed) {
  const auto read = [](const std::string& name) {
    std::ifstream file(std::string(HRCSENSE_SOURCE_DIR) + "/fuzz/corpus/link/" + name, std::ios::binary);
    EXPECT_TRUE(file.good()) << name;
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  };
  EXPECT_TRUE(decode(read("frame")).ok);
  EXPECT_EQ(decode(read("heartbeat")).datagram.kind, LinkKind::heartbeat);
  EXPECT_EQ(decode(read("final_stop")).datagram.kind, LinkKind::final_stop);
  EXPECT_EQ(decode(read("no_contact")).ok, true);
  EXPECT_TRUE(std::isnan(decode(read("no_contact")).datagram.distance_m));
  EXPECT_EQ(decode(read("bad_crc")).error.rfind("crc: ", 0), 0U);
  EXPECT_EQ(decode(read("short")).error, "size: expected 45 bytes, got 20");
  EXPECT_EQ(decode(read("version1")).error.rfind("version: 1 is the 41-byte layout without a session", 0), 0U);
  for (const char* name : {"frame", "heartbeat", "final_stop", "no_contact"}) {
    EXPECT_NE(decode(read(name)).datagram.session, 0U) << name;
  }
}

TEST(UdpLinkDatagramFrom, TakesTheVerdictAndMakesUnsendableValuesSafe) {
  FrameResult r;
  r.host_time_ns = 123456789;
  r.verdict.state = VerdictState::slow;
  r.verdict.code = ReasonCode::in_slow_zone;
  r.verdict.speed_scale = 0.4F;
  r.verdict.protective_distance_m = 1.0F;
  r.contact.valid = true;
  r.contact.distance_m = 0.8F;
  r.robot_state_age_ms = 12.5;  // rounds half away from zero
  LinkDatagram d = link_datagram_from(r, LinkKind::frame, 0xC0FFEEU, 7);
  EXPECT_EQ(d.kind, LinkKind::frame);
  EXPECT_EQ(d.session, 0xC0FFEEU);
  EXPECT_EQ(d.sequence, 7U);
  EXPECT_EQ(d.timestamp_ns, 123456789);
  EXPECT_EQ(d.verdict, VerdictState::slow);
  EXPECT_EQ(d.reason, ReasonCode::in_slow_zone);
  EXPECT_EQ(d.speed_scale, 0.4F);
  EXPECT_EQ(d.distance_m, 0.8F);
  EXPECT_EQ(d.protective_distance_m, 1.0F);
  EXPECT_EQ(d.robot_state_age_ms, 13);

  r.contact.valid = false;  // no contact: NaN
  EXPECT_TRUE(std::isnan(link_datagram_from(r, LinkKind::frame, 1, 0).distance_m));
  r.robot_state_age_ms = 70000.0;
  EXPECT_EQ(link_datagram_from(r, LinkKind::frame, 1, 0).robot_state_age_ms, 65535);
  r.robot_state_age_ms = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(link_datagram_from(r, LinkKind::frame, 1, 0).robot_state_age_ms, 65535);
  r.robot_state_age_ms = -3.0;
  EXPECT_EQ(link_datagram_from(r, LinkKind::frame, 1, 0).robot_state_age_ms, 0);
  r.verdict.speed_scale = 1.5F;
  EXPECT_EQ(link_datagram_from(r, LinkKind::frame, 1, 0).speed_scale, 1.0F);
  r.verdict.protective_distance_m = std::numeric_limits<float>::infinity();
  EXPECT_EQ(link_datagram_from(r, LinkKind::frame, 1, 0).protective_distance_m, 0.0F);
  r.verdict.speed_scale = std::numeric_limits<float>::quiet_NaN();
  d = link_datagram_from(r, LinkKind::frame, 1, 0);
  EXPECT_EQ(d.verdict, VerdictState::stop);
  EXPECT_EQ(d.reason, ReasonCode::non_finite_input);
  EXPECT_EQ(d.speed_scale, 0.0F);
  // Whatever comes in, what goes out decodes.
  const LinkBytes bytes = encode_link_datagram(d);
  EXPECT_TRUE(decode_link_datagram(bytes.data(), bytes.size()).ok);
}

TEST(UdpLinkAddress, NumericAddressesOnlyAndTheKeyIsNamed) {
  unsigned length = 0;
  EXPECT_NO_THROW(parse_link_address("127.0.0.1:30020", length));
  EXPECT_EQ(length, sizeof(sockaddr_in));
  EXPECT_NO_THROW(parse_link_address("[::1]:30020", length));
  EXPECT_EQ(length, sizeof(sockaddr_in6));
  for (const char* bad : {"localhost:30020", "127.0.0.1", "127.0.0.1:0", "127.0.0.1:65536", "127.0.0.1:x",
                          "::1:30020", "[::1]", "[nonsense]:30020", ""}) {
    try {
      parse_link_address(bad, length);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("link.udp.address '" + std::string(bad) + "': ", 0), 0U) << e.what();
    }
  }
}

// ---- The sink, over loopback

// A UDP socket bound to 127.0.0.1 on an ephemeral port.
class Receiver {
 public:
  std::string address() const { return "127.0.0.1:" + std::to_string(socket_.port); }
  uint16_t port() const { return socket_.port; }

  /// The next datagram, waiting at most `timeout_ms`; none when nothing came.
  std::optional<std::string> next(int timeout_ms = 2000) const {
    pollfd fds{socket_.fd, POLLIN, 0};
    if (::poll(&fds, 1, timeout_ms) <= 0) return std::nullopt;
    char buffer[65536];
    const ssize_t got = ::recv(socket_.fd, buffer, sizeof buffer, MSG_DONTWAIT);
    if (got < 0) return std::nullopt;
    return std::string(buffer, static_cast<size_t>(got));
  }

  /// The next datagram decoded; fails the test when none comes or it does not decode.
  LinkDatagram next_datagram(int timeout_ms = 2000) const {
    const std::optional<std::string> bytes = next(timeout_ms);
    if (!bytes) {
      ADD_FAILURE() << "no datagram within " << timeout_ms << " ms";
      return {};
    }
    const LinkDecodeResult r = decode_link_datagram(reinterpret_cast<const uint8_t*>(bytes->data()), bytes->size());
    EXPECT_TRUE(r.ok) << r.error;
    return r.datagram;
  }

 private:
  test::LoopbackUdpSocket socket_;
};

FrameResult frame_at(int64_t index, int64_t host_time_ns, bool contact) {
  FrameResult r;
  r.frame = index;
  r.timestamp_ns = host_time_ns;
  r.host_time_ns = host_time_ns;
  r.valid = true;
  r.verdict.state = contact ? VerdictState::slow : VerdictState::run;
  r.verdict.code = contact ? ReasonCode::in_slow_zone : ReasonCode::no_foreground;
  r.verdict.speed_scale = contact ? 0.5F : 1.0F;
  r.verdict.protective_distance_m = 0.5F;
  r.contact.valid = contact;
  r.contact.distance_m = contact ? 0.75F : 0.0F;
  r.robot_state_age_ms = 4.0;
  return r;
}

UdpLinkParams params_for(const Receiver& receiver, double heartbeat_hz = 10.0) {
  UdpLinkParams params;
  params.address = receiver.address();
  params.heartbeat_hz = heartbeat_hz;  // 100 ms on the fake clock
  return params;
}

constexpr int kQuietMs = 60;  // well over the sender's 2 ms look at the clock

TEST(UdpLinkSink, FramesArriveInOrderWithTheirValues) {
  const Receiver receiver;
  FakeClock clock(1000 * kMs);
  UdpLinkSink sink(params_for(receiver), clock);
  // By default the process's session, the one the JSON Lines header names.
  EXPECT_NE(sink.session(), 0U);
  EXPECT_EQ(sink.session(), process_session());
  sink.header(RunHeader{});
  for (int64_t k = 0; k < 10; ++k) sink.frame(frame_at(k, 1000 * kMs + k, k % 2 == 1));
  for (uint32_t k = 0; k < 10; ++k) {
    const LinkDatagram d = receiver.next_datagram();
    EXPECT_EQ(d.kind, LinkKind::frame);
    EXPECT_EQ(d.session, process_session());
    EXPECT_EQ(d.sequence, k);
    EXPECT_EQ(d.timestamp_ns, 1000 * kMs + k);
    if (k % 2 == 1) {
      EXPECT_EQ(d.verdict, VerdictState::slow);
      EXPECT_EQ(d.speed_scale, 0.5F);
      EXPECT_EQ(d.distance_m, 0.75F);
    } else {
      EXPECT_EQ(d.verdict, VerdictState::run);
      EXPECT_EQ(d.reason, ReasonCode::no_foreground);
      EXPECT_TRUE(std::isnan(d.distance_m)) << k;
    }
    EXPECT_EQ(d.robot_state_age_ms, 4);
  }
  EXPECT_FALSE(receiver.next(kQuietMs)) << "the fake clock did not move: no heartbeat";
  const UdpLinkCounters counters = sink.counters();
  EXPECT_EQ(counters.frames, 10);
  EXPECT_EQ(counters.heartbeats, 0);
  EXPECT_EQ(counters.send_errors, 0);
}

TEST(UdpLinkSink, HeartbeatsWhenFramesStopSayStopWithTheLastFramesTime) {
  const Receiver receiver;
  FakeClock clock(0);
  UdpLinkSink sink(params_for(receiver), clock);
  sink.frame(frame_at(0, 5 * kMs, true));
  EXPECT_EQ(receiver.next_datagram().kind, LinkKind::frame);
  clock.advance(99 * kMs);
  EXPECT_FALSE(receiver.next(kQuietMs)) << "less than one period since the frame";
  for (uint32_t k = 1; k <= 3; ++k) {
    clock.advance(k == 1 ? 1 * kMs : 100 * kMs);  // 100 ms after the frame, then every 100 ms
    const LinkDatagram d = receiver.next_datagram();
    EXPECT_EQ(d.kind, LinkKind::heartbeat);
    EXPECT_EQ(d.sequence, k);
    EXPECT_EQ(d.verdict, VerdictState::stop);
    EXPECT_EQ(d.reason, ReasonCode::no_frame);
    EXPECT_EQ(d.speed_scale, 0.0F);
    EXPECT_EQ(d.timestamp_ns, 5 * kMs) << "the last frame's time";
    EXPECT_FALSE(receiver.next(kQuietMs)) << "one heartbeat per period";
  }
  // A frame again: the next heartbeat is one period after it.
  sink.frame(frame_at(1, 400 * kMs, false));
  EXPECT_EQ(receiver.next_datagram().sequence, 4U);
  clock.advance(50 * kMs);
  EXPECT_FALSE(receiver.next(kQuietMs));
  clock.advance(50 * kMs);
  const LinkDatagram d = receiver.next_datagram();
  EXPECT_EQ(d.kind, LinkKind::heartbeat);
  EXPECT_EQ(d.sequence, 5U);
  EXPECT_EQ(d.timestamp_ns, 400 * kMs);
  EXPECT_EQ(sink.counters().heartbeats, 4);
}

TEST(UdpLinkSink, EveryKindCarriesTheSinksSessionAndASecondSinkStartsItsOwnCount) {
  const Receiver receiver;
  FakeClock clock(0);
  UdpLinkParams first_params = params_for(receiver);
  first_params.session = 0x11111111U;
  {
    UdpLinkSink first(first_params, clock);
    EXPECT_EQ(first.session(), 0x11111111U);
    first.frame(frame_at(0, 5 * kMs, false));
    clock.advance(100 * kMs);  // one heartbeat
    const LinkDatagram frame = receiver.next_datagram();
    const LinkDatagram heartbeat = receiver.next_datagram();
    EXPECT_EQ(frame.session, 0x11111111U);
    EXPECT_EQ(heartbeat.kind, LinkKind::heartbeat);
    EXPECT_EQ(heartbeat.session, 0x11111111U);
    EXPECT_EQ(heartbeat.sequence, 1U);
  }
  const LinkDatagram last = receiver.next_datagram();  // the destructor's final stop
  EXPECT_EQ(last.kind, LinkKind::final_stop);
  EXPECT_EQ(last.session, 0x11111111U);
  // What a restart looks like on the wire: another session, the sequence from 0 again.
  UdpLinkParams second_params = params_for(receiver);
  second_params.session = 0x22222222U;
  UdpLinkSink second(second_params, clock);
  second.frame(frame_at(0, 900 * kMs, false));
  const LinkDatagram again = receiver.next_datagram();
  EXPECT_EQ(again.session, 0x22222222U);
  EXPECT_EQ(again.sequence, 0U);
}

TEST(UdpLinkSink, NoHeartbeatWhileFramesCome) {
  const Receiver receiver;
  FakeClock clock(0);
  UdpLinkSink sink(params_for(receiver), clock);
  for (int64_t k = 0; k < 20; ++k) {
    clock.advance(60 * kMs);  // 0.6 periods between frames
    sink.frame(frame_at(k, clock.now_ns(), false));
  }
  for (uint32_t k = 0; k < 20; ++k) {
    const LinkDatagram d = receiver.next_datagram();
    EXPECT_EQ(d.kind, LinkKind::frame) << k;
    EXPECT_EQ(d.sequence, k);
  }
  EXPECT_FALSE(receiver.next(kQuietMs));
  EXPECT_EQ(sink.counters().heartbeats, 0);
}

TEST(UdpLinkSink, HeartbeatsBeforeTheFirstFrame) {
  const Receiver receiver;
  FakeClock clock(0);
  UdpLinkSink sink(params_for(receiver), clock);
  clock.advance(100 * kMs);
  const LinkDatagram d = receiver.next_datagram();
  EXPECT_EQ(d.kind, LinkKind::heartbeat);
  EXPECT_EQ(d.sequence, 0U);
  EXPECT_EQ(d.timestamp_ns, 0) << "no frame yet";
  EXPECT_EQ(d.verdict, VerdictState::stop);
}

TEST(UdpLinkSink, FinalStopOnSummaryAndNothingAfterIt) {
  const Receiver receiver;
  FakeClock clock(0);
  {
    UdpLinkSink sink(params_for(receiver), clock);
    sink.frame(frame_at(0, 7 * kMs, true));
    RunSummary summary;
    summary.end_code = ReasonCode::frame_limit_reached;
    sink.summary(summary);
    EXPECT_EQ(receiver.next_datagram().kind, LinkKind::frame);
    const LinkDatagram last = receiver.next_datagram();
    EXPECT_EQ(last.kind, LinkKind::final_stop);
    EXPECT_EQ(last.sequence, 1U);
    EXPECT_EQ(last.verdict, VerdictState::stop);
    EXPECT_EQ(static_cast<uint16_t>(last.reason), 18) << "frame_limit_reached (docs/OUTPUT.md)";
    EXPECT_EQ(last.timestamp_ns, 7 * kMs);
    sink.frame(frame_at(1, 8 * kMs, true));
    clock.advance(1000 * kMs);
    EXPECT_FALSE(receiver.next(kQuietMs)) << "no frame or heartbeat after the final stop";
    EXPECT_EQ(sink.counters().final_stops, 1);
  }
  EXPECT_FALSE(receiver.next(kQuietMs)) << "the destructor sends no second final stop";
}

TEST(UdpLinkSink, DestructorSendsTheFinalStopWhenNoSummaryCame) {
  const Receiver receiver;
  FakeClock clock(0);
  {
    UdpLinkSink sink(params_for(receiver), clock);
    sink.frame(frame_at(0, 9 * kMs, false));
  }
  EXPECT_EQ(receiver.next_datagram().kind, LinkKind::frame);
  const LinkDatagram last = receiver.next_datagram();
  EXPECT_EQ(last.kind, LinkKind::final_stop);
  EXPECT_EQ(last.verdict, VerdictState::stop);
  EXPECT_EQ(last.reason, ReasonCode::no_frame);
  EXPECT_EQ(last.timestamp_ns, 9 * kMs);
}

TEST(UdpLinkSink, HeartbeatsOnTheSteadyClock) {
  // The real clock at 50 Hz: about 20 ms apart, within the sender's bounds.
  const Receiver receiver;
  SteadyClock clock;
  UdpLinkSink sink(params_for(receiver, 50.0), clock);
  std::vector<int64_t> arrivals;
  for (int k = 0; k < 6; ++k) {
    const LinkDatagram d = receiver.next_datagram(500);
    EXPECT_EQ(d.kind, LinkKind::heartbeat);
    arrivals.push_back(clock.now_ns());
  }
  for (size_t k = 1; k < arrivals.size(); ++k) {
    const int64_t gap_ns = arrivals[k] - arrivals[k - 1];
    EXPECT_GT(gap_ns, 5 * kMs) << k;     // not a burst
    EXPECT_LT(gap_ns, 200 * kMs) << k;   // generous for a loaded 2-core machine
  }
}

TEST(UdpLinkSink, JsonFormatSendsTheFramesLine) {
  const Receiver receiver;
  FakeClock clock(0);
  UdpLinkParams params = params_for(receiver);
  params.format = UdpLinkParams::Format::json;
  params.backend = "octree";  // proximity.backend, named when no search ran
  params.session = 4000000000U;  // above 2^31: written unsigned
  UdpLinkSink sink(params, clock);
  sink.header(RunHeader{});
  FrameResult frame = frame_at(3, 42 * kMs, true);
  frame.backend = nullptr;
  sink.frame(frame);
  // The line JSON Lines output writes for the same result.
  std::ostringstream expected_out;
  JsonLinesSink jsonl(expected_out, "octree");
  jsonl.frame(frame);
  std::string expected = expected_out.str();
  ASSERT_FALSE(expected.empty());
  expected.pop_back();  // the newline
  // ... with the session and `"for_control":false` as its second and third members.
  const std::string type_member = "{\"type\":\"frame\",";
  ASSERT_EQ(expected.rfind(type_member, 0), 0U) << expected;
  expected.insert(type_member.size(), "\"session\":4000000000,\"for_control\":false,");
  const std::optional<std::string> line = receiver.next();
  ASSERT_TRUE(line);
  EXPECT_EQ(*line, expected);
  EXPECT_EQ(nlohmann::json::parse(*line).at("type"), "frame");
  EXPECT_EQ(nlohmann::json::parse(*line).at("session").get<uint64_t>(), 4000000000U);
  EXPECT_EQ(nlohmann::json::parse(*line).at("backend"), "octree");
  EXPECT_EQ(nlohmann::json::parse(*line).at("for_control"), false) << "a line for logs, not for a controller";

  clock.advance(100 * kMs);
  const std::optional<std::string> heartbeat = receiver.next();
  ASSERT_TRUE(heartbeat);
  EXPECT_EQ(*heartbeat,
            "{\"type\":\"heartbeat\",\"session\":4000000000,\"for_control\":false,\"sequence\":1,"
            "\"timestamp_ns\":42000000,"
            "\"verdict\":\"stop\",\"reason_code\":\"no_frame\"}");
  RunSummary summary;
  summary.end_code = ReasonCode::stop_requested;
  sink.summary(summary);
  const std::optional<std::string> last = receiver.next();
  ASSERT_TRUE(last);
  EXPECT_EQ(*last,
            "{\"type\":\"final_stop\",\"session\":4000000000,\"for_control\":false,\"sequence\":2,"
            "\"timestamp_ns\":42000000,"
            "\"verdict\":\"stop\",\"reason_code\":\"stop_requested\"}");
}

TEST(UdpLinkSink, JsonFormatVerdictLinesSayTheyAreNotForControlToo) {
  // A watchdog's or the run's own stop (a `verdict` line: no source frame) as the third member
  // too, beside the frame lines, heartbeats and final stop of the test above.
  const Receiver receiver;
  FakeClock clock(0);
  UdpLinkParams params = params_for(receiver);
  params.format = UdpLinkParams::Format::json;
  params.session = 7;
  UdpLinkSink sink(params, clock);
  sink.header(RunHeader{});
  FrameResult stop = frame_at(0, 5 * kMs, false);
  stop.source_frame = false;
  stop.verdict.state = VerdictState::stop;
  stop.verdict.code = ReasonCode::no_frame;
  sink.frame(stop);
  const std::optional<std::string> line = receiver.next();
  ASSERT_TRUE(line);
  EXPECT_EQ(line->rfind("{\"type\":\"verdict\",\"session\":7,\"for_control\":false,", 0), 0U) << *line;
  EXPECT_EQ(nlohmann::json::parse(*line).at("for_control"), false);
}

TEST(UdpLinkSink, SendErrorsAreCountedNeverThrown) {
  // A port nobody listens on: loopback answers with ICMP port unreachable, which a connected
  // socket reports as ECONNREFUSED on a later send.
  uint16_t port = 0;
  {
    const Receiver probe;
    port = probe.port();
  }
  FakeClock clock(0);
  UdpLinkParams params;
  params.address = "127.0.0.1:" + std::to_string(port);
  UdpLinkSink sink(params, clock);
  for (int k = 0; k < 200 && sink.counters().send_errors == 0; ++k) {
    EXPECT_NO_THROW(sink.frame(frame_at(k, k, false)));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const UdpLinkCounters counters = sink.counters();
  EXPECT_GE(counters.send_errors, 1);
  EXPECT_NE(counters.last_error.find("link.udp.address '127.0.0.1:" + std::to_string(port) + "'"), std::string::npos)
      << counters.last_error;
}

TEST(UdpLinkSink, BadAddressNamesTheKey) {
  FakeClock clock(0);
  UdpLinkParams params;
  params.address = "robot.local:30020";
  try {
    UdpLinkSink sink(params, clock);
    ADD_FAILURE() << "accepted a host name";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("link.udp.address 'robot.local:30020': ", 0), 0U) << e.what();
  }
}

// ---- `hrcsense run` with the link on

TEST(UdpLinkCli, RunSendsOneDatagramPerVerdictLineThenAFinalStop) {
  const Receiver receiver;
  std::vector<std::string> datagrams;
  std::thread collect([&] {
    // Until the final stop, at most 2000 datagrams, at most 120 s of silence.
    for (int k = 0; k < 2000; ++k) {
      const std::optional<std::string> bytes = receiver.next(120000);
      if (!bytes) break;
      datagrams.push_back(*bytes);
      const LinkDecodeResult r = decode_link_datagram(reinterpret_cast<const uint8_t*>(bytes->data()), bytes->size());
      if (r.ok && r.datagram.kind == LinkKind::final_stop) break;
    }
  });
  const std::string out = std::string(::testing::TempDir()) + "udp_link_cli.jsonl";
  std::remove(out.c_str());
  const std::string command = std::string(HRCSENSE_CLI) + " run --set link.udp.address=" + receiver.address() +
                              " --frames 30 --out " + out + " 2>/dev/null";
  const int status = std::system(command.c_str());
  collect.join();
  EXPECT_EQ(status, 0) << command;

  // The lines the run wrote through its sinks, in order: frames and verdicts (watchdog and
  // end-of-run stops).
  std::vector<nlohmann::json> lines;
  nlohmann::json header;
  std::ifstream in(out);
  std::string text;
  while (std::getline(in, text)) {
    nlohmann::json j = nlohmann::json::parse(text);
    if (j.at("type") == "frame" || j.at("type") == "verdict") lines.push_back(j);
    if (j.at("type") == "header") header = j;
  }
  std::remove(out.c_str());
  int frame_lines = 0;
  for (const nlohmann::json& j : lines) frame_lines += j.at("type") == "frame" ? 1 : 0;
  EXPECT_EQ(frame_lines, 30);

  std::vector<LinkDatagram> frames;
  ASSERT_FALSE(datagrams.empty());
  for (size_t k = 0; k < datagrams.size(); ++k) {
    const LinkDecodeResult r =
        decode_link_datagram(reinterpret_cast<const uint8_t*>(datagrams[k].data()), datagrams[k].size());
    ASSERT_TRUE(r.ok) << k << ": " << r.error;
    EXPECT_EQ(r.datagram.sequence, k) << "+1 per datagram, from 0";
    // One session for the whole run, the one its JSON Lines header names.
    ASSERT_TRUE(header.contains("session") && header.at("session").is_number_unsigned()) << header.dump();
    EXPECT_EQ(r.datagram.session, header.at("session").get<uint32_t>()) << k;
    if (r.datagram.kind == LinkKind::frame) frames.push_back(r.datagram);
    if (r.datagram.kind == LinkKind::heartbeat) {
      EXPECT_EQ(r.datagram.verdict, VerdictState::stop);
    }
    if (k + 1 < datagrams.size()) {
      EXPECT_NE(r.datagram.kind, LinkKind::final_stop) << k;
    }
  }
  const LinkDecodeResult last =
      decode_link_datagram(reinterpret_cast<const uint8_t*>(datagrams.back().data()), datagrams.back().size());
  EXPECT_EQ(last.datagram.kind, LinkKind::final_stop);
  EXPECT_EQ(last.datagram.verdict, VerdictState::stop);
  EXPECT_EQ(static_cast<uint16_t>(last.datagram.reason), 18) << "frame_limit_reached";

  ASSERT_EQ(frames.size(), lines.size()) << "one frame datagram per frame or verdict line";
  for (size_t k = 0; k < frames.size(); ++k) {
    const nlohmann::json& line = lines[k];
    EXPECT_EQ(frames[k].timestamp_ns, line.at("host_time_ns").get<int64_t>()) << k;
    EXPECT_EQ(verdict_name(frames[k].verdict), line.at("verdict").get<std::string>()) << k;
    EXPECT_EQ(reason_code_name(frames[k].reason), line.at("reason_code").get<std::string>()) << k;
    EXPECT_FLOAT_EQ(frames[k].speed_scale, line.at("speed_scale").get<float>()) << k;
    EXPECT_EQ(std::isnan(frames[k].distance_m), line.at("distance_m").is_null()) << k;
  }
  EXPECT_EQ(lines.back().at("type"), "verdict") << "the run's own last stop";
}

}  // namespace
}  // namespace hrcsense
