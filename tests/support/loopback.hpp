// SPDX-License-Identifier: Apache-2.0
// Test support: a UDP socket bound to 127.0.0.1 on an ephemeral port, the peer of every
// datagram test (tests never leave loopback).
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <stdexcept>

namespace hrcsense::test {

/// A UDP socket on 127.0.0.1 with the port the system chose; closed with the object.
struct LoopbackUdpSocket {
  int fd = -1;
  uint16_t port = 0;
  LoopbackUdpSocket() {
    fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) throw std::runtime_error("loopback UDP socket");
    sockaddr_in self{};
    self.sin_family = AF_INET;
    self.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof self;
    if (::bind(fd, reinterpret_cast<const sockaddr*>(&self), sizeof self) != 0 ||
        ::getsockname(fd, reinterpret_cast<sockaddr*>(&self), &length) != 0) {
      ::close(fd);
      throw std::runtime_error("bind to 127.0.0.1");
    }
    port = ntohs(self.sin_port);
  }
  ~LoopbackUdpSocket() { ::close(fd); }
  LoopbackUdpSocket(const LoopbackUdpSocket&) = delete;
  LoopbackUdpSocket& operator=(const LoopbackUdpSocket&) = delete;
};

}  // namespace hrcsense::test
