#pragma once
/// \file
/// The connection state of a hot-pluggable backend (hid, usb), and their base HotplugDevice:
/// connected or lost, and how often it was lost. The servo thread marks it lost (and stops touching
/// the transport from then on); the service thread, having reopened the device, marks it connected
/// again. Atomics only: any thread reads it, none allocates, locks or blocks.

#include <atomic>
#include <cstdint>

#include "daemon/device/device.h"

namespace hapticd::device {

class Connection {
 public:
  /// Any thread.
  bool connected() const noexcept { return connected_.load(std::memory_order_acquire); }
  /// Times it was lost since the device was opened. Any thread.
  std::uint64_t disconnects() const noexcept {
    return disconnects_.load(std::memory_order_relaxed);
  }
  /// Lost (removed, an I/O error), counted. Servo thread.
  void markLost() noexcept {
    connected_.store(false, std::memory_order_release);
    disconnects_.fetch_add(1, std::memory_order_relaxed);
  }
  /// Not open yet (not counted as a loss). The opener, before the device runs.
  void markClosed() noexcept { connected_.store(false, std::memory_order_release); }
  /// Reopened. Service thread, after the transport is ready.
  void markConnected() noexcept { connected_.store(true, std::memory_order_release); }

 private:
  std::atomic<bool> connected_{true};
  std::atomic<std::uint64_t> disconnects_{0};
};

/// A backend that can be unplugged and come back (hid, usb): the Device answers connected() and
/// disconnects() from its Connection.
class HotplugDevice : public Device {
 public:
  bool connected() const noexcept override { return link_.connected(); }
  std::uint64_t disconnects() const noexcept override { return link_.disconnects(); }

 protected:
  Connection link_;  ///< connected or lost, and the count of losses
};

}  // namespace hapticd::device
