// SPDX-License-Identifier: Apache-2.0
// hrcsense-link-receiver: the reference receiver (LinkReceiver) as a program, the starting point
// of a controller-side receiver. Listens on 127.0.0.1:PORT for the binary link datagrams and
// prints one line per datagram and one per timeout:
//   hrcsense-link-receiver [--port N] [--timeout-ms T] [--datagrams N]
// --port 0 (the default) lets the system choose; the first line says which:
//   listening on 127.0.0.1:40213
//   session 439041101 sequence 17 frame taken: run 1 (frame, reason no_foreground)
//   nothing taken for 200 ms: stop 0 (timed_out, reason no_frame)
// --datagrams N ends after N datagrams (0: never; SIGINT ends it).
#include "hrcsense/net/link_receiver.hpp"
#include "hrcsense/safety.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

using namespace hrcsense;

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void print_verdict(const LinkReceiverVerdict& v) {
  std::printf("%s %g (%s, reason %s)\n", verdict_name(v.state), static_cast<double>(v.speed_scale),
              link_verdict_basis_name(v.basis), reason_code_name(v.reason));
}

bool read_number(const char* text, long minimum, long maximum, long& value) {
  char* end = nullptr;
  value = std::strtol(text, &end, 10);
  return end != text && *end == '\0' && value >= minimum && value <= maximum;
}

struct Options {
  long port = 0;        ///< 0: the system chooses
  long timeout_ms = 200;
  long datagrams = 0;   ///< end after this many; 0: never
};

bool parse_options(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; i += 2) {
    const std::string flag = argv[i];
    const bool ok = i + 1 < argc && ((flag == "--port" && read_number(argv[i + 1], 0, 65535, o.port)) ||
                                     (flag == "--timeout-ms" && read_number(argv[i + 1], 1, 60000, o.timeout_ms)) ||
                                     (flag == "--datagrams" && read_number(argv[i + 1], 0, 1L << 30, o.datagrams)));
    if (!ok) return false;
  }
  return true;
}

/// A UDP socket bound to 127.0.0.1:port (loopback only: the link has no authentication); prints
/// the port it got. -1 on failure, said on stderr.
int open_loopback(long port) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in self{};
  self.sin_family = AF_INET;
  self.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  self.sin_port = htons(static_cast<uint16_t>(port));
  socklen_t length = sizeof self;
  if (fd < 0 || ::bind(fd, reinterpret_cast<const sockaddr*>(&self), sizeof self) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&self), &length) != 0) {
    std::fprintf(stderr, "127.0.0.1:%ld: %s\n", port, std::strerror(errno));
    if (fd >= 0) ::close(fd);
    return -1;
  }
  std::printf("listening on 127.0.0.1:%u\n", static_cast<unsigned>(ntohs(self.sin_port)));
  std::fflush(stdout);
  return fd;
}

/// Takes one datagram that arrived now and prints what became of it and the verdict.
LinkTake take_and_print(LinkReceiver& receiver, const uint8_t* bytes, size_t size) {
  const int64_t arrival_ns = now_ns();
  const LinkDecodeResult decoded = decode_link_datagram(bytes, size);
  // take_bytes on what does not decode, so that the receiver counts it.
  const LinkTake take = decoded.ok ? receiver.take(decoded.datagram, arrival_ns)
                                   : receiver.take_bytes(bytes, size, arrival_ns);
  if (decoded.ok) {
    const LinkDatagram& d = decoded.datagram;
    const char* kind = d.kind == LinkKind::frame ? "frame" : d.kind == LinkKind::heartbeat ? "heartbeat" : "final_stop";
    std::printf("session %u sequence %u %s %s: ", d.session, d.sequence, kind, link_take_name(take));
  } else {
    std::printf("malformed (%s): ", decoded.error.c_str());
  }
  print_verdict(receiver.verdict(arrival_ns));
  std::fflush(stdout);
  return take;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (!parse_options(argc, argv, options)) {
    std::fprintf(stderr, "usage: %s [--port 0-65535] [--timeout-ms 1-60000] [--datagrams N]\n", argv[0]);
    return 2;
  }
  const int fd = open_loopback(options.port);
  if (fd < 0) return 1;
  LinkReceiverParams params;
  params.timeout_ns = options.timeout_ms * 1'000'000;
  LinkReceiver receiver(params);
  bool timeout_reported = true;  // nothing taken yet: nothing to report
  for (long count = 0; options.datagrams == 0 || count < options.datagrams;) {
    // Wake when the timeout of the last taken datagram runs out too, so that silence is
    // reported when it turns the verdict to stop (rejected datagrams do not delay it).
    int wait_ms = -1;
    if (!timeout_reported) {
      const int64_t left_ns = params.timeout_ns - std::max<int64_t>(0, receiver.verdict(now_ns()).age_ns);
      wait_ms = static_cast<int>(std::max<int64_t>(0, left_ns / 1'000'000 + 1));
    }
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, wait_ms);
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) {
      const LinkReceiverVerdict v = receiver.verdict(now_ns());
      if (v.basis == LinkVerdictBasis::timed_out && !timeout_reported) {
        std::printf("nothing taken for %ld ms: ", options.timeout_ms);
        print_verdict(v);
        std::fflush(stdout);
        timeout_reported = true;
      }
      continue;
    }
    uint8_t bytes[2048];
    const ssize_t got = ::recv(fd, bytes, sizeof bytes, 0);
    if (got < 0) continue;
    ++count;
    const LinkTake take = take_and_print(receiver, bytes, static_cast<size_t>(got));
    timeout_reported = timeout_reported && !link_taken(take);
  }
  ::close(fd);
  return 0;
}
