// SPDX-License-Identifier: Apache-2.0
// udp_json: the datagram parser (good and malformed datagrams, messages worked out by hand) and
// the robot state source fed by a sender socket in this process over loopback, on a fake clock.
#include "hrcsense/net/udp_json.hpp"

#include "../support/loopback.hpp"
#include "../support/units.hpp"
#include "cli_cell.hpp"

#include "common/assembly.hpp"
#include "hrcsense/clock.hpp"
#include "hrcsense/config/config.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

namespace hrcsense {
namespace {

using test::kMs;
constexpr double kPi = 3.14159265358979323846;
constexpr int64_t kS = 1'000'000'000;

UdpJsonDatagram parse(const std::string& text) { return parse_udp_json_state(text.data(), text.size()); }

// ---- Parser

TEST(UdpJsonParse, GoodDatagram) {
  const UdpJsonDatagram d = parse(
      R"({"t_ns": 1000000000, "q": [0, -1.5708, 1.5708, -1.5708, -1.5708, 0.25],)"
      R"( "qd": [0.1, 0, 0, 0, 0, -0.5]})");
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_FALSE(d.non_finite);
  EXPECT_TRUE(d.error.empty());
  EXPECT_EQ(d.t_ns, 1'000'000'000);
  const JointAngles q{0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.25};
  const JointAngles qd{0.1, 0.0, 0.0, 0.0, 0.0, -0.5};
  EXPECT_EQ(d.q_rad, q);  // from_chars is correctly rounded: the same doubles as the literals
  EXPECT_EQ(d.qd_rad_s, qd);
}

// Any key order, any JSON whitespace, exponents and negative zero in the joints; t_ns 0 and 2^62.
TEST(UdpJsonParse, KeyOrderWhitespaceAndNumberForms) {
  UdpJsonDatagram d = parse("\r\n { \"qd\":[1e-3,-2E+1,0.5,-0,3,4] ,\t\"t_ns\":0,\n\"q\":[1,2,3,4,5,6.125] } \n");
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.t_ns, 0);
  EXPECT_EQ(d.q_rad, (JointAngles{1, 2, 3, 4, 5, 6.125}));
  EXPECT_EQ(d.qd_rad_s, (JointAngles{0.001, -20.0, 0.5, 0.0, 3, 4}));
  EXPECT_TRUE(std::signbit(d.qd_rad_s[3]));
  d = parse(R"({"t_ns":4611686018427387904,"q":[0,0,0,0,0,0],"qd":[0,0,0,0,0,0]})");
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.t_ns, int64_t{1} << 62);
}

// 1024 bytes is the limit: a good datagram padded with spaces to exactly 1024 passes, 1025 not.
TEST(UdpJsonParse, SizeLimit) {
  const std::string good = R"({"t_ns":5,"q":[0,0,0,0,0,0],"qd":[0,0,0,0,0,0]})";
  const std::string at_limit = good + std::string(1024 - good.size(), ' ');
  ASSERT_EQ(at_limit.size(), 1024U);
  EXPECT_TRUE(parse(at_limit).ok);
  const UdpJsonDatagram over = parse(at_limit + " ");
  EXPECT_FALSE(over.ok);
  EXPECT_EQ(over.error, "datagram of 1025 bytes: more than 1024");
  EXPECT_EQ(parse("").error, "empty datagram");
  EXPECT_EQ(parse_udp_json_state(nullptr, 0).error, "empty datagram");
}

struct Malformed {
  std::string datagram;
  std::string error;
};

// Each malformed datagram with its message; byte offsets counted by hand from 0.
TEST(UdpJsonParse, MalformedDatagramsNameTheField) {
  const std::string q6 = R"("q":[0,0,0,0,0,0])";
  const std::string qd6 = R"("qd":[0,0,0,0,0,0])";
  const Malformed cases[] = {
      {"[1,2]", R"(expected a JSON object {"t_ns": ..., "q": [...], "qd": [...]})"},
      {"hello", R"(expected a JSON object {"t_ns": ..., "q": [...], "qd": [...]})"},
      {R"({"t_ns":1,"q":[0,0,0,0,0],)" + qd6 + "}", "q: expected 6 numbers, got 5"},
      {R"({"t_ns":1,"q":[0,0,0,0,0,0,0],)" + qd6 + "}", "q: expected 6 numbers, got 7"},
      {R"({"t_ns":1,)" + q6 + R"(,"qd":[]})", "qd: expected 6 numbers, got 0"},
      {R"({"t_ns":1.5e9,)" + q6 + "," + qd6 + "}", "t_ns: expected an integer from 0 to 4611686018427387904, got 1.5e9"},
      {R"({"t_ns":1000.0,)" + q6 + "," + qd6 + "}", "t_ns: expected an integer from 0 to 4611686018427387904, got 1000.0"},
      {R"({"t_ns":-1,)" + q6 + "," + qd6 + "}", "t_ns: expected an integer from 0 to 4611686018427387904, got -1"},
      {R"({"t_ns":4611686018427387905,)" + q6 + "," + qd6 + "}",
       "t_ns: expected an integer from 0 to 4611686018427387904, got 4611686018427387905"},
      {R"({"t_ns":99999999999999999999,)" + q6 + "," + qd6 + "}",
       "t_ns: expected an integer from 0 to 4611686018427387904, got 99999999999999999999"},
      {R"({"t_ns":"12",)" + q6 + "," + qd6 + "}", "t_ns: expected an integer, got a string"},
      {R"({"t_ns":NaN,)" + q6 + "," + qd6 + "}", "t_ns: expected an integer, got an invalid token"},
      {R"({"t_ns":null,)" + q6 + "," + qd6 + "}", "t_ns: expected an integer, got null"},
      {R"({"t_ns":1,)" + q6 + "}", "missing key 'qd'"},
      {"{}", "missing key 't_ns'"},
      {R"({"t_ns":1,)" + q6 + "," + q6 + "," + qd6 + "}", "duplicate key 'q'"},
      {R"({"t_ns":1,"t_ns":2,)" + q6 + "," + qd6 + "}", "duplicate key 't_ns'"},
      {R"({"t_ns":1,"seq":7,)" + q6 + "," + qd6 + "}", "unknown key 'seq' (expected t_ns, q, qd, speed_fraction)"},
      {R"({"t_ns":1,)" + q6 + "," + qd6 + R"(,"speed_fraction":1.5})",
       "speed_fraction: expected a number from 0 to 1, got 1.5"},
      {R"({"t_ns":1,)" + q6 + "," + qd6 + R"(,"speed_fraction":-0.25})",
       "speed_fraction: expected a number from 0 to 1, got -0.25"},
      {R"({"t_ns":1,)" + q6 + "," + qd6 + R"(,"speed_fraction":"0.5"})", "speed_fraction: expected a number, got a string"},
      {R"({"t_ns":1,)" + q6 + "," + qd6 + R"(,"speed_fraction":NaN})",
       "speed_fraction: expected a number, got an invalid token"},
      {R"({"speed_fraction":1,"t_ns":1,)" + q6 + "," + qd6 + R"(,"speed_fraction":1})", "duplicate key 'speed_fraction'"},
      {R"({"t\u005fns":1,)" + q6 + "," + qd6 + "}",
       "key: escapes and control characters are not accepted in keys at byte 3"},
      {R"({"t_ns":1,"q":[0,0,"0",0,0,0],)" + qd6 + "}", "q[2]: expected a number, got a string"},
      {R"({"t_ns":1,"q":[null,0,0,0,0,0],)" + qd6 + "}", "q[0]: expected a number, got null"},
      {R"({"t_ns":1,"q":[0,[0],0,0,0,0],)" + qd6 + "}", "q[1]: expected a number, got an array"},
      {R"({"t_ns":1,)" + q6 + R"(,"qd":[0,0,0,0,0,true]})", "qd[5]: expected a number, got true"},
      {R"({"t_ns":1,"q":5,)" + qd6 + "}", "q: expected an array of 6 numbers, got a number"},
      {R"({"t_ns":1,"q":{},)" + qd6 + "}", "q: expected an array of 6 numbers, got an object"},
      {R"({"t_ns":1,"q":[1e999,0,0,0,0,0],)" + qd6 + "}", "q[0]: number out of range: 1e999"},
      {R"({"t_ns":1,"q":[.5,0,0,0,0,0],)" + qd6 + "}", "q[0]: expected a number, got an invalid token"},
      // {"t_ns":1,"q":[0 is bytes 0-15; the '1' of 01 at 16.
      {R"({"t_ns":1,"q":[01,0,0,0,0,0],)" + qd6 + "}", "q: expected ',' or ']' at byte 16"},
      // {"t_ns": 1, "q": [1,2 is 21 bytes: it ends at byte 21.
      {R"({"t_ns": 1, "q": [1,2)", "q: expected ',' or ']' at byte 21 (end of datagram)"},
      {"{", "expected a key (\"t_ns\", \"q\" or \"qd\") at byte 1 (end of datagram)"},
      {R"({"t_ns" 1})", "t_ns: expected ':' at byte 8"},
      {R"({"t_ns":1 "q":[]})", "after t_ns: expected ',' or '}' at byte 10"},
      {R"({"t_ns)", "unterminated key at byte 6 (end of datagram)"},
      // The object is 47 bytes (10 + 18 + 18 + 1, bytes 0-46); the garbage starts at 47, after a space at 48.
      {R"({"t_ns":5,"q":[0,0,0,0,0,0],"qd":[0,0,0,0,0,0]}x)", "trailing bytes after the object at byte 47"},
      {R"({"t_ns":5,"q":[0,0,0,0,0,0],"qd":[0,0,0,0,0,0]} {})", "trailing bytes after the object at byte 48"},
      {std::string("\x00\xff\x01", 3), R"(expected a JSON object {"t_ns": ..., "q": [...], "qd": [...]})"},
  };
  for (const Malformed& c : cases) {
    const UdpJsonDatagram d = parse(c.datagram);
    EXPECT_FALSE(d.ok) << c.datagram;
    EXPECT_FALSE(d.non_finite) << c.datagram;
    EXPECT_EQ(d.error, c.error) << c.datagram;
  }
}

// speed_fraction is optional: absent, the datagram's fraction is NaN (the monitor then takes the
// scale it sent last); present, the number as sent, 0 and 1 included.
TEST(UdpJsonParse, OptionalSpeedFraction) {
  const std::string joints = R"("q":[0,0,0,0,0,0],"qd":[0,0,0,0,0,0])";
  UdpJsonDatagram d = parse(R"({"t_ns":1,)" + joints + "}");
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_TRUE(std::isnan(d.speed_fraction));
  d = parse(R"({"speed_fraction": 0.25, "t_ns":1,)" + joints + "}");
  ASSERT_TRUE(d.ok) << d.error;
  EXPECT_EQ(d.speed_fraction, 0.25);
  EXPECT_EQ(parse(R"({"t_ns":1,)" + joints + R"(,"speed_fraction":0})").speed_fraction, 0.0);
  EXPECT_EQ(parse(R"({"t_ns":1,)" + joints + R"(,"speed_fraction":1})").speed_fraction, 1.0);
}

// Python's json.dumps writes NaN and Infinity: well-formed, but not a state. The values come
// through (the history rejects them as non-finite); the first non-finite field is named.
TEST(UdpJsonParse, NonFiniteJointsAreNamed) {
  const UdpJsonDatagram d = parse(R"({"t_ns":7,"q":[0,0,NaN,0,0,0],"qd":[0,-Infinity,0,0,0,Infinity]})");
  EXPECT_FALSE(d.ok);
  EXPECT_TRUE(d.non_finite);
  EXPECT_EQ(d.error, "q[2]: not a finite number");
  EXPECT_EQ(d.t_ns, 7);
  EXPECT_TRUE(std::isnan(d.q_rad[2]));
  EXPECT_EQ(d.qd_rad_s[1], -INFINITY);
  EXPECT_EQ(d.qd_rad_s[5], INFINITY);
  EXPECT_EQ(parse(R"({"t_ns":7,"q":[0,0,0,0,0,0],"qd":[0,0,0,0,0,-Infinity]})").error, "qd[5]: not a finite number");
}

// The fuzzer's seeds (fuzz/corpus/udp_json/) parse as their names say.
TEST(UdpJsonParse, FuzzSeedsParseAsNamed) {
  const auto read = [](const std::string& name) {
    std::ifstream file(std::string(HRCSENSE_SOURCE_DIR) + "/fuzz/corpus/udp_json/" + name, std::ios::binary);
    EXPECT_TRUE(file.good()) << name;
    return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  };
  EXPECT_TRUE(parse(read("good")).ok);
  EXPECT_TRUE(parse(read("reordered_keys")).ok);
  EXPECT_TRUE(parse(read("non_finite")).non_finite);
  EXPECT_EQ(parse(read("short_q")).error, "q: expected 6 numbers, got 5");
  EXPECT_EQ(parse(read("speed_fraction")).speed_fraction, 0.4);
}

// ---- The source, over loopback

// Waits, in real time, until `done` holds: at most 5 s and 5000 looks; false when it never did.
template <class Predicate>
bool wait_until(Predicate done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  for (int i = 0; i < 5000; ++i) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() > deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return done();
}

// A UDP socket on 127.0.0.1 (ephemeral port) that sends to the source's port.
class Sender {
 public:
  explicit Sender(uint16_t to_port) {
    to_.sin_family = AF_INET;
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to_.sin_port = htons(to_port);
  }
  void send(const std::string& bytes) const {
    const ssize_t sent =
        ::sendto(socket_.fd, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
    ASSERT_EQ(sent, static_cast<ssize_t>(bytes.size()));
  }
  uint16_t port() const { return socket_.port; }

 private:
  test::LoopbackUdpSocket socket_;
  sockaddr_in to_{};
};

UdpJsonParams loopback_params() {
  UdpJsonParams params;
  params.listen = "127.0.0.1:0";
  params.history.max_age_s = 0.05;
  return params;
}

// The test trajectory: sample i at i·8 ms on the sender's clock, which reads host − 1000 s
// (host 2000 s ↔ sender 1000 s). Joint 1 from 0.1 rad at +1 rad/s, joint 6 from −0.2 at −0.5 rad/s.
constexpr int64_t kHostStart = 2000 * kS;
constexpr int64_t kSenderStart = 1000 * kS;
constexpr int64_t kPeriod = 8 * kMs;

std::string trajectory_datagram(int i) {
  const double t_s = 0.008 * i;
  char text[256];
  std::snprintf(text, sizeof text, R"({"t_ns": %lld, "q": [%.17g, 0.5, 0, 0, 0, %.17g], "qd": [1, 0, 0, 0, 0, -0.5]})",
                static_cast<long long>(kSenderStart + i * kPeriod), 0.1 + 1.0 * t_s, -0.2 - 0.5 * t_s);
  return text;
}

// Sets the fake clock to the arrival time, sends, and waits until the source took the datagram
// (`counted` increments), so that the reader read exactly that arrival time.
template <class Counter>
void deliver(FakeClock& clock, int64_t arrival_ns, const Sender& sender, const std::string& datagram,
             UdpJsonRobotState& source, Counter counted) {
  clock.set(std::max(arrival_ns, clock.now_ns()));
  const int64_t before = counted(source.stats());
  sender.send(datagram);
  ASSERT_TRUE(wait_until([&] { return counted(source.stats()) > before; })) << datagram;
}

int64_t accepted(const RobotStateStats& s) { return s.samples.accepted; }
int64_t malformed(const RobotStateStats& s) { return s.malformed; }

// Arrival delays 0, 3, 1, 2, 0.5 ms: the first is the least delayed, so the clock map's offset
// stays host − sender = 1000 s and sample i lands at exactly 2000 s + i·8 ms on the host.
void send_trajectory(FakeClock& clock, const Sender& sender, UdpJsonRobotState& source) {
  const int64_t delay_us[] = {0, 3000, 1000, 2000, 500};
  for (int i = 0; i < 5; ++i) {
    deliver(clock, kHostStart + i * kPeriod + delay_us[i] * 1000, sender, trajectory_datagram(i), source, accepted);
  }
}

TEST(UdpJsonRobotState, StatesOnTheHostClockMatchTheSentTrajectory) {
  FakeClock clock(kHostStart - 5 * kMs);
  UdpJsonRobotState source(loopback_params(), clock);
  ASSERT_NE(source.bound_port(), 0);
  EXPECT_EQ(source.origin(), RobotStateOrigin::udp_json);
  RobotState state;
  EXPECT_FALSE(source.state_at(kHostStart, state));  // nothing received yet
  EXPECT_FALSE(state.valid);
  EXPECT_EQ(state.origin, RobotStateOrigin::udp_json);
  EXPECT_NE(source.error().find("no robot state accepted; no datagram received"), std::string::npos) << source.error();

  Sender sender(source.bound_port());
  send_trajectory(clock, sender, source);
  EXPECT_EQ(source.stats().samples.accepted, 5);
  EXPECT_EQ(source.stats().samples.rejected(), 0);
  EXPECT_EQ(source.stats().malformed, 0);

  // 12 ms: halfway between samples 1 (8 ms) and 2 (16 ms): joint 1 0.112, joint 6 −0.206.
  ASSERT_TRUE(source.state_at(kHostStart + 12 * kMs, state)) << source.error();
  EXPECT_TRUE(state.valid);
  EXPECT_EQ(state.origin, RobotStateOrigin::udp_json);
  EXPECT_EQ(state.host_time_ns, kHostStart + 12 * kMs);
  EXPECT_NEAR(state.q_rad[0], 0.112, 1e-9);
  EXPECT_NEAR(state.q_rad[1], 0.5, 1e-12);
  EXPECT_NEAR(state.q_rad[5], -0.206, 1e-9);
  EXPECT_NEAR(state.qd_rad_s[0], 1.0, 1e-12);
  EXPECT_NEAR(state.qd_rad_s[5], -0.5, 1e-12);
  // On sample 4 (32 ms, arrived 0.5 ms late): 0.132 and −0.216.
  ASSERT_TRUE(source.state_at(kHostStart + 32 * kMs, state));
  EXPECT_NEAR(state.q_rad[0], 0.132, 1e-9);
  EXPECT_NEAR(state.q_rad[5], -0.216, 1e-9);
  // 4 ms past the newest: moved on with qd, 0.136 and −0.218.
  ASSERT_TRUE(source.state_at(kHostStart + 36 * kMs, state));
  EXPECT_NEAR(state.q_rad[0], 0.136, 1e-9);
  EXPECT_NEAR(state.q_rad[5], -0.218, 1e-9);
}

// A sender that reports its speed fraction: samples 0-1 at 1, samples 2-3 at 0.4 (a slider set
// down). Each state carries the fraction of the sample in force at its time (it steps, it does
// not interpolate); a sender that stops reporting it leaves it unknown (NaN).
TEST(UdpJsonRobotState, StatesCarryTheSpeedFractionInForce) {
  FakeClock clock(kHostStart);
  UdpJsonRobotState source(loopback_params(), clock);
  Sender sender(source.bound_port());
  const double fractions[] = {1.0, 1.0, 0.4, 0.4};
  for (int i = 0; i < 5; ++i) {
    std::string datagram = trajectory_datagram(i);
    if (i < 4) datagram.insert(1, "\"speed_fraction\": " + std::to_string(fractions[i]) + ", ");
    deliver(clock, kHostStart + i * kPeriod, sender, datagram, source, accepted);
  }
  RobotState state;
  ASSERT_TRUE(source.state_at(kHostStart + 4 * kMs, state));
  EXPECT_EQ(state.speed_fraction, 1.0);
  ASSERT_TRUE(source.state_at(kHostStart + 12 * kMs, state));  // between samples 1 and 2: sample 1's
  EXPECT_EQ(state.speed_fraction, 1.0);
  ASSERT_TRUE(source.state_at(kHostStart + 20 * kMs, state));
  EXPECT_EQ(state.speed_fraction, 0.4);
  ASSERT_TRUE(source.state_at(kHostStart + 32 * kMs, state));  // sample 4 says nothing
  EXPECT_TRUE(std::isnan(state.speed_fraction));
}

// The sender stops after sample 4 (host 2000.032 s): 38 ms later the state is still valid, 51 ms
// later (past max_age_s 50 ms) it is stale, on the fake clock.
TEST(UdpJsonRobotState, SenderThatStopsIsStaleAfterMaxAge) {
  FakeClock clock(kHostStart);
  UdpJsonRobotState source(loopback_params(), clock);
  Sender sender(source.bound_port());
  send_trajectory(clock, sender, source);
  RobotState state;
  clock.set(kHostStart + 70 * kMs);
  EXPECT_TRUE(source.state_at(clock.now_ns(), state)) << source.error();
  EXPECT_TRUE(source.error().empty());
  clock.set(kHostStart + 83 * kMs);
  EXPECT_FALSE(source.state_at(clock.now_ns(), state));
  EXPECT_FALSE(state.valid);
  EXPECT_EQ(state.origin, RobotStateOrigin::udp_json);
  EXPECT_EQ(source.error(), "udp_json on 127.0.0.1:" + std::to_string(source.bound_port()) +
                                ": newest state 51.0 ms old (max 50.0 ms)");
}

// Garbage, a short q and an oversized datagram between good ones: counted, named with the
// sender's address, and the good states around them unchanged.
TEST(UdpJsonRobotState, MalformedDatagramsAreCountedAndDoNotDisturbGoodOnes) {
  FakeClock clock(kHostStart);
  UdpJsonRobotState source(loopback_params(), clock);
  Sender sender(source.bound_port());
  deliver(clock, kHostStart, sender, trajectory_datagram(0), source, accepted);
  deliver(clock, kHostStart + 1 * kMs, sender, "hello", source, malformed);
  deliver(clock, kHostStart + 2 * kMs, sender, std::string(2000, '{'), source, malformed);
  EXPECT_EQ(source.stats().last_problem,
            "from 127.0.0.1:" + std::to_string(sender.port()) + ": datagram of 2000 bytes: more than 1024");
  deliver(clock, kHostStart + 3 * kMs, sender,
          R"({"t_ns": 1000004000000, "q": [0, 0, 0, 0, 0], "qd": [0, 0, 0, 0, 0, 0]})", source, malformed);
  deliver(clock, kHostStart + kPeriod, sender, trajectory_datagram(1), source, accepted);
  const RobotStateStats stats = source.stats();
  EXPECT_EQ(stats.malformed, 3);
  EXPECT_EQ(stats.samples.accepted, 2);
  EXPECT_EQ(stats.samples.rejected(), 0);
  EXPECT_EQ(stats.last_problem, "from 127.0.0.1:" + std::to_string(sender.port()) + ": q: expected 6 numbers, got 5");
  RobotState state;
  ASSERT_TRUE(source.state_at(kHostStart + 4 * kMs, state));  // halfway: 0.104
  EXPECT_NEAR(state.q_rad[0], 0.104, 1e-9);

  // A burst, queued faster than the reader wakes: every datagram is read and counted.
  for (int i = 0; i < 64; ++i) sender.send("{\"t_ns\": 1}");
  EXPECT_TRUE(wait_until([&] { return source.stats().malformed == 3 + 64; })) << source.stats().malformed;
  EXPECT_EQ(source.stats().last_problem, "from 127.0.0.1:" + std::to_string(sender.port()) + ": missing key 'q'");
}

// A NaN joint (Python's json.dumps spelling) is counted by the history as non-finite, not as
// malformed, and the states on either side interpolate past it.
TEST(UdpJsonRobotState, NanJointsAreRejectedByTheHistory) {
  FakeClock clock(kHostStart);
  UdpJsonRobotState source(loopback_params(), clock);
  Sender sender(source.bound_port());
  const auto non_finite = [](const RobotStateStats& s) { return s.samples.rejected_non_finite; };
  deliver(clock, kHostStart, sender, trajectory_datagram(0), source, accepted);
  deliver(clock, kHostStart + kPeriod, sender,
          R"({"t_ns": 1000008000000, "q": [0.108, 0.5, NaN, 0, 0, -0.204], "qd": [1, 0, 0, 0, 0, -0.5]})", source,
          non_finite);
  deliver(clock, kHostStart + 2 * kPeriod, sender, trajectory_datagram(2), source, accepted);
  const RobotStateStats stats = source.stats();
  EXPECT_EQ(stats.samples.accepted, 2);
  EXPECT_EQ(stats.samples.rejected_non_finite, 1);
  EXPECT_EQ(stats.malformed, 0);
  EXPECT_EQ(stats.last_problem,
            "from 127.0.0.1:" + std::to_string(sender.port()) + ": t_ns 1000008000000 rejected: q[2]: not a finite number");
  RobotState state;
  ASSERT_TRUE(source.state_at(kHostStart + 8 * kMs, state));  // between samples 0 and 2: 0.108, joint 3 zero
  EXPECT_NEAR(state.q_rad[0], 0.108, 1e-9);
  EXPECT_EQ(state.q_rad[2], 0.0);
}

// A sender that sends degrees for radians (or garbage such as 1e300) sends no pose of a UR5,
// whose joints end at ±2π: each such datagram is rejected as outside the limits, counted apart,
// and named in last_problem (joint, value, limits); with no state accepted, error() says so and
// why, which a run puts on every stopped frame.
TEST(UdpJsonRobotState, JointsOutsideTheArmsLimitsAreRejectedAndNamed) {
  FakeClock clock(kHostStart);
  UdpJsonParams params = loopback_params();
  params.history.q_min_rad.fill(-2.0 * kPi);
  params.history.q_max_rad.fill(2.0 * kPi);
  UdpJsonRobotState source(params, clock);
  Sender sender(source.bound_port());
  const auto limits = [](const RobotStateStats& s) { return s.samples.rejected_limits; };
  deliver(clock, kHostStart, sender,
          R"({"t_ns": 1000000000000, "q": [-53.9, -85.9, 80.2, -97.4, -90, 0], "qd": [0, 0, 0, 0, 0, 0]})", source,
          limits);
  const std::string from = "from 127.0.0.1:" + std::to_string(sender.port()) + ": ";
  EXPECT_EQ(source.stats().last_problem,
            from + "t_ns 1000000000000 rejected: joint 1 (shoulder_pan) -53.9 rad outside the arm's limits "
                   "-6.283..6.283 rad");
  deliver(clock, kHostStart + kPeriod, sender,
          R"({"t_ns": 1000008000000, "q": [0, 0, 0, 0, 0, 1e300], "qd": [0, 0, 0, 0, 0, 0]})", source, limits);
  const RobotStateStats stats = source.stats();
  EXPECT_EQ(stats.samples.rejected_limits, 2);
  EXPECT_EQ(stats.samples.accepted, 0);
  EXPECT_EQ(stats.malformed, 0);
  EXPECT_NE(stats.last_problem.find("joint 6 (wrist_3) 1e+300 rad outside"), std::string::npos) << stats.last_problem;
  RobotState state;
  EXPECT_FALSE(source.state_at(kHostStart + kPeriod, state));
  EXPECT_EQ(source.error(), "udp_json on 127.0.0.1:" + std::to_string(source.bound_port()) +
                                ": no robot state accepted; last datagram problem: " + stats.last_problem);
  // The summary's last_problem keeps the latest: now the lookup's, which carries the datagram's.
  EXPECT_EQ(source.stats().last_problem, source.error());
  // Within the limits again: taken.
  deliver(clock, kHostStart + 2 * kPeriod, sender, trajectory_datagram(2), source, accepted);
  EXPECT_TRUE(source.state_at(kHostStart + 2 * kPeriod, state)) << source.error();
}

// Sample 1 overtaken by sample 2 arrives late: rejected as backwards, and the clock map is left
// alone, so sample 3 still lands at exactly 2000 s + 24 ms (a reset map would put it 3 ms late,
// at its arrival).
TEST(UdpJsonRobotState, ReorderedDatagramIsBackwardsAndLeavesTheClockMap) {
  FakeClock clock(kHostStart);
  UdpJsonRobotState source(loopback_params(), clock);
  Sender sender(source.bound_port());
  const auto backwards = [](const RobotStateStats& s) { return s.samples.rejected_backwards; };
  deliver(clock, kHostStart, sender, trajectory_datagram(0), source, accepted);
  deliver(clock, kHostStart + 2 * kPeriod + 1 * kMs, sender, trajectory_datagram(2), source, accepted);
  deliver(clock, kHostStart + 2 * kPeriod + 2 * kMs, sender, trajectory_datagram(1), source, backwards);
  deliver(clock, kHostStart + 3 * kPeriod + 3 * kMs, sender, trajectory_datagram(3), source, accepted);
  EXPECT_EQ(source.stats().samples.accepted, 3);
  EXPECT_EQ(source.stats().samples.rejected_backwards, 1);
  RobotState state;
  ASSERT_TRUE(source.state_at(kHostStart + 24 * kMs, state));
  EXPECT_NEAR(state.q_rad[0], 0.124, 1e-9);
  ASSERT_TRUE(source.state_at(kHostStart + 8 * kMs, state));  // between 0 and 2: 0.108
  EXPECT_NEAR(state.q_rad[0], 0.108, 1e-9);
}

// A socket bound to 127.0.0.1 on an ephemeral port, held by the test.
using HeldPort = test::LoopbackUdpSocket;

// `Error`: std::runtime_error for what only the machine decides (bind), std::invalid_argument
// for an address that is no numeric host:port (the configuration's error, exit 2).
template <class Error>
void expect_error(const UdpJsonParams& params, const std::string& message) {
  FakeClock clock;
  try {
    UdpJsonRobotState source(params, clock);
    ADD_FAILURE() << "no error for " << params.listen;
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
}

TEST(UdpJsonRobotState, BindFailureAndBadAddressesNameTheAddress) {
  const HeldPort held;
  UdpJsonParams params;
  params.listen = "127.0.0.1:" + std::to_string(held.port);
  expect_error<std::runtime_error>(params, "udp_json: robot.state.listen '" + params.listen +
                                               "': cannot bind: Address already in use");
  params.listen = "localhost:30010";
  expect_error<std::invalid_argument>(params, "udp_json: robot.state.listen 'localhost:30010': expected a numeric "
                                              "IPv4 address a.b.c.d:port or [IPv6]:port");
  params.listen = "127.0.0.1:65536";
  expect_error<std::invalid_argument>(params, "udp_json: robot.state.listen '127.0.0.1:65536': expected host:port "
                                              "with a port from 0 to 65535");
  params.listen = "[::1x]:5";
  expect_error<std::invalid_argument>(params, "udp_json: robot.state.listen '[::1x]:5': not a numeric IPv6 address");
}

// Destruction wakes the reader: it takes far less than its 200 ms poll timeout (bounded at 1 s
// here so that a loaded machine does not fail the test).
TEST(UdpJsonRobotState, DestructorEndsTheReaderPromptly) {
  FakeClock clock;
  auto source = std::make_unique<UdpJsonRobotState>(loopback_params(), clock);
  const auto start = std::chrono::steady_clock::now();
  source.reset();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
}

// robot.state.source udp_json: the assembly binds robot.state.listen (a port the test holds: the
// bind fails naming it), with the history's max_age_s from the configuration, on the steady clock.
TEST(UdpJsonAssembly, BuildsTheSourceFromTheConfiguration) {
  uint16_t port = 0;
  {
    const HeldPort held;
    port = held.port;
    const std::string listen = "127.0.0.1:" + std::to_string(port);
    const Config config = load_config("", {"robot.state.source=udp_json", "robot.state.listen=" + listen});
    try {
      (void)make_robot_state_source(config);
      ADD_FAILURE() << "bound a held port";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()),
                "udp_json: robot.state.listen '" + listen + "': cannot bind: Address already in use");
    }
  }
  // A host name is the configuration's error (exit 2, naming the file and the key), as it is
  // for link.udp.address (issue R2, defect 6): no name is looked up at start-up.
  const Config named = load_config("", {"robot.state.source=udp_json", "robot.state.listen=localhost:30010"});
  try {
    (void)make_robot_state_source(named);
    ADD_FAILURE() << "took a host name";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "configuration: udp_json: robot.state.listen 'localhost:30010': expected a "
                                     "numeric IPv4 address a.b.c.d:port or [IPv6]:port");
  }
  // The port is free again. One datagram stamped with the steady clock: it lands between t0
  // (before sending) and t1 (once taken). At t0 + 150 ms its age is at most 150 ms: valid with
  // max_age_s 0.2 (stale with the default 0.05); at t1 + 201 ms it is at least 201 ms old: stale.
  const Config config = load_config("", {"robot.state.source=udp_json",
                                         "robot.state.listen=127.0.0.1:" + std::to_string(port),
                                         "robot.state.max_age_s=0.2"});
  const std::unique_ptr<RobotStateSource> source = make_robot_state_source(config);
  EXPECT_EQ(source->origin(), RobotStateOrigin::udp_json);
  const SteadyClock steady;
  const int64_t t0 = steady.now_ns();
  Sender(port).send("{\"t_ns\": " + std::to_string(t0) + ", \"q\": [1, 2, 3, 4, 5, 6], \"qd\": [0, 0, 0, 0, 0, 0]}");
  ASSERT_TRUE(wait_until([&] { return source->stats().samples.accepted == 1; }));
  const int64_t t1 = steady.now_ns();
  RobotState state;
  ASSERT_TRUE(source->state_at(t0 + 150 * kMs, state)) << source->error();
  EXPECT_EQ(state.q_rad, (JointAngles{1, 2, 3, 4, 5, 6}));
  EXPECT_FALSE(source->state_at(t1 + 201 * kMs, state));
}

