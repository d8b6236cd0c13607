// A MAVLink TCP client link with plain POSIX sockets: non-blocking connect retried until a
// deadline, non-blocking reads into a mavlink::Parser, writes that never block.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "mavlink/frame.hpp"

namespace kelp_sitl::mission {

using Clock = std::chrono::steady_clock;

struct Endpoint {
  std::string host;
  std::uint16_t port = 0;
};

// "tcp:HOST:PORT" (the "tcp:" prefix is optional).
inline Endpoint parse_endpoint(const std::string& text) {
  std::string s = text;
  if (s.rfind("tcp:", 0) == 0) s = s.substr(4);
  const auto colon = s.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == s.size())
    throw std::invalid_argument("expected tcp:HOST:PORT, got '" + text + "'");
  Endpoint e;
  e.host = s.substr(0, colon);
  const std::string port = s.substr(colon + 1);
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (*end != '\0' || p <= 0 || p > 65535)
    throw std::invalid_argument("bad port in '" + text + "'");
  e.port = static_cast<std::uint16_t>(p);
  return e;
}

class TcpLink {
 public:
  TcpLink() = default;
  TcpLink(const TcpLink&) = delete;
  TcpLink& operator=(const TcpLink&) = delete;
  ~TcpLink() { close(); }

  // Tries to connect until `deadline`, every 0.5 s (a SITL may not listen yet). Returns false
  // on time-out; `error` then tells the last failure.
  bool connect(const Endpoint& e, Clock::time_point deadline, std::string& error) {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    for (;;) {
      addrinfo* res = nullptr;
      const int rc = getaddrinfo(e.host.c_str(), std::to_string(e.port).c_str(), &hints, &res);
      if (rc != 0) {
        error = std::string("cannot resolve ") + e.host + ": " + gai_strerror(rc);
        return false;
      }
      const bool ok = try_connect(res, deadline, error);
      freeaddrinfo(res);
      if (ok) return true;
      const auto left = deadline - Clock::now();
      if (left <= Clock::duration::zero()) return false;
      std::this_thread::sleep_for(std::min<Clock::duration>(left, std::chrono::milliseconds(500)));
    }
  }

  bool is_open() const { return fd_ >= 0; }
  int fd() const { return fd_; }

  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

  // Sends all of `bytes` unless the kernel buffer is full (the peer does not read): then the
  // frame is dropped and counted rather than blocking the mission loop. False if the link broke.
  bool send(const std::vector<std::uint8_t>& bytes) {
    if (fd_ < 0) return false;
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n > 0) {
        sent += static_cast<std::size_t>(n);
      } else if (n < 0 && errno == EINTR) {
        continue;
      } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
        if (sent == 0) {
          ++dropped_frames_;
          return true;
        }
        // Part of a frame is out: finish it (bounded wait) so the stream stays aligned.
        pollfd p{fd_, POLLOUT, 0};
        if (::poll(&p, 1, 1000) <= 0) return false;
      } else {
        return false;
      }
    }
    return true;
  }

  // Reads what is available (non-blocking) into the parser; calls on_frame per frame. Returns
  // false when the peer closed the connection or it failed.
  template <class F>
  bool receive(F&& on_frame) {
    if (fd_ < 0) return false;
    std::uint8_t buf[4096];
    for (;;) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n > 0) {
        parser_.feed(buf, static_cast<std::size_t>(n), on_frame);
        continue;
      }
      if (n == 0) return false;
      if (errno == EINTR) continue;
      return errno == EAGAIN || errno == EWOULDBLOCK;
    }
  }

  const mavlink::ParserStats& stats() const { return parser_.stats(); }
  std::uint64_t dropped_frames() const { return dropped_frames_; }

 private:
  bool try_connect(addrinfo* res, Clock::time_point deadline, std::string& error) {
    for (addrinfo* a = res; a != nullptr; a = a->ai_next) {
      const int fd =
          ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
      if (fd < 0) {
        error = std::strerror(errno);
        continue;
      }
      int rc = ::connect(fd, a->ai_addr, a->ai_addrlen);
      if (rc < 0 && errno == EINPROGRESS) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        pollfd p{fd, POLLOUT, 0};
        const int timeout_ms =
            static_cast<int>(std::max<long long>(1, std::min<long long>(left.count(), 2000)));
        if (::poll(&p, 1, timeout_ms) == 1) {
          int err = 0;
          socklen_t len = sizeof err;
          ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
          rc = err == 0 ? 0 : -1;
          errno = err;
        } else {
          errno = ETIMEDOUT;
        }
      }
      if (rc == 0) {
        const int one = 1;
        ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
        fd_ = fd;
        return true;
      }
      error = std::strerror(errno);
      ::close(fd);
    }
    return false;
  }

  int fd_ = -1;
  mavlink::Parser parser_;
  std::uint64_t dropped_frames_ = 0;
};

}  // namespace kelp_sitl::mission
