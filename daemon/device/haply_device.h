#pragma once
/// \file
/// The `haply[:ws://HOST:PORT]` device: a Haply Inverse3 (and its VerseGrip) through the Haply
/// Inverse Service's simulation channel, a local WebSocket of JSON messages (haply_protocol.h).
/// The Inverse3's cursor position and velocity and the VerseGrip's orientation and buttons in; the
/// cursor force out (3-DOF force: torque is dropped and counted). docs/devices.md.
///
/// The network I/O runs on a thread of its own (`hapticd-haply`), never on the servo thread: the
/// service answers each command with one state message, so the I/O thread sends the newest force
/// (whenever the servo thread wrote a new one, and at least every 10 ms) and publishes the state
/// that comes back. The two meet at two seqlocks (protocol/seqlock.h): the newest state (I/O
/// thread → servo thread) and the newest force (servo thread → I/O thread).
///
/// A lost service (closed, silent for haply_silence_lost_s, the Inverse3 no longer listed) is a
/// lost device: the I/O thread marks it lost and ends, read() and write() return kLost from then
/// on, and service() reconnects; the first read after a reconnection reports kFault, so the loop
/// holds the force at zero until re-armed.
///
/// Threads: open() and service() off the servo thread; read(), write() and setOutputHeld() on the
/// servo thread (seqlock copies only: no allocation, lock, log or I/O).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "daemon/device/connection.h"
#include "daemon/device/haply_protocol.h"
#include "daemon/device/pose_velocity.h"
#include "protocol/seqlock.h"

namespace hapticd::device {

class HaplyWsClient;

class HaplyDevice final : public HotplugDevice {
 public:
  /// Connects to the service at `url` (ws://HOST:PORT[/PATH]) and takes its first Inverse3 and
  /// VerseGrip. Off the servo thread; waits at most options.haply_connect_timeout_s. Fails with
  /// one line that names the Haply Inverse Service and what to install when it is unreachable.
  static Result<std::unique_ptr<HaplyDevice>> open(std::string_view url,
                                                   const DeviceOptions& options);
  /// Stops the I/O thread (it sends a zero force and closes the connection).
  ~HaplyDevice() override;

  const DeviceInfo& info() const override { return info_; }
  /// The newest state: position and orientation in the device frame (x right, y up, z toward the
  /// user; Haply's x right, y forward, z up turned), the service's cursor velocity, the angular
  /// velocity as the backward difference of the grip's orientation. kLost while not connected;
  /// kFault while the service reports an error, and once after a reconnection. Servo thread.
  DeviceStatus read(double t_s, DeviceSample& out) noexcept override;
  /// Hands the force (device frame) to the I/O thread; zero while the output is held. Servo
  /// thread.
  DeviceStatus write(const Vec3& force_n, const Vec3& torque_nm) noexcept override;
  /// Held: a zero force from now on until live again. Servo thread.
  void setOutputHeld(bool held) noexcept override;
  /// After a loss: once the I/O thread has ended, reconnects (waits at most
  /// haply_connect_timeout_s). Normal thread.
  bool service() override;

  /// Counters (any thread): exchanges with the service (one command, one state), state messages
  /// that could not be read (the last state kept), ticks read() reported a service error,
  /// torques dropped (the Inverse3 renders force only).
  std::uint64_t exchanges() const noexcept { return exchanges_.load(); }
  std::uint64_t badMessages() const noexcept { return bad_messages_.load(); }
  std::uint64_t faultTicks() const noexcept { return fault_ticks_.load(); }
  std::uint64_t torquesDropped() const noexcept { return torque_dropped_.load(); }
  /// The forces handed over by the servo thread so far (write() and a hold), and how many of
  /// them the service has had when it last answered: equal once the service has the newest
  /// force. Any thread.
  std::uint64_t forcesWritten() const noexcept { return force_.writes(); }
  std::uint64_t forcesAnswered() const noexcept { return answered_.load(); }

 private:
  struct Force {
    double force_n[3] = {0.0, 0.0, 0.0};  // Haply's frame
  };

  HaplyDevice(const WsUrl& url, const DeviceOptions& options);
  // connects, reads the device list, publishes its state; then connected, and the I/O thread runs
  bool connect(std::string& error);
  // the I/O thread: exchanges until stopped or lost
  void session(HaplyWsClient& client, std::uint64_t forces_before);

  WsUrl url_;
  std::string url_text_;
  DeviceOptions options_;
  DeviceInfo info_;
  haply::Inventory inventory_;          // the I/O thread's while it runs, else service()'s
  proto::Seqlock<haply::State> state_;  // written by the I/O thread (and connect())
  proto::Seqlock<Force> force_;         // written by the servo thread
  std::thread io_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> session_done_{true};
  std::atomic<bool> rearm_pending_{false};  // reconnected: report one kFault
  std::atomic<std::uint64_t> exchanges_{0};
  std::atomic<std::uint64_t> bad_messages_{0};
  std::atomic<std::uint64_t> fault_ticks_{0};
  std::atomic<std::uint64_t> torque_dropped_{0};
  std::atomic<std::uint64_t> answered_{0};
  // servo-thread state
  haply::State last_;
  PoseVelocity velocity_;
  bool held_ = false;
};

/// makeDevice("haply[:URL]"): connects to the Haply Inverse Service. Off the servo thread.
Result<std::unique_ptr<Device>> makeHaplyDevice(std::string_view url, const DeviceOptions& options);

}  // namespace hapticd::device
