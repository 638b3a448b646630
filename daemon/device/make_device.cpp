#include <string>

#include "daemon/device/device.h"
#include "daemon/device/forcedimension_device.h"
#include "daemon/device/haply_device.h"
#include "daemon/device/hid_device.h"
#include "daemon/device/openhaptics_device.h"
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
    case DeviceSpec::Backend::kForceDimension:
      return makeForceDimensionDevice(std::stoi(s.arg), options);
    case DeviceSpec::Backend::kOpenHaptics:
      return makeOpenHapticsDevice(s.arg, options);
    case DeviceSpec::Backend::kHaply:
      return makeHaplyDevice(s.arg, options);
    case DeviceSpec::Backend::kUsb:
      break;
  }
  return makeUsbDevice(options);
}

}  // namespace hapticd::device
