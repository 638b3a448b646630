#include <string>

#include "daemon/device/device.h"
#include "daemon/device/hid_device.h"
#include "daemon/device/replay_device.h"
#include "daemon/device/sim_device.h"
#include "daemon/device/usb_device.h"

namespace hapticd::device {

Result<std::unique_ptr<Device>> makeDevice(std::string_view spec, const DeviceOptions& options) {
  const std::string quoted = "'" + std::string(spec) + "'";
  const auto colon = spec.find(':');
  const std::string_view backend = spec.substr(0, colon);
  const bool has_arg = colon != std::string_view::npos;
  const std::string_view arg = has_arg ? spec.substr(colon + 1) : std::string_view{};

  if (backend == "sim") {
    if (has_arg)
      return Error{"device " + quoted + ": 'sim' takes no argument"};
    return makeSimDevice(options);
  }
  if (backend == "replay") {
    if (arg.empty())
      return Error{"device " + quoted + ": 'replay' needs a file: replay:FILE.csv"};
    return makeReplayDevice(arg, options);
  }
  if (backend == "hid") {
    if (has_arg && arg.empty())
      return Error{"device " + quoted + ": 'hid:' needs a path (hid:/dev/hidrawN) or none (hid)"};
    return makeHidDevice(arg, options);
  }
  if (backend == "usb") {
    if (has_arg && arg != "falcon")
      return Error{"device " + quoted + ": unknown usb device '" + std::string(arg) +
                   "' (known: usb:falcon)"};
    return makeUsbDevice(options);
  }
  if (spec.empty())
    return Error{
        "device '': empty spec (known: sim, replay:FILE, hid, hid:PATH, "
        "usb, usb:falcon)"};
  return Error{"device " + quoted + ": unknown backend '" + std::string(backend) +
               "' (known: sim, replay:FILE, hid, hid:PATH, usb, usb:falcon)"};
}

}  // namespace hapticd::device
