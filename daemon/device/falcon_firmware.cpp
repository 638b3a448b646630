#include "daemon/device/falcon_firmware.h"

#include <algorithm>
#include <array>
#include <string>

namespace hapticd::device::falcon {

namespace {

constexpr unsigned kTimeout_ms = 1000;
constexpr int kCheckTries = 100;

Result<bool> controls(FtdiLink& link,
                      std::initializer_list<std::pair<std::uint8_t, std::uint16_t>> steps,
                      const char* what) {
  for (const auto& [request, value] : steps)
    if (!link.control(request, value))
      return Error{std::string("falcon firmware: FTDI request failed while ") + what};
  return true;
}

// reads exactly n bytes (or fails) within a few timeouts
bool readExactly(FtdiLink& link, std::span<std::uint8_t> out) {
  std::size_t got = 0;
  for (int tries = 0; got < out.size() && tries < 8; ++tries) {
    const int n = link.read(out.subspan(got), kTimeout_ms);
    if (n < 0)
      return false;
    got += static_cast<std::size_t>(n);
  }
  return got == out.size();
}

}  // namespace

Result<bool> setNormalMode(FtdiLink& link) {
  return controls(link,
                  {{kFtdiSetLatencyTimer, 1},
                   {kFtdiSetBaudRate, kFtdiBaudNormal},
                   {kFtdiReset, kFtdiPurgeRx},
                   {kFtdiReset, kFtdiPurgeTx}},
                  "setting the normal mode");
}

Result<bool> loadFirmware(FtdiLink& link, std::span<const std::uint8_t> firmware) {
  if (firmware.empty())
    return Error{"falcon firmware: the firmware file is empty"};
  if (auto r = controls(link,
                        {{kFtdiReset, kFtdiPurgeRx},
                         {kFtdiReset, kFtdiPurgeTx},
                         {kFtdiSetLatencyTimer, 16},
                         {kFtdiSetBaudRate, kFtdiBaud9600},
                         {kFtdiSetData, kFtdiData8N1},
                         {kFtdiSetFlowCtrl, 0},
                         {kFtdiModemCtrl, kFtdiRtsLow},
                         {kFtdiModemCtrl, kFtdiDtrLow},
                         {kFtdiModemCtrl, kFtdiDtrHigh}},
                        "entering the bootloader mode");
      !r)
    return r;
  // the bootloader's greeting
  constexpr std::array<std::uint8_t, 3> kHello = {0x0a, 0x43, 0x0d};
  constexpr std::array<std::uint8_t, 4> kReply = {0x0a, 0x44, 0x2c, 0x0d};
  bool greeted = false;
  for (int i = 0; i < kCheckTries && !greeted; ++i) {
    if (link.write(kHello, kTimeout_ms) != static_cast<int>(kHello.size()))
      return Error{"falcon firmware: cannot write to the bootloader"};
    std::array<std::uint8_t, 64> buf{};
    const int n = link.read(buf, kTimeout_ms);
    if (n < 0)
      return Error{"falcon firmware: cannot read from the bootloader"};
    const auto got = std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n));
    greeted = got.size() >= kReply.size() &&
              std::equal(kReply.begin(), kReply.end(), got.end() - kReply.size());
  }
  if (!greeted)
    return Error{
        "falcon firmware: the bootloader did not answer (is the Falcon powered, and its "
        "firmware not loaded already?)"};
  if (auto r = controls(link, {{kFtdiModemCtrl, kFtdiDtrLow}, {kFtdiSetBaudRate, kFtdiBaud140k}},
                        "switching to the upload rate");
      !r)
    return r;
  const std::array<std::uint8_t, 1> kA = {'A'};
  std::array<std::uint8_t, 1> echo{};
  if (link.write(kA, kTimeout_ms) != 1 || !readExactly(link, echo) || echo[0] != 'A')
    return Error{"falcon firmware: the bootloader did not confirm the upload rate"};
  std::array<std::uint8_t, kFirmwareChunk> back{};
  for (std::size_t off = 0; off < firmware.size(); off += kFirmwareChunk) {
    const auto chunk = firmware.subspan(off, std::min(kFirmwareChunk, firmware.size() - off));
    if (link.write(chunk, kTimeout_ms) != static_cast<int>(chunk.size()))
      return Error{"falcon firmware: write failed at byte " + std::to_string(off)};
    const auto echoed = std::span(back).first(chunk.size());
    if (!readExactly(link, echoed))
      return Error{"falcon firmware: no echo at byte " + std::to_string(off)};
    const auto mismatch = std::mismatch(chunk.begin(), chunk.end(), echoed.begin());
    if (mismatch.first != chunk.end())
      return Error{"falcon firmware: echo mismatch at byte " +
                   std::to_string(off + static_cast<std::size_t>(mismatch.first - chunk.begin()))};
  }
  return setNormalMode(link);
}

}  // namespace hapticd::device::falcon
