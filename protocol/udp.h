#pragma once
/// \file
/// A non-blocking UDP endpoint (IPv4 and IPv6) and address parsing. Server and client threads;
/// not for the servo thread.

#include <sys/socket.h>

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "core/common/result.h"

namespace hapticd::proto {

/// The daemon's default UDP port, and bind address.
inline constexpr std::uint16_t kDefaultPort = 47100;
inline constexpr std::string_view kDefaultBindAddress = "127.0.0.1:47100";

/// An IPv4 or IPv6 socket address.
struct SocketAddress {
  sockaddr_storage storage{};
  socklen_t length = 0;

  /// "127.0.0.1:47100" or "[::1]:47100".
  std::string toString() const;
  std::uint16_t port() const;
  bool isLoopback() const;
  bool operator==(const SocketAddress& o) const;
};

/// Parses "HOST:PORT", "[V6]:PORT", "HOST" or "[V6]" (port `default_port`), where HOST is a
/// numeric address or, with `resolve`, a name looked up by getaddrinfo (blocking). Errors name
/// the text and what is wrong.
Result<SocketAddress> parseAddress(std::string_view text,
                                   std::uint16_t default_port = kDefaultPort,
                                   bool resolve = false);

/// What receive() got.
struct Received {
  std::size_t size = 0;    ///< bytes placed in the buffer
  bool got = false;        ///< a datagram was read
  bool truncated = false;  ///< the datagram was larger than the buffer (its tail is lost)
  /// No datagram, but the kernel reported that the peer's port is closed (ICMP port unreachable,
  /// ECONNREFUSED): only on a connected socket (connectedTo), at once on loopback.
  bool refused = false;
};

/// A bound, non-blocking UDP socket. Movable, not copyable; closes on destruction.
class UdpSocket {
 public:
  UdpSocket() = default;
  ~UdpSocket();
  UdpSocket(UdpSocket&& o) noexcept;
  UdpSocket& operator=(UdpSocket&& o) noexcept;
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;

  /// Binds to `address` (port 0 picks a free one). `receive_buffer_bytes` > 0 sets SO_RCVBUF.
  static Result<UdpSocket> bind(const SocketAddress& address, int receive_buffer_bytes = 0);
  /// An unconnected socket on an ephemeral port of the family of `peer` (loopback for a
  /// loopback peer, any address otherwise).
  static Result<UdpSocket> forPeer(const SocketAddress& peer, int receive_buffer_bytes = 0);
  /// forPeer, connected to `peer`: it receives only from `peer`, and the kernel reports a closed
  /// port there (ICMP port unreachable) as Received::refused or a refused send. A client's socket.
  static Result<UdpSocket> connectedTo(const SocketAddress& peer, int receive_buffer_bytes = 0);

  /// Reads one datagram if any is waiting (never blocks). Other errors than "nothing waiting"
  /// and ECONNREFUSED (Received::refused) are swallowed: the datagram is simply not there.
  Received receive(std::span<std::uint8_t> buffer, SocketAddress& from);
  /// Sends one datagram; false when the kernel refused it (buffer full, unreachable), with
  /// *refused (when given) set if the reason is a closed port (ECONNREFUSED, connected sockets).
  bool sendTo(const SocketAddress& to,
              std::span<const std::uint8_t> datagram,
              bool* refused = nullptr);
  /// Waits up to timeout_ms (< 0: forever) for a datagram or an error to read; true when one
  /// is waiting.
  bool waitReadable(int timeout_ms) const;
  /// Same with a timeout in ns (ppoll), for sub-millisecond state pacing.
  bool waitReadableNs(std::uint64_t timeout_ns) const;

  SocketAddress localAddress() const;
  int fd() const { return fd_; }
  bool valid() const { return fd_ >= 0; }

 private:
  explicit UdpSocket(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace hapticd::proto
