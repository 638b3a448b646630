#include "protocol/udp.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

namespace hapticd::proto {

std::string SocketAddress::toString() const {
  char host[INET6_ADDRSTRLEN] = "?";
  if (storage.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&storage);
    inet_ntop(AF_INET, &a->sin_addr, host, sizeof host);
    return std::string(host) + ":" + std::to_string(ntohs(a->sin_port));
  }
  if (storage.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&storage);
    inet_ntop(AF_INET6, &a->sin6_addr, host, sizeof host);
    return "[" + std::string(host) + "]:" + std::to_string(ntohs(a->sin6_port));
  }
  return "(no address)";
}

std::uint16_t SocketAddress::port() const {
  if (storage.ss_family == AF_INET)
    return ntohs(reinterpret_cast<const sockaddr_in*>(&storage)->sin_port);
  if (storage.ss_family == AF_INET6)
    return ntohs(reinterpret_cast<const sockaddr_in6*>(&storage)->sin6_port);
  return 0;
}

bool SocketAddress::isLoopback() const {
  if (storage.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&storage);
    return (ntohl(a->sin_addr.s_addr) >> 24) == 127;
  }
  if (storage.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&storage);
    return IN6_IS_ADDR_LOOPBACK(&a->sin6_addr);
  }
  return false;
}

bool SocketAddress::operator==(const SocketAddress& o) const {
  if (storage.ss_family != o.storage.ss_family)
    return false;
  if (storage.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&storage);
    const auto* b = reinterpret_cast<const sockaddr_in*>(&o.storage);
    return a->sin_port == b->sin_port && a->sin_addr.s_addr == b->sin_addr.s_addr;
  }
  if (storage.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&storage);
    const auto* b = reinterpret_cast<const sockaddr_in6*>(&o.storage);
    return a->sin6_port == b->sin6_port &&
           std::memcmp(&a->sin6_addr, &b->sin6_addr, sizeof a->sin6_addr) == 0;
  }
  return length == o.length;
}

namespace {

template <class Sockaddr>
SocketAddress addressOf(const Sockaddr& a) {
  SocketAddress out;
  std::memcpy(&out.storage, &a, sizeof a);
  out.length = sizeof a;
  return out;
}

void setPort(SocketAddress& a, std::uint16_t port) {
  if (a.storage.ss_family == AF_INET)
    reinterpret_cast<sockaddr_in*>(&a.storage)->sin_port = htons(port);
  else if (a.storage.ss_family == AF_INET6)
    reinterpret_cast<sockaddr_in6*>(&a.storage)->sin6_port = htons(port);
}

// a host name through getaddrinfo (blocking), IPv4 preferred: the daemon binds 127.0.0.1 by
// default and "localhost" often lists ::1 first
Result<SocketAddress> lookUp(const std::string& host, const std::string& quoted) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* res = nullptr;
  const int rc = getaddrinfo(host.c_str(), nullptr, &hints, &res);
  if (rc != 0 || !res)
    return Error{quoted + ": cannot resolve '" + host + "': " + gai_strerror(rc)};
  const addrinfo* pick = res;
  for (const addrinfo* p = res; p; p = p->ai_next)
    if (p->ai_family == AF_INET) {
      pick = p;
      break;
    }
  SocketAddress out;
  std::memcpy(&out.storage, pick->ai_addr, pick->ai_addrlen);
  out.length = static_cast<socklen_t>(pick->ai_addrlen);
  freeaddrinfo(res);
  return out;
}

}  // namespace

Result<SocketAddress> parseAddress(std::string_view text,
                                   std::uint16_t default_port,
                                   bool resolve) {
  const std::string quoted = "address '" + std::string(text) + "'";
  std::string host;
  std::string_view port_text;
  bool has_port = false;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos)
      return Error{quoted + ": '[' without ']'"};
    host = std::string(text.substr(1, close - 1));
    const auto rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':')
        return Error{quoted + ": expected ':PORT' after ']'"};
      port_text = rest.substr(1);
      has_port = true;
    }
  } else {
    const auto colon = text.rfind(':');
    if (colon != std::string_view::npos && text.find(':') != colon)
      return Error{quoted + ": an IPv6 address needs brackets, e.g. [::1]:47100"};
    host = std::string(text.substr(0, colon));
    if (colon != std::string_view::npos) {
      port_text = text.substr(colon + 1);
      has_port = true;
    }
  }
  if (host.empty())
    return Error{quoted + ": no host"};
  std::uint16_t port = default_port;
  if (has_port) {
    unsigned v = 0;
    auto [p, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), v);
    if (ec != std::errc{} || p != port_text.data() + port_text.size() || v > 65535 ||
        port_text.empty())
      return Error{quoted + ": port must be a number 0..65535"};
    port = static_cast<std::uint16_t>(v);
  }
  SocketAddress out;
  sockaddr_in v4{};
  sockaddr_in6 v6{};
  if (inet_pton(AF_INET, host.c_str(), &v4.sin_addr) == 1) {
    v4.sin_family = AF_INET;
    out = addressOf(v4);
  } else if (inet_pton(AF_INET6, host.c_str(), &v6.sin6_addr) == 1) {
    v6.sin6_family = AF_INET6;
    out = addressOf(v6);
  } else if (!resolve) {
    return Error{quoted + ": '" + host + "' is not a numeric IPv4 or IPv6 address"};
  } else {
    auto found = lookUp(host, quoted);
    if (!found)
      return found.error();
    out = found.value();
  }
  setPort(out, port);
  return out;
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0)
    ::close(fd_);
}
UdpSocket::UdpSocket(UdpSocket&& o) noexcept : fd_(o.fd_) {
  o.fd_ = -1;
}
UdpSocket& UdpSocket::operator=(UdpSocket&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0)
      ::close(fd_);
    fd_ = o.fd_;
    o.fd_ = -1;
  }
  return *this;
}

