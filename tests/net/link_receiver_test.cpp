// SPDX-License-Identifier: Apache-2.0
// The reference receiver (LinkReceiver, issue 30 item 4): session, sequence and the timeout
// counted from the last taken datagram, on datagrams laid out by hand from docs/SAFETY.md's
// version 2 table (with a CRC-32 computed bit by bit here, not by the library); then the example
// program, and a kill -9 and restart of the real `hrcsense run` on loopback (127.0.0.1,
// ephemeral ports, every wait bounded).
#include "hrcsense/net/link_receiver.hpp"

#include "../support/child_process.hpp"
#include "../support/loopback.hpp"
#include "../support/units.hpp"

#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace hrcsense {
namespace {

using test::kMs;
constexpr uint32_t kDead = 0x0BADF00DU;   // the session of the process that dies
constexpr uint32_t kReborn = 0x600DCAFEU; // the session of its restart

// ---- Datagrams by hand (docs/SAFETY.md, "The binary datagram", version 2)

uint32_t bitwise_crc32(const std::vector<uint8_t>& bytes, size_t size) {
  uint32_t crc = 0xFFFFFFFFU;
  for (size_t i = 0; i < size; ++i) {
    crc ^= bytes[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1U) != 0 ? (crc >> 1) ^ 0xEDB88320U : crc >> 1;
  }
  return ~crc;
}

void put(std::vector<uint8_t>& bytes, size_t at, uint64_t value, int size) {
  for (int i = 0; i < size; ++i) bytes[at + static_cast<size_t>(i)] = static_cast<uint8_t>(value >> (8 * i));
}

uint32_t bits(float value) {
  uint32_t b = 0;
  std::memcpy(&b, &value, sizeof b);
  return b;
}

/// One datagram: kind 1 frame, 2 heartbeat, 3 final stop; verdict 0 run, 1 slow, 2 stop;
/// reason by number (docs/OUTPUT.md: 1 no_foreground, 2 in_slow_zone, 3 in_stop_zone, 16
/// no_frame, 19 stop_requested).
std::vector<uint8_t> datagram(uint16_t kind, uint32_t session, uint32_t sequence, uint8_t verdict, uint16_t reason,
                              float scale) {
  std::vector<uint8_t> b(45, 0);
  b[0] = 'H';
  b[1] = 'R';
  b[2] = 'C';
  b[3] = 'S';
  put(b, 4, 2, 2);                       // version
  put(b, 6, kind, 2);
  put(b, 8, sequence, 4);
  put(b, 12, 1'000'000'000ULL + sequence, 8);  // timestamp_ns
  b[20] = verdict;
  put(b, 21, reason, 2);
  put(b, 23, bits(scale), 4);
  put(b, 27, 0x7FC00000U, 4);            // distance: NaN, no contact
  put(b, 31, bits(0.5F), 4);             // protective distance
  put(b, 35, 3, 2);                      // robot state age, ms
  put(b, 37, session, 4);
  put(b, 41, bitwise_crc32(b, 41), 4);
  return b;
}
std::vector<uint8_t> run_frame(uint32_t session, uint32_t sequence) { return datagram(1, session, sequence, 0, 1, 1.0F); }
std::vector<uint8_t> slow_frame(uint32_t session, uint32_t sequence) { return datagram(1, session, sequence, 1, 2, 0.25F); }
std::vector<uint8_t> stop_frame(uint32_t session, uint32_t sequence) { return datagram(1, session, sequence, 2, 3, 0.0F); }
std::vector<uint8_t> heartbeat(uint32_t session, uint32_t sequence) { return datagram(2, session, sequence, 2, 16, 0.0F); }
std::vector<uint8_t> final_stop(uint32_t session, uint32_t sequence) { return datagram(3, session, sequence, 2, 19, 0.0F); }

LinkTake feed(LinkReceiver& receiver, const std::vector<uint8_t>& bytes, int64_t arrival_ns) {
  return receiver.take_bytes(bytes.data(), bytes.size(), arrival_ns);
}

LinkReceiver receiver_ms(int64_t timeout_ms) {
  LinkReceiverParams params;
  params.timeout_ns = timeout_ms * kMs;
  return LinkReceiver(params);
}

// ---- LinkReceiver on hand-built datagrams

TEST(LinkReceiver, NothingTakenIsStop) {
  const LinkReceiver receiver;
  const LinkReceiverVerdict v = receiver.verdict(5 * kMs);
  EXPECT_EQ(v.state, VerdictState::stop);
  EXPECT_EQ(v.speed_scale, 0.0F);
  EXPECT_EQ(v.basis, LinkVerdictBasis::nothing_taken);
  EXPECT_EQ(v.session, 0U);
  EXPECT_EQ(v.age_ns, -1);
  EXPECT_EQ(receiver.session(), 0U);
}

TEST(LinkReceiver, FollowsOneSessionFrameByFrame) {
  LinkReceiver receiver = receiver_ms(200);
  EXPECT_EQ(feed(receiver, run_frame(kDead, 7), 0), LinkTake::first_session) << "any first sequence";
  EXPECT_EQ(receiver.session(), kDead);
  LinkReceiverVerdict v = receiver.verdict(10 * kMs);
  EXPECT_EQ(v.state, VerdictState::run);
  EXPECT_EQ(v.speed_scale, 1.0F);
  EXPECT_EQ(v.basis, LinkVerdictBasis::frame);
  EXPECT_EQ(v.reason, ReasonCode::no_foreground);
  EXPECT_EQ(v.session, kDead);
  EXPECT_EQ(v.sequence, 7U);
  EXPECT_EQ(v.age_ns, 10 * kMs);

  EXPECT_EQ(feed(receiver, slow_frame(kDead, 8), 33 * kMs), LinkTake::taken);
  v = receiver.verdict(40 * kMs);
  EXPECT_EQ(v.state, VerdictState::slow);
  EXPECT_EQ(v.speed_scale, 0.25F);
  EXPECT_EQ(v.reason, ReasonCode::in_slow_zone);

  EXPECT_EQ(feed(receiver, stop_frame(kDead, 10), 66 * kMs), LinkTake::taken) << "a gap is a lost datagram";
  v = receiver.verdict(70 * kMs);
  EXPECT_EQ(v.state, VerdictState::stop);
  EXPECT_EQ(v.speed_scale, 0.0F);
  EXPECT_EQ(v.reason, ReasonCode::in_stop_zone);

  EXPECT_EQ(feed(receiver, run_frame(kDead, 11), 99 * kMs), LinkTake::taken);
  EXPECT_EQ(feed(receiver, heartbeat(kDead, 12), 149 * kMs), LinkTake::taken);
  v = receiver.verdict(150 * kMs);
  EXPECT_EQ(v.state, VerdictState::stop) << "a heartbeat is alive but says stop";
  EXPECT_EQ(v.basis, LinkVerdictBasis::heartbeat);
  EXPECT_EQ(v.reason, ReasonCode::no_frame);

  const LinkReceiverCounters& c = receiver.counters();
  EXPECT_EQ(c.taken, 5);
  EXPECT_EQ(c.sessions, 1);
  EXPECT_EQ(c.new_sessions, 0);
  EXPECT_EQ(c.old_sequence + c.malformed + c.after_final_stop + c.retired_session, 0);
}

// The issue's case: the process that said `run` is killed, a new one starts 46 ms later at
// sequence 0. Keyed on the sequence alone, 0 is "not newer" than 99 and the dead run stays.
TEST(LinkReceiver, RestartWithANewSessionDoesNotKeepTheDeadRun) {
  LinkReceiver receiver = receiver_ms(200);
  int64_t t = 0;
  for (uint32_t k = 0; k < 100; ++k, t += 33 * kMs) ASSERT_TRUE(link_taken(feed(receiver, run_frame(kDead, k), t)));
  const int64_t killed = t;
  EXPECT_EQ(receiver.verdict(killed).state, VerdictState::run);
  // The restart's first datagram: a heartbeat (it is still starting), sequence 0.
  EXPECT_EQ(feed(receiver, heartbeat(kReborn, 0), killed + 46 * kMs), LinkTake::new_session);
  LinkReceiverVerdict v = receiver.verdict(killed + 46 * kMs);
  EXPECT_EQ(v.state, VerdictState::stop) << "the dead process's run ends with the new session's first datagram";
  EXPECT_EQ(v.session, kReborn);
  EXPECT_EQ(v.sequence, 0U);
  EXPECT_EQ(receiver.session(), kReborn);
  // A late datagram of the dead process (queued, reordered) cannot bring its run back.
  EXPECT_EQ(feed(receiver, run_frame(kDead, 100), killed + 50 * kMs), LinkTake::retired_session);
  EXPECT_EQ(receiver.verdict(killed + 50 * kMs).state, VerdictState::stop);
  EXPECT_EQ(receiver.verdict(killed + 50 * kMs).session, kReborn);
  // The new process follows from its own count.
  EXPECT_EQ(feed(receiver, heartbeat(kReborn, 1), killed + 96 * kMs), LinkTake::taken);
  EXPECT_EQ(feed(receiver, run_frame(kReborn, 2), killed + 500 * kMs), LinkTake::taken);
  EXPECT_EQ(receiver.verdict(killed + 510 * kMs).state, VerdictState::run);
  EXPECT_EQ(receiver.verdict(killed + 510 * kMs).session, kReborn);
  const LinkReceiverCounters& c = receiver.counters();
  EXPECT_EQ(c.sessions, 2);
  EXPECT_EQ(c.new_sessions, 1);
  EXPECT_EQ(c.retired_session, 1);
  EXPECT_EQ(c.taken, 103);
}

TEST(LinkReceiver, ANewSessionStartingAtZeroIsTakenEvenAfterADeadRunAndBeforeItsTimeout) {
  LinkReceiver receiver = receiver_ms(200);
  ASSERT_EQ(feed(receiver, run_frame(kDead, 5000), 0), LinkTake::first_session);
  // Sequence 0 of another session, straight away: a restart whose first frame already says run.
  EXPECT_EQ(feed(receiver, run_frame(kReborn, 0), 10 * kMs), LinkTake::new_session);
  const LinkReceiverVerdict v = receiver.verdict(20 * kMs);
  EXPECT_EQ(v.state, VerdictState::run);
  EXPECT_EQ(v.session, kReborn);
  EXPECT_EQ(v.sequence, 0U);
  EXPECT_EQ(v.age_ns, 10 * kMs);
  // Its sequence, not the old session's 5000, is what later datagrams are compared with.
  EXPECT_EQ(feed(receiver, slow_frame(kReborn, 1), 30 * kMs), LinkTake::taken);
  EXPECT_EQ(feed(receiver, run_frame(kReborn, 1), 31 * kMs), LinkTake::old_sequence);
}

TEST(LinkReceiver, ReplaysDuplicatesAndReorderedDatagramsAreRejected) {
  LinkReceiver receiver = receiver_ms(200);
  ASSERT_TRUE(link_taken(feed(receiver, run_frame(kDead, 10), 0)));
  ASSERT_TRUE(link_taken(feed(receiver, stop_frame(kDead, 11), 1 * kMs)));
  // A duplicate of the stop and a late copy of the earlier run: neither is taken, the stop stays.
  EXPECT_EQ(feed(receiver, stop_frame(kDead, 11), 2 * kMs), LinkTake::old_sequence);
  EXPECT_EQ(feed(receiver, run_frame(kDead, 10), 3 * kMs), LinkTake::old_sequence);
  EXPECT_EQ(feed(receiver, run_frame(kDead, 3), 4 * kMs), LinkTake::old_sequence);
  LinkReceiverVerdict v = receiver.verdict(5 * kMs);
  EXPECT_EQ(v.state, VerdictState::stop);
  EXPECT_EQ(v.sequence, 11U);
  EXPECT_EQ(v.age_ns, 4 * kMs) << "rejected datagrams do not refresh the last taken one";
  EXPECT_EQ(receiver.counters().old_sequence, 3);
  // Half the sequence space back counts as older, too ((int32_t)(seq - last) <= 0).
  EXPECT_EQ(feed(receiver, run_frame(kDead, 11 + 0x80000000U), 6 * kMs), LinkTake::old_sequence);

  // Wrap-around: 0xFFFFFFFF, then 0, 1 are newer.
  LinkReceiver wrapping = receiver_ms(200);
  ASSERT_TRUE(link_taken(feed(wrapping, stop_frame(kDead, 0xFFFFFFFEU), 0)));
  EXPECT_EQ(feed(wrapping, stop_frame(kDead, 0xFFFFFFFFU), 1 * kMs), LinkTake::taken);
  EXPECT_EQ(feed(wrapping, run_frame(kDead, 0), 2 * kMs), LinkTake::taken);
  EXPECT_EQ(feed(wrapping, stop_frame(kDead, 0xFFFFFFFFU), 3 * kMs), LinkTake::old_sequence);
  EXPECT_EQ(wrapping.verdict(4 * kMs).state, VerdictState::run);
}

TEST(LinkReceiver, NothingOfASessionIsTakenAfterItsFinalStop) {
  LinkReceiver receiver = receiver_ms(200);
  ASSERT_TRUE(link_taken(feed(receiver, run_frame(kDead, 1), 0)));
  EXPECT_EQ(feed(receiver, final_stop(kDead, 2), 1 * kMs), LinkTake::taken);
  LinkReceiverVerdict v = receiver.verdict(2 * kMs);
  EXPECT_EQ(v.state, VerdictState::stop);
  EXPECT_EQ(v.basis, LinkVerdictBasis::final_stop);
  EXPECT_EQ(v.reason, ReasonCode::stop_requested);
  // Newer by sequence, but the sender said nothing follows: a replay or a forgery.
  EXPECT_EQ(feed(receiver, run_frame(kDead, 3), 3 * kMs), LinkTake::after_final_stop);
  EXPECT_EQ(receiver.verdict(4 * kMs).state, VerdictState::stop);
  EXPECT_EQ(receiver.counters().after_final_stop, 1);
  // The next start is a new session and is followed.
  EXPECT_EQ(feed(receiver, run_frame(kReborn, 0), 500 * kMs), LinkTake::new_session);
  EXPECT_EQ(receiver.verdict(501 * kMs).state, VerdictState::run);
}

TEST(LinkReceiver, TimeoutCountsFromTheLastTakenDatagram) {
  LinkReceiver receiver = receiver_ms(100);
  ASSERT_TRUE(link_taken(feed(receiver, run_frame(kDead, 1), 1000 * kMs)));
  EXPECT_EQ(receiver.verdict(1099 * kMs).state, VerdictState::run);
  EXPECT_EQ(receiver.verdict(1099 * kMs).age_ns, 99 * kMs);
  LinkReceiverVerdict v = receiver.verdict(1100 * kMs);
  EXPECT_EQ(v.state, VerdictState::stop) << "100 ms after the last taken datagram";
  EXPECT_EQ(v.speed_scale, 0.0F);
  EXPECT_EQ(v.basis, LinkVerdictBasis::timed_out);
  EXPECT_EQ(v.reason, ReasonCode::no_frame);
  EXPECT_EQ(v.session, kDead);

  // Datagrams that decode but are not taken keep nothing alive (the issue's 4.2 s came from
  // a receiver that counted them).
  LinkReceiver replayed = receiver_ms(100);
  ASSERT_TRUE(link_taken(feed(replayed, run_frame(kDead, 50), 0)));
  for (int64_t t = 10; t <= 300; t += 10) {
    EXPECT_EQ(feed(replayed, run_frame(kDead, 50), t * kMs), LinkTake::old_sequence);
    const LinkReceiverVerdict at = replayed.verdict(t * kMs);
    EXPECT_EQ(at.state, t < 100 ? VerdictState::run : VerdictState::stop) << t << " ms";
  }
  // Neither do malformed bytes.
  std::vector<uint8_t> damaged = run_frame(kDead, 51);
  damaged[30] ^= 0x01;
  EXPECT_EQ(feed(replayed, damaged, 310 * kMs), LinkTake::malformed);
  EXPECT_EQ(replayed.verdict(310 * kMs).basis, LinkVerdictBasis::timed_out);

  // A verdict asked for before the last arrival (two clocks mixed up) reads as age 0.
  EXPECT_EQ(receiver.verdict(900 * kMs).age_ns, 0);
  EXPECT_THROW(receiver_ms(0), std::invalid_argument);
}

TEST(LinkReceiver, MalformedBytesAndVersionOneAreCountedNotTaken) {
  LinkReceiver receiver = receiver_ms(200);
  std::vector<uint8_t> version1 = run_frame(kDead, 1);
  version1.resize(41);
  version1[4] = 1;
  put(version1, 37, bitwise_crc32(version1, 37), 4);
  EXPECT_EQ(feed(receiver, version1, 0), LinkTake::malformed);
  EXPECT_EQ(feed(receiver, datagram(1, 0, 1, 0, 1, 1.0F), 1 * kMs), LinkTake::malformed) << "session 0";
  EXPECT_EQ(receiver.take_bytes(nullptr, 0, 2 * kMs), LinkTake::malformed);
  EXPECT_EQ(receiver.counters().malformed, 3);
  EXPECT_EQ(receiver.counters().taken, 0);
  EXPECT_EQ(receiver.verdict(3 * kMs).basis, LinkVerdictBasis::nothing_taken);
  // take() on a value with session 0 (not from the decoder) is refused the same way.
  LinkDatagram no_session;
  no_session.verdict = VerdictState::run;
  no_session.speed_scale = 1.0F;
  EXPECT_EQ(receiver.take(no_session, 4 * kMs), LinkTake::malformed);
}

TEST(LinkReceiver, RemembersTheLastSixteenSessionsItLeft) {
  LinkReceiver receiver = receiver_ms(200);
  // Sessions 1..18 one after the other: 1..17 are retired, the ring keeps the last 16 (2..17).
  for (uint32_t s = 1; s <= 18; ++s) {
    ASSERT_TRUE(link_taken(feed(receiver, run_frame(s, 0), s * kMs))) << s;
  }
  EXPECT_EQ(feed(receiver, run_frame(17, 1), 20 * kMs), LinkTake::retired_session);
  EXPECT_EQ(feed(receiver, run_frame(2, 1), 21 * kMs), LinkTake::retired_session);
  // Session 1 left 17 restarts ago and is forgotten: it would be taken as a new one.
  EXPECT_EQ(feed(receiver, run_frame(1, 1), 22 * kMs), LinkTake::new_session);
  EXPECT_EQ(receiver.counters().sessions, 19);
  EXPECT_EQ(receiver.counters().retired_session, 2);
}

// ---- A child process with its standard output on a pipe, killed if still running at the end

using Child = test::ChildProcess;

/// Sends `bytes` to 127.0.0.1:port.
void send_to(uint16_t port, const std::vector<uint8_t>& bytes) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  to.sin_port = htons(port);
  EXPECT_EQ(::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to),
            static_cast<ssize_t>(bytes.size()));
  ::close(fd);
}

