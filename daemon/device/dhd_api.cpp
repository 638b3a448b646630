#include "daemon/device/dhd_api.h"

namespace hapticd::device::dhd {

Result<Api> loadApi(const std::string& configured) {
  constexpr const char* kInstall =
      "install the Force Dimension SDK (https://www.forcedimension.com/software/sdk) and put its "
      "libdhd.so on the loader's path, or set [device] forcedimension_library or "
      "HAPTICD_DHD_LIBRARY to it";
  auto lib = VendorLibrary::open(
      VendorLibrary::candidates(configured, kLibraryEnv, {"libdhd.so", "libdhd.so.3"}));
  if (!lib)
    return Error{"cannot load the Force Dimension DHD library (" + lib.error().message + "); " +
                 kInstall};
  const VendorLibrary& l = lib.value();
  Api a{};
  SymbolBinder need(l);
  need(a.getDeviceCount, "dhdGetDeviceCount");
  need(a.openID, "dhdOpenID");
  need(a.close, "dhdClose");
  need(a.getSystemType, "dhdGetSystemType");
  need(a.getSystemName, "dhdGetSystemName");
  need(a.getSerialNumber, "dhdGetSerialNumber");
  need(a.hasWrist, "dhdHasWrist");
  need(a.hasActiveWrist, "dhdHasActiveWrist");
  need(a.hasGripper, "dhdHasGripper");
  need(a.hasActiveGripper, "dhdHasActiveGripper");
  need(a.isLeftHanded, "dhdIsLeftHanded");
  need(a.enableForce, "dhdEnableForce");
  need(a.setGravityCompensation, "dhdSetGravityCompensation");
  need(a.setBrakes, "dhdSetBrakes");
  need(a.getPosition, "dhdGetPosition");
  need(a.getOrientationFrame, "dhdGetOrientationFrame");
  need(a.getGripperAngleRad, "dhdGetGripperAngleRad");
  need(a.getButtonMask, "dhdGetButtonMask");
  need(a.setForceAndTorqueAndGripperForce, "dhdSetForceAndTorqueAndGripperForce");
  need(a.errorGetLast, "dhdErrorGetLast");
  need(a.errorGetLastStr, "dhdErrorGetLastStr");
  if (const std::string& missing = need.missing(); !missing.empty())
    return Error{"the Force Dimension DHD library '" + l.path() + "' lacks " + missing +
                 " (an SDK older than 3.3?); " + kInstall};
  return a;
}

}  // namespace hapticd::device::dhd
