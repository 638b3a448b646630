#pragma once
/// \file
/// The part of the Force Dimension DHD API (the "haptic SDK", C interface of libdhd) that the
/// `forcedimension` backend uses, declared here from Force Dimension's public documentation of
/// the SDK's C/C++ interface (function names, arguments, return conventions and constants); the
/// vendor's header is not included and the library is loaded at run time (vendor_library.h).
///
/// Conventions of the API (as documented): every device function takes the device ID as its last
/// argument (-1 selects the default device); int functions return 0 (or a documented positive
/// value such as DHD_TIMEGUARD and DHD_MOTOR_SATURATED) on success and -1 on failure, with the
/// error from dhdErrorGetLast(). Units: metres, radians, newtons, newton metres. The device's
/// base frame: x toward the user, y to the right, z up.

#include <string>

#include "core/common/result.h"
#include "daemon/device/vendor_library.h"

namespace hapticd::device::dhd {

// documented constants (the SDK's DHD_ON, DHD_MOTOR_SATURATED, dhd_errors and DHD_DEVICE_*)
inline constexpr int kOn = 1;
inline constexpr int kMotorSaturated = 2;
enum ErrorCode : int {
  kNoError = 0,
  kError = 1,
  kErrorCom = 2,
  kErrorDhcBusy = 3,
  kErrorNoDriverFound = 4,
  kErrorNoDeviceFound = 5,
  kErrorNotAvailable = 6,
  kErrorTimeout = 7,
  kErrorDeviceNotReady = 12,
};
enum SystemType : int {
  kDelta3 = 63,
  kDelta6 = 64,
  kOmega3 = 33,
  kOmega33 = 34,
  kOmega33Left = 36,
  kOmega331 = 35,
  kOmega331Left = 37,
  kFalcon = 60,
  kSigma331 = 104,
  kSigma331Left = 105,
};

/// The functions, bound by name from libdhd. All of them are required.
struct Api {
  int (*getDeviceCount)();
  int (*openID)(char index);
  int (*close)(char id);
  int (*getSystemType)(char id);
  const char* (*getSystemName)(char id);
  int (*getSerialNumber)(unsigned short* serial, char id);
  bool (*hasWrist)(char id);
  bool (*hasActiveWrist)(char id);
  bool (*hasGripper)(char id);
  bool (*hasActiveGripper)(char id);
  bool (*isLeftHanded)(char id);
  int (*enableForce)(unsigned char on, char id);
  int (*setGravityCompensation)(int on, char id);
  int (*setBrakes)(int on, char id);
  int (*getPosition)(double* px, double* py, double* pz, char id);
  int (*getOrientationFrame)(double matrix[3][3], char id);
  int (*getGripperAngleRad)(double* angle, char id);
  unsigned int (*getButtonMask)(char id);
  int (*setForceAndTorqueAndGripperForce)(double fx,
                                          double fy,
                                          double fz,
                                          double tx,
                                          double ty,
                                          double tz,
                                          double fg,
                                          char id);
  int (*errorGetLast)();
  const char* (*errorGetLastStr)();
};

/// The environment variable naming the library to load (a path or a dlopen name).
inline constexpr const char* kLibraryEnv = "HAPTICD_DHD_LIBRARY";

/// Loads libdhd (`configured`, else $HAPTICD_DHD_LIBRARY, else libdhd.so and libdhd.so.3) and
/// binds every function. Off the servo thread. Fails, naming the library and the SDK to install,
/// when it cannot be loaded or lacks a function.
Result<Api> loadApi(const std::string& configured);

/// Whether an error of the API means the device is gone (USB unplugged, powered off).
constexpr bool isLoss(int error) {
  return error == kErrorCom || error == kErrorNoDeviceFound || error == kErrorTimeout ||
         error == kErrorDeviceNotReady || error == kErrorNoDriverFound;
}

}  // namespace hapticd::device::dhd