// ---- The example program

TEST(LinkReceiverExample, PrintsTheVerdictPerDatagramAndTheTimeout) {
  // A timeout of 1 s: long enough that the lines below arrive well within it on a loaded machine.
  Child example({HRCSENSE_LINK_RECEIVER, "--port", "0", "--timeout-ms", "1000", "--datagrams", "4"});
  std::string line;
  ASSERT_TRUE(example.read_line(line, 10.0));
  unsigned port = 0;
  ASSERT_EQ(std::sscanf(line.c_str(), "listening on 127.0.0.1:%u", &port), 1) << line;
  ASSERT_GT(port, 0U);
  const auto port16 = static_cast<uint16_t>(port);
  send_to(port16, run_frame(kDead, 4));
  ASSERT_TRUE(example.read_line(line, 10.0));
  EXPECT_EQ(line, "session 195948557 sequence 4 frame first_session: run 1 (frame, reason no_foreground)");
  send_to(port16, run_frame(kDead, 4));
  ASSERT_TRUE(example.read_line(line, 10.0));
  EXPECT_EQ(line, "session 195948557 sequence 4 frame old_sequence: run 1 (frame, reason no_foreground)");
  // Silence: the timeout turns the verdict to stop and is reported (1 s; wait up to 10 s).
  ASSERT_TRUE(example.read_line(line, 10.0));
  EXPECT_EQ(line, "nothing taken for 1000 ms: stop 0 (timed_out, reason no_frame)");
  send_to(port16, heartbeat(kReborn, 0));
  ASSERT_TRUE(example.read_line(line, 10.0));
  EXPECT_EQ(line, "session 1611516670 sequence 0 heartbeat new_session: stop 0 (heartbeat, reason no_frame)");
  send_to(port16, {0x48, 0x52});
  ASSERT_TRUE(example.read_line(line, 10.0));
  EXPECT_EQ(line.rfind("malformed (size: expected 45 bytes, got 2): stop 0 (", 0), 0U) << line;
  EXPECT_EQ(example.stop(0, 10.0), 0) << "ends by itself after --datagrams 4";
}

