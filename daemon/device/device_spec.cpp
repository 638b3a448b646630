#include <charconv>
#include <cstdio>
#include <string>

#include "daemon/device/device.h"

namespace hapticd::device {

Result<DeviceSpec> parseDeviceSpec(std::string_view spec) {
  constexpr const char* kKnown =
      "(known: sim, replay:FILE, hid, hid:PATH, usb, usb:falcon, forcedimension, "
      "forcedimension:INDEX, openhaptics, openhaptics:NAME, haply, haply:ws://HOST:PORT)";
  const std::string quoted = "'" + std::string(spec) + "'";
  const auto colon = spec.find(':');
  const std::string_view backend = spec.substr(0, colon);
  const bool has_arg = colon != std::string_view::npos;
  DeviceSpec out;
  out.arg = has_arg ? std::string(spec.substr(colon + 1)) : std::string();
  if (backend == "sim") {
    if (has_arg)
      return Error{"device " + quoted + ": 'sim' takes no argument"};
    out.backend = DeviceSpec::Backend::kSim;
  } else if (backend == "replay") {
    if (out.arg.empty())
      return Error{"device " + quoted + ": 'replay' needs a file: replay:FILE.csv"};
    out.backend = DeviceSpec::Backend::kReplay;
  } else if (backend == "hid") {
    if (has_arg && out.arg.empty())
      return Error{"device " + quoted + ": 'hid:' needs a path (hid:/dev/hidrawN) or none (hid)"};
    out.backend = DeviceSpec::Backend::kHid;
  } else if (backend == "usb") {
    if (has_arg && out.arg != "falcon")
      return Error{"device " + quoted + ": unknown usb device '" + out.arg +
                   "' (known: usb:falcon)"};
    out.backend = DeviceSpec::Backend::kUsb;
  } else if (backend == "forcedimension") {
    int index = 0;
    const char* first = out.arg.data();
    const char* last = first + out.arg.size();
    if (has_arg) {
      const auto r = std::from_chars(first, last, index);
      if (out.arg.empty() || r.ec != std::errc() || r.ptr != last || index < 0 ||
          index > kMaxForceDimensionIndex)
        return Error{"device " + quoted + ": the index must be a whole number from 0 to " +
                     std::to_string(kMaxForceDimensionIndex) + " (forcedimension:INDEX)"};
    }
    out.arg = std::to_string(index);
    out.backend = DeviceSpec::Backend::kForceDimension;
  } else if (backend == "openhaptics") {
    if (has_arg && out.arg.empty())
      return Error{"device " + quoted +
                   ": 'openhaptics:' needs the device's configured name (openhaptics:NAME) or "
                   "none (openhaptics: the default device)"};
    out.backend = DeviceSpec::Backend::kOpenHaptics;
  } else if (backend == "haply") {
    if (!has_arg)
      out.arg = kHaplyDefaultUrl;
    auto url = parseWsUrl(out.arg);
    if (!url)
      return Error{"device " + quoted + ": " + url.error().message};
    out.backend = DeviceSpec::Backend::kHaply;
  } else if (spec.empty()) {
    return Error{std::string("device '': empty spec ") + kKnown};
  } else {
    return Error{"device " + quoted + ": unknown backend '" + std::string(backend) + "' " + kKnown};
  }
  return out;
}

Result<WsUrl> parseWsUrl(std::string_view url) {
  constexpr std::string_view kScheme = "ws://";
  const std::string what = "'" + std::string(url) + "' is not a WebSocket URL ws://HOST:PORT";
  if (url.substr(0, 6) == "wss://")
    return Error{what + " (wss://, TLS, is not supported: the service listens on plain ws://)"};
  if (url.substr(0, kScheme.size()) != kScheme)
    return Error{what};
  std::string_view rest = url.substr(kScheme.size());
  WsUrl out;
  const auto slash = rest.find('/');
  if (slash != std::string_view::npos) {
    out.path = std::string(rest.substr(slash));
    rest = rest.substr(0, slash);
  }
  std::size_t colon = rest.rfind(':');
  if (!rest.empty() && rest.front() == '[') {  // [IPv6]:PORT
    const auto close = rest.find(']');
    if (close == std::string_view::npos || close + 1 != colon)
      return Error{what};
    out.host = std::string(rest.substr(1, close - 1));
  } else if (colon != std::string_view::npos) {
    out.host = std::string(rest.substr(0, colon));
  }
  if (out.host.empty() || colon == std::string_view::npos ||
      out.host.find_first_of(" /?#@") != std::string::npos)
    return Error{what};
  const std::string_view port = rest.substr(colon + 1);
  unsigned value = 0;
  const auto r = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || r.ec != std::errc() || r.ptr != port.data() + port.size() || value == 0 ||
      value > 65535)
    return Error{what + " (the port must be a whole number from 1 to 65535)"};
  out.port = static_cast<std::uint16_t>(value);
  return out;
}

std::string describeDevice(const DeviceInfo& info) {
  if (info.model.empty())
    return info.name;
  char limits[96];
  std::snprintf(limits, sizeof limits, "limits %g N %g N m", info.limits.max_force_n,
                info.limits.max_torque_nm);
  return info.name + ": serial " + (info.serial.empty() ? "unknown" : info.serial) + ", sensing " +
         std::to_string(info.sensing_dof) + " DOF, force " + std::to_string(info.force_dof) +
         " DOF, " + limits;
}

}  // namespace hapticd::device
