#include <string>

#include "daemon/device/device.h"
#include "daemon/device/hid_device.h"
#include "daemon/device/replay_device.h"
#include "daemon/device/sim_device.h"
#include "daemon/device/usb_device.h"

namespace hapticd::device {

Result<std::unique_ptr<Device>> makeDevice(std::string_view spec, const DeviceOptions& options) {
  auto parsed = parseDeviceSpec(spec);
  if (!parsed)
    return parsed.error();
  const DeviceSpec& s = parsed.value();
  switch (s.backend) {
    case DeviceSpec::Backend::kSim:
      return makeSimDevice(options);
    case DeviceSpec::Backend::kReplay:
      return makeReplayDevice(s.arg, options);
    case DeviceSpec::Backend::kHid:
      return makeHidDevice(s.arg, options);
    case DeviceSpec::Backend::kUsb:
      break;
  }
  return makeUsbDevice(options);
}

}  // namespace hapticd::device