TEST(LinkReceiverExample, RefusesBadArguments) {
  Child example({HRCSENSE_LINK_RECEIVER, "--port", "70000"});
  EXPECT_EQ(WEXITSTATUS(example.stop(0, 10.0)), 2);
}

// ---- kill -9 and restart of the real `hrcsense run`

// A noise-free, static cell (kCliCell's camera and UR5 without the box) at 424x240, paced: after
// 10 learning frames every frame says run. 900 frames (30 s) is more than the test needs.
constexpr const char* kQuietCell = R"(source: {type: sim, seed: 1, pace: true}
sim: {width: 424, height: 240, fps: 30, frames: 900, noise: false, color: false}
camera:
  T_base_camera: {translation_m: [2.0, 0, 1.6], rotation_rpy_deg: [-125, 0, 90]}
scene:
  objects:
    - name: floor
      static: true
      shapes:
        - plane: {point: [0, 0, -0.75], normal: [0, 0, 1]}
background: {frames: 10}
robot:
  model: ur5
  base_frame: base
  padding_m: 0.05
  joints_rad: [-0.941593, -1.5, 1.4, -1.7, -1.5708, 0.0]
safety: {slow_distance_m: 1.0, stop_distance_m: 0.5}
)";

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

uint32_t header_session(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return 0;
  const nlohmann::json header = nlohmann::json::parse(line);
  return header.at("type") == "header" && header.at("session").is_number() ? header.at("session").get<uint32_t>() : 0;
}