Result<UdpSocket> UdpSocket::bind(const SocketAddress& address, int receive_buffer_bytes) {
  const int fd = ::socket(address.storage.ss_family, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0)
    return Error{std::string("udp: socket(): ") + std::strerror(errno)};
  UdpSocket s(fd);
  if (address.storage.ss_family == AF_INET6) {
    const int one = 1;
    ::setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &one, sizeof one);
  }
  if (receive_buffer_bytes > 0)
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof receive_buffer_bytes);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address.storage), address.length) != 0)
    return Error{"udp: cannot bind " + address.toString() + ": " + std::strerror(errno)};
  return s;
}

Result<UdpSocket> UdpSocket::forPeer(const SocketAddress& peer, int receive_buffer_bytes) {
  const char* text = peer.storage.ss_family == AF_INET6
                         ? (peer.isLoopback() ? "[::1]:0" : "[::]:0")
                         : (peer.isLoopback() ? "127.0.0.1:0" : "0.0.0.0:0");
  auto a = parseAddress(text);
  if (!a)
    return a.error();
  return bind(a.value(), receive_buffer_bytes);
}

Result<UdpSocket> UdpSocket::connectedTo(const SocketAddress& peer, int receive_buffer_bytes) {
  auto s = forPeer(peer, receive_buffer_bytes);
  if (!s)
    return s.error();
  if (::connect(s.value().fd_, reinterpret_cast<const sockaddr*>(&peer.storage), peer.length) != 0)
    return Error{"udp: cannot connect to " + peer.toString() + ": " + std::strerror(errno)};
  return s;
}

Received UdpSocket::receive(std::span<std::uint8_t> buffer, SocketAddress& from) {
  Received r;
  for (;;) {
    from.length = sizeof from.storage;
    const ssize_t n = ::recvfrom(fd_, buffer.data(), buffer.size(), MSG_TRUNC,
                                 reinterpret_cast<sockaddr*>(&from.storage), &from.length);
    if (n < 0) {
      if (errno == EINTR)
        continue;
      r.refused = errno == ECONNREFUSED;  // an ICMP port unreachable after an earlier send
      return r;
    }
    r.got = true;
    r.truncated = static_cast<std::size_t>(n) > buffer.size();
    r.size = r.truncated ? buffer.size() : static_cast<std::size_t>(n);
    return r;
  }
}

bool UdpSocket::sendTo(const SocketAddress& to, std::span<const std::uint8_t> d, bool* refused) {
  for (;;) {
    const ssize_t n = ::sendto(fd_, d.data(), d.size(), MSG_NOSIGNAL,
                               reinterpret_cast<const sockaddr*>(&to.storage), to.length);
    if (n < 0 && errno == EINTR)
      continue;
    if (refused != nullptr)
      *refused = n < 0 && errno == ECONNREFUSED;
    return n == static_cast<ssize_t>(d.size());
  }
}

bool UdpSocket::waitReadable(int timeout_ms) const {
  pollfd p{fd_, POLLIN, 0};
  for (;;) {
    const int rc = ::poll(&p, 1, timeout_ms);
    if (rc < 0 && errno == EINTR)
      continue;
    return rc > 0 && (p.revents & (POLLIN | POLLERR));
  }
}

bool UdpSocket::waitReadableNs(std::uint64_t timeout_ns) const {
  pollfd p{fd_, POLLIN, 0};
  timespec ts{static_cast<time_t>(timeout_ns / 1'000'000'000ull),
              static_cast<long>(timeout_ns % 1'000'000'000ull)};
  for (;;) {
    const int rc = ::ppoll(&p, 1, &ts, nullptr);
    if (rc < 0 && errno == EINTR)
      continue;
    return rc > 0 && (p.revents & (POLLIN | POLLERR));
  }
}

SocketAddress UdpSocket::localAddress() const {
  SocketAddress a;
  a.length = sizeof a.storage;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a.storage), &a.length);
  return a;
}

}  // namespace hapticd::proto
