#include "daemon/device/hd_api.h"

namespace hapticd::device::hd {

Result<Api> loadApi(const std::string& configured) {
  constexpr const char* kInstall =
      "install 3D Systems' OpenHaptics for Linux and its device driver (from 3D Systems), or set "
      "[device] openhaptics_library or HAPTICD_HD_LIBRARY to its libHD.so";
  auto lib = VendorLibrary::open(
      VendorLibrary::candidates(configured, kLibraryEnv, {"libHD.so", "libHD.so.3.4"}));
  if (!lib)
    return Error{"cannot load the OpenHaptics HD library (" + lib.error().message + "); " +
                 kInstall};
  const VendorLibrary& l = lib.value();
  Api a{};
  SymbolBinder need(l);
  need(a.initDevice, "hdInitDevice");
  need(a.disableDevice, "hdDisableDevice");
  need(a.makeCurrentDevice, "hdMakeCurrentDevice");
  need(a.enable, "hdEnable");
  need(a.disable, "hdDisable");
  need(a.startScheduler, "hdStartScheduler");
  need(a.stopScheduler, "hdStopScheduler");
  need(a.scheduleAsynchronous, "hdScheduleAsynchronous");
  need(a.unschedule, "hdUnschedule");
  need(a.beginFrame, "hdBeginFrame");
  need(a.endFrame, "hdEndFrame");
  need(a.getDoublev, "hdGetDoublev");
  need(a.getIntegerv, "hdGetIntegerv");
  need(a.getString, "hdGetString");
  need(a.setDoublev, "hdSetDoublev");
  need(a.getError, "hdGetError");
  need(a.checkCalibration, "hdCheckCalibration");
  if (const std::string& missing = need.missing(); !missing.empty())
    return Error{"the OpenHaptics HD library '" + l.path() + "' lacks " + missing + "; " +
                 kInstall};
  return a;
}

}  // namespace hapticd::device::hd