// Taken frame datagrams that say run, each counted once (the verdict is looked at more often).
struct RunCount {
  int runs = 0;
  int64_t last_sequence = -1;
  void see(const LinkReceiverVerdict& v) {
    if (v.basis != LinkVerdictBasis::frame || v.state != VerdictState::run || v.sequence == last_sequence) return;
    ++runs;
    last_sequence = v.sequence;
  }
};

// A loopback socket with a LinkReceiver behind it, and `hrcsense run` on kQuietCell sending to it.
class LinkReceiverKillAndRestart : public ::testing::Test {
 protected:
  static constexpr int64_t kTimeoutNs = 200 * kMs;

  LinkReceiverKillAndRestart() : receiver_(params()) { std::ofstream(config_) << kQuietCell; }
  ~LinkReceiverKillAndRestart() override { std::remove(config_.c_str()); }

  static LinkReceiverParams params() {
    LinkReceiverParams p;
    p.timeout_ns = kTimeoutNs;
    return p;
  }
  /// A file in the temporary folder, named for this process (two test runs may share the folder).
  static std::string temp(const std::string& name) {
    return std::string(::testing::TempDir()) + std::to_string(::getpid()) + "_" + name;
  }

  std::unique_ptr<Child> start(const std::string& out) {
    std::remove(out.c_str());
    return std::make_unique<Child>(std::vector<std::string>{
        HRCSENSE_CLI, "run", "--config", config_, "--set",
        "link.udp.address=127.0.0.1:" + std::to_string(socket_.port), "--out", out});
  }