// `hrcsense run` with `robot.state.source: udp_json`, end to end: the tool runs as a child and
// binds robot.state.listen (a port this test found free); this process sends the cell's joints
// at 250 Hz, stamped with its own steady clock (the sender's clock, which the tool maps to its
// own), until the run has written 30 frames, and then falls silent. While it sends, every
// contact is the fixed run's (tests/net/cli_cell.hpp); after it stops, the frames are `stop`.
TEST(UdpJsonCli, RunFollowsTheSenderAndStopsWhenItFallsSilent) {
  const std::string config = test::write_cli_cell("udp_json");
  const test::ToolRun fixed = test::run_tool(config, "--set source.pace=false", "udp_fixed");

  uint16_t port = 0;
  {
    const HeldPort probe;  // free now; the tool binds it a moment later
    port = probe.port;
  }
  const std::string out = test::cli_out_path("udp");
  std::thread sender([&] {
    const Sender to(port);
    const SteadyClock steady;
    std::string q;
    for (size_t j = 0; j < 6; ++j) q += (j ? ", " : "") + std::to_string(test::kCliJoints[j]);
    // 250 Hz until the run has written kSilentAfterFrames frames (bounded: 10 s); datagrams
    // sent before the tool has bound the port are lost.
    for (int k = 0; k < 2500 && test::frames_written(out) < test::kSilentAfterFrames; ++k) {
      to.send("{\"t_ns\": " + std::to_string(steady.now_ns()) + ", \"q\": [" + q + "], \"qd\": [0, 0, 0, 0, 0, 0]}");
      std::this_thread::sleep_for(std::chrono::milliseconds(4));
    }
  });
  const test::ToolRun live = test::run_tool(
      config, "--set robot.state.source=udp_json --set robot.state.listen=127.0.0.1:" + std::to_string(port), "udp");
  sender.join();
  std::remove(config.c_str());

  EXPECT_EQ(live.header.at("robot_state"), "udp_json");
  const nlohmann::json& robot = live.summary.at("robot_state");
  EXPECT_GE(robot.at("accepted").get<int64_t>(), test::kSilentAfterFrames);  // 250 Hz against 30 fps
  EXPECT_EQ(robot.at("malformed"), 0);
  test::expect_follows_then_stops(live, fixed);
}

