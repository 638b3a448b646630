#include <string>

#include "daemon/device/device.h"

namespace hapticd::device {

Result<DeviceSpec> parseDeviceSpec(std::string_view spec) {
  constexpr const char* kKnown = "(known: sim, replay:FILE, hid, hid:PATH, usb, usb:falcon)";
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
  } else if (spec.empty()) {
    return Error{std::string("device '': empty spec ") + kKnown};
  } else {
    return Error{"device " + quoted + ": unknown backend '" + std::string(backend) + "' " + kKnown};
  }
  return out;
}

}  // namespace hapticd::device
