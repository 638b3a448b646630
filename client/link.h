#pragma once
/// \file
/// hapticctl's ways to a running daemon: UDP (proto::Client) and the shared-memory segment
/// (proto::ShmClient), behind one Link for the streaming commands (pose, replay, record, watch).
/// Errors are said on the caller's `err` stream, each a sentence that starts "hapticctl".
/// Thread: the caller's.

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>

#include "client/daemon_commands.h"
#include "protocol/client.h"

namespace hapticd::client {

/// "HOST:PORT" of the target, "[HOST]:PORT" for an IPv6 host.
std::string address(const DaemonTarget& t);

/// Connects over UDP with the target's key file, timeout and address; nullptr after saying why
/// on `err` (an unreadable or bad key file, no daemon, a wrong key, a refusal).
std::unique_ptr<proto::Client> connectUdp(const DaemonTarget& t, std::ostream& err);

/// What pose, replay, watch and record need of a transport.
class Link {
 public:
  virtual ~Link() = default;
  /// Takes control (arm); false with *why set.
  virtual bool arm(std::string* why) = 0;
  /// Queues one pose command; false with *why set when it cannot be sent.
  virtual bool sendPose(const proto::PoseCommand& cmd, std::string* why) = 0;
  /// States at up to rate_hz (UDP: the server's rate; shared memory: every new tick seen).
  virtual bool subscribe(std::uint32_t rate_hz, std::uint32_t flags, std::string* why) = 0;
  /// The next state not seen yet, waiting up to timeout_ms.
  virtual std::optional<proto::State> receiveState(int timeout_ms) = 0;
  /// The servo rate, Hz (0 when not known).
  virtual std::uint32_t tickRateHz() = 0;
  /// The largest state rate the daemon serves, Hz.
  virtual std::uint32_t maxStateRateHz() const = 0;
  /// Handles what is waiting without blocking (heartbeats, errors).
  virtual void pump() = 0;
  /// The daemon went away: UDP, its port was reported closed (ICMP port unreachable); shared
  /// memory, its heartbeat is older than the target's timeout.
  virtual bool gone() const = 0;
  /// Ends the session.
  virtual void close() = 0;
};

/// The link a command uses: shared memory when t.shm_name is set, else UDP; with `arm`, armed
/// (the gate takes the commands of the session that armed last). nullptr after saying why on
/// `err` (exit code 1).
std::unique_ptr<Link> openLink(const DaemonTarget& t,
                               const char* command,
                               bool arm,
                               std::ostream& err);

}  // namespace hapticd::client
