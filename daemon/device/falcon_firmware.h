#pragma once
/// \file
/// Loading the Novint Falcon's firmware. The Falcon keeps no firmware across power cycles: after
/// power-up its bootloader waits for the firmware over the FTDI serial link. The sequence, as
/// described by libnifalcon (FalconCommLibUSB::setFirmwareMode, FalconFirmware::loadFirmware):
/// 1. purge both FTDI buffers; latency timer 16 ms; 9600 baud; 8N1; no flow control; RTS low,
///    DTR low, then DTR high;
/// 2. send 0x0a 0x43 0x0d until the bootloader answers 0x0a 0x44 0x2c 0x0d (some hosts see a
///    leading 0x00), at most 100 tries;
/// 3. DTR low; 140 kbaud (divisor value 0x15); send 'A', expect 'A' back;
/// 4. send the firmware in chunks of 62 bytes; the bootloader echoes every byte, which must match;
/// 5. back to the normal mode: latency timer 1 ms, 1.5 Mbaud (divisor 2), purge both buffers.
/// Normal thread only (blocking I/O with timeouts).

#include <cstdint>
#include <span>

#include "core/common/result.h"

namespace hapticd::device::falcon {

/// The FTDI link, blocking. Implemented over libusb by the usb backend, by a fake in tests.
class FtdiLink {
 public:
  virtual ~FtdiLink() = default;
  /// One FTDI vendor request (bmRequestType 0x40, index 0). false on failure.
  virtual bool control(std::uint8_t request, std::uint16_t value) = 0;
  /// Writes bytes; returns the count written, < 0 on error.
  virtual int write(std::span<const std::uint8_t> bytes, unsigned timeout_ms) = 0;
  /// Reads what arrives within timeout_ms (FTDI status bytes removed); returns the count (0 on
  /// timeout), < 0 on error.
  virtual int read(std::span<std::uint8_t> buf, unsigned timeout_ms) = 0;
};

// FTDI vendor requests and values used here and by the usb backend
inline constexpr std::uint8_t kFtdiReset = 0x00;
inline constexpr std::uint8_t kFtdiModemCtrl = 0x01;
inline constexpr std::uint8_t kFtdiSetFlowCtrl = 0x02;
inline constexpr std::uint8_t kFtdiSetBaudRate = 0x03;
inline constexpr std::uint8_t kFtdiSetData = 0x04;
inline constexpr std::uint8_t kFtdiSetLatencyTimer = 0x09;
inline constexpr std::uint16_t kFtdiPurgeRx = 1;
inline constexpr std::uint16_t kFtdiPurgeTx = 2;
inline constexpr std::uint16_t kFtdiDtrHigh = 0x0101;
inline constexpr std::uint16_t kFtdiDtrLow = 0x0100;
inline constexpr std::uint16_t kFtdiRtsLow = 0x0200;
inline constexpr std::uint16_t kFtdiBaud9600 = 0x4138;
inline constexpr std::uint16_t kFtdiBaud140k = 0x0015;
inline constexpr std::uint16_t kFtdiBaudNormal = 0x0002;  ///< 3 MHz / 2 = 1.5 Mbaud
inline constexpr std::uint16_t kFtdiData8N1 = 8;
inline constexpr std::size_t kFirmwareChunk = 62;
/// A firmware file larger than this is refused.
inline constexpr std::size_t kMaxFirmwareBytes = 1u << 20;

/// Sends firmware to a Falcon in its bootloader and leaves the link in the normal mode. Errors
/// say which step failed. Normal thread.
Result<bool> loadFirmware(FtdiLink& link, std::span<const std::uint8_t> firmware);

/// The normal mode (step 5 above), also used when opening a Falcon. Normal thread.
Result<bool> setNormalMode(FtdiLink& link);

}  // namespace hapticd::device::falcon