  /// Receives for at most `limit_ms`, until `done` says so; after every datagram and every 5 ms
  /// of silence, `check` sees the verdict at that moment.
  template <typename Done, typename Check>
  void receive(int limit_ms, const Done& done, const Check& check) {
    const int64_t deadline = steady_ns() + limit_ms * kMs;
    while (steady_ns() < deadline && !done()) {
      pollfd p{socket_.fd, POLLIN, 0};
      if (::poll(&p, 1, 5) > 0) drain();
      const int64_t now = steady_ns();
      check(receiver_.verdict(now), now);
    }
  }

  /// Takes every datagram waiting in the socket, as arrived now.
  void drain() {
    uint8_t bytes[2048];
    for (ssize_t got; (got = ::recv(socket_.fd, bytes, sizeof bytes, MSG_DONTWAIT)) > 0;) {
      receiver_.take_bytes(bytes, static_cast<size_t>(got), steady_ns());
    }
  }

  const test::LoopbackUdpSocket socket_;
  const std::string config_ = temp("link_receiver_cell.yaml");
  LinkReceiver receiver_;
};

TEST_F(LinkReceiverKillAndRestart, TheDeadRunEndsWithinTheTimeoutAndTheRestartIsFollowed) {
  const std::string out_dead = temp("link_receiver_dead.jsonl"), out_reborn = temp("link_receiver_reborn.jsonl");
  // 1. The first process runs until 15 frames saying run were taken, then is killed. What it
  // sent before it died is taken at once, before the restart (whose fork can take a while on a
  // loaded machine), as it would arrive at a controller.
  auto dead = start(out_dead);
  RunCount dead_runs;
  receive(60000, [&] { return dead_runs.runs >= 15; }, [&](const LinkReceiverVerdict& v, int64_t) { dead_runs.see(v); });
  ASSERT_GE(dead_runs.runs, 15) << "the first run never said run on the link";
  const uint32_t dead_session = receiver_.session();
  ASSERT_NE(dead_session, 0U);
  const int killed = dead->stop(SIGKILL, 10.0);
  const int64_t killed_ns = steady_ns();
  ASSERT_TRUE(WIFSIGNALED(killed) && WTERMSIG(killed) == SIGKILL) << killed;
  drain();
  const int64_t drained_ns = steady_ns();

  // 2. Restarted at once. The dead process's run may stand only until the timeout after its
  // last datagram, and never once the new session is taken; the new one is followed until it
  // says run too.
  auto reborn = start(out_reborn);
  int64_t dead_run_last_ns = killed_ns;  // the latest moment the dead run was still the verdict
  bool reborn_seen = false, dead_after_reborn = false;
  RunCount reborn_runs;
  receive(
      60000, [&] { return reborn_runs.runs >= 5; },
      [&](const LinkReceiverVerdict& v, int64_t now) {
        if (v.session == dead_session) {
          dead_after_reborn = dead_after_reborn || reborn_seen;
          if (v.state != VerdictState::stop) dead_run_last_ns = now;
        } else if (v.session != 0) {
          reborn_seen = true;
          reborn_runs.see(v);
        }
      });
  std::printf("kill -9 and restart: the dead run was the verdict until %.1f ms after the kill (timeout %lld ms)\n",
              static_cast<double>(dead_run_last_ns - killed_ns) / 1e6, static_cast<long long>(kTimeoutNs / kMs));
  EXPECT_LT(dead_run_last_ns - drained_ns, kTimeoutNs)
      << "the dead process's run was the verdict " << (dead_run_last_ns - killed_ns) / kMs << " ms after the kill";
  EXPECT_TRUE(reborn_seen) << "the restarted process was never followed";
  EXPECT_FALSE(dead_after_reborn) << "the dead session came back after the new one was taken";
  EXPECT_GE(reborn_runs.runs, 5) << "the restarted process's run was not taken";
  const uint32_t reborn_session = receiver_.session();
  EXPECT_NE(reborn_session, dead_session);
  EXPECT_NE(reborn_session, 0U);
  const LinkReceiverCounters counters = receiver_.counters();
  EXPECT_EQ(counters.sessions, 2);
  EXPECT_EQ(counters.new_sessions, 1);
  EXPECT_EQ(counters.malformed, 0);
  EXPECT_EQ(counters.retired_session, 0) << "nothing of the dead process arrives after the restart's first datagram";

  // 3. Each file's header names the session its datagrams carried.
  EXPECT_EQ(header_session(out_dead), dead_session);
  EXPECT_EQ(header_session(out_reborn), reborn_session);

  // 4. The restarted process ends normally: its final stop is taken and the verdict is stop.
  const int status = reborn->stop(SIGTERM, 20.0);
  EXPECT_TRUE(WIFEXITED(status)) << status;
  bool final_taken = false;
  receive(
      5000, [&] { return final_taken; },
      [&](const LinkReceiverVerdict& v, int64_t) {
        final_taken = final_taken || (v.basis == LinkVerdictBasis::final_stop && v.session == reborn_session);
      });
  EXPECT_TRUE(final_taken) << "the restarted process's final stop";
  EXPECT_EQ(receiver_.verdict(steady_ns()).state, VerdictState::stop);
  std::remove(out_dead.c_str());
  std::remove(out_reborn.c_str());
}

}  // namespace
}  // namespace hrcsense
