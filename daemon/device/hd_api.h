#pragma once
/// \file
/// The part of the 3D Systems OpenHaptics HD API (libHD) that the `openhaptics` backend uses,
/// declared here from the OpenHaptics Programmer's Guide and API Reference (function names,
/// arguments, the HD_* parameter and error codes); the vendor's header is not included and the
/// library is loaded at run time (vendor_library.h).
///
/// Conventions of the API (as documented): a device is initialised by name (the name given in
/// the device setup utility; NULL: the default device) and made current; state is read and
/// forces are set between hdBeginFrame() and hdEndFrame() inside a callback that the HD servo
/// scheduler runs at its own rate (1 kHz by default); errors are taken from a stack with
/// hdGetError() (errorCode HD_SUCCESS when empty). Units: millimetres, radians, newtons, and
/// millinewton metres for gimbal torque. The device frame: x right, y up, z toward the user.

#include <cstdint>
#include <string>

#include "core/common/result.h"
#include "daemon/device/vendor_library.h"

namespace hapticd::device::hd {

using HHD = unsigned int;
using HDenum = unsigned int;
/// A scheduler callback: returns kCallbackContinue to be called again at the next tick.
using SchedulerCallback = unsigned int (*)(void* data);

/// What hdGetError() returns (by value).
struct ErrorInfo {
  unsigned int error_code;
  int internal_error_code;
  HHD device;
};

// documented constants (hdDefines.h of OpenHaptics 3)
inline constexpr HHD kInvalidHandle = 0xFFFFFFFF;
inline constexpr unsigned int kCallbackDone = 0;
inline constexpr unsigned int kCallbackContinue = 1;
inline constexpr unsigned short kMaxSchedulerPriority = 0xFFFF;
inline constexpr unsigned int kSuccess = 0x0000;
inline constexpr unsigned int kCommError = 0x0302;
inline constexpr unsigned int kCommConfigError = 0x0303;
inline constexpr unsigned int kDeviceFault = 0x0300;
inline constexpr HDenum kCurrentButtons = 0x2000;
inline constexpr HDenum kCurrentTransform = 0x2052;
inline constexpr HDenum kDeviceModelType = 0x2501;
inline constexpr HDenum kDeviceSerialNumber = 0x2504;
inline constexpr HDenum kInputDof = 0x2553;
inline constexpr HDenum kOutputDof = 0x2554;
inline constexpr HDenum kNominalMaxContinuousForce = 0x2604;
inline constexpr HDenum kNominalMaxTorqueContinuousForce = 0x2623;
inline constexpr HDenum kCurrentForce = 0x2700;
inline constexpr HDenum kCurrentGimbalTorque = 0x2704;
inline constexpr HDenum kForceOutput = 0x4000;
inline constexpr int kCalibrationOk = 0x5000;
inline constexpr int kCalibrationNeedsUpdate = 0x5001;
inline constexpr int kCalibrationNeedsManualInput = 0x5002;

/// The functions, bound by name from libHD. All of them are required.
struct Api {
  HHD (*initDevice)(const char* name);
  void (*disableDevice)(HHD device);
  void (*makeCurrentDevice)(HHD device);
  void (*enable)(HDenum capability);
  void (*disable)(HDenum capability);
  void (*startScheduler)();
  void (*stopScheduler)();
  unsigned long (*scheduleAsynchronous)(SchedulerCallback callback,
                                        void* data,
                                        unsigned short priority);
  void (*unschedule)(unsigned long handle);
  void (*beginFrame)(HHD device);
  void (*endFrame)(HHD device);
  void (*getDoublev)(HDenum parameter, double* values);
  void (*getIntegerv)(HDenum parameter, int* values);
  const char* (*getString)(HDenum parameter);
  void (*setDoublev)(HDenum parameter, const double* values);
  ErrorInfo (*getError)();
  int (*checkCalibration)();
};

/// The environment variable naming the library to load (a path or a dlopen name).
inline constexpr const char* kLibraryEnv = "HAPTICD_HD_LIBRARY";

/// Loads libHD (`configured`, else $HAPTICD_HD_LIBRARY, else libHD.so and libHD.so.3.4) and binds
/// every function. Off the servo thread. Fails, naming the library and the OpenHaptics package
/// to install, when it cannot be loaded or lacks a function.
Result<Api> loadApi(const std::string& configured);

}  // namespace hapticd::device::hd