// A sender that sends the cell's joints in degrees, end to end: the run takes the UR5's limits
// from robot.model, rejects every datagram (shoulder_pan −53.9 is no pose of it), never
// measures a frame against them, and says why on the frames and in the summary.
TEST(UdpJsonCli, JointsInDegreesAreRejectedAndEveryFrameStops) {
  const std::string config = test::write_cli_cell("udp_json_degrees");
  uint16_t port = 0;
  {
    const HeldPort probe;  // free now; the tool binds it a moment later
    port = probe.port;
  }
  std::atomic<bool> done{false};
  std::thread sender([&] {
    const Sender to(port);
    const SteadyClock steady;
    std::string q;
    for (size_t j = 0; j < 6; ++j) q += (j ? ", " : "") + std::to_string(test::kCliJoints[j] * 180.0 / kPi);
    for (int k = 0; k < 2500 && !done; ++k) {  // 250 Hz for the run, at most 10 s
      to.send("{\"t_ns\": " + std::to_string(steady.now_ns()) + ", \"q\": [" + q + "], \"qd\": [0, 0, 0, 0, 0, 0]}");
      std::this_thread::sleep_for(std::chrono::milliseconds(4));
    }
  });
  const test::ToolRun live = test::run_tool(
      config, "--set robot.state.source=udp_json --set robot.state.listen=127.0.0.1:" + std::to_string(port),
      "udp_degrees");
  done = true;
  sender.join();
  std::remove(config.c_str());

  const nlohmann::json& robot = live.summary.at("robot_state");
  EXPECT_EQ(robot.at("accepted"), 0);
  EXPECT_GE(robot.at("rejected_limits").get<int64_t>(), 30);  // 250 Hz over a 2.5 s run
  EXPECT_EQ(robot.at("malformed"), 0);
  EXPECT_NE(robot.at("last_problem").get<std::string>().find("joint 1 (shoulder_pan) -53.9"), std::string::npos)
      << robot.at("last_problem");
  ASSERT_FALSE(live.frames.empty());
  int named = 0;
  for (const auto& [index, frame] : live.frames) {
    EXPECT_EQ(frame.at("verdict"), "stop") << index;
    EXPECT_FALSE(frame.at("valid").get<bool>()) << index;
    const std::string reason = frame.at("verdict_reason").get<std::string>();
    if (frame.at("reason_code") == "no_robot_state" && reason.find("outside the arm's limits") != std::string::npos) {
      ++named;
    }
  }
  EXPECT_GE(named, 30) << "the stopped frames should say why there is no state";
}

}  // namespace
}  // namespace hrcsense
