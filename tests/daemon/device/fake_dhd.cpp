// A fake Force Dimension DHD library for the tests: a shared library exporting the SDK's function
// names (as declared in daemon/device/dhd_api.h, from the SDK's documentation) over scripted
// devices, and a control API of its own (fake_dhd.h) that moves them, presses buttons, makes calls
// fail, disconnects and reconnects them, and records every force call. Nothing here allocates or
// locks: the servo thread calls it in the allocation tests. State shared with the test thread is
// atomic; the force records are written by the one servo thread and read after it stopped.
#include "tests/daemon/device/fake_dhd.h"

#include <atomic>
#include <cstdint>
#include <cstring>

namespace {

constexpr int kDevices = 4;

struct Device {
  std::atomic<int> type{104};
  std::atomic<bool> present{true};  // plugged in
  std::atomic<bool> open{false};
  std::atomic<bool> forces_on{false};
  std::atomic<bool> brakes{false};
  std::atomic<bool> gravity{false};
  std::atomic<int> fail_error{0};  // the next fail_count calls fail with this
  std::atomic<int> fail_count{0};
  FakePose pose;  // SDK frame, R row-major
  std::atomic<double> gripper{0.0};
  std::atomic<unsigned> buttons{0};
  std::atomic<std::uint64_t> force_count{0};
  std::atomic<std::uint64_t> opens{0};
  FakeDhdForce forces[kFakeDhdForceCapacity];
};

Device g_dev[kDevices];
std::atomic<int> g_count{1};
thread_local int t_error = 0;

Device* dev(char id) {
  if (id < 0 || id >= kDevices)
    return nullptr;
  return &g_dev[static_cast<int>(id)];
}

// a call on device id: false (with the error set) when it fails
bool call(char id) {
  Device* d = dev(id);
  if (d == nullptr) {
    t_error = 15;  // DHD_ERROR_INVALID_INDEX
    return false;
  }
  if (!d->present.load()) {
    t_error = 2;  // DHD_ERROR_COM
    return false;
  }
  if (!d->open.load()) {
    t_error = 5;  // DHD_ERROR_NO_DEVICE_FOUND
    return false;
  }
  if (d->fail_count.load() > 0) {
    d->fail_count.fetch_sub(1);
    t_error = d->fail_error.load();
    return false;
  }
  t_error = 0;
  return true;
}

// sets a device's `flag`; turning it on clears `excluded` (forces and brakes exclude each other)
int setFlag(char id,
            bool on,
            std::atomic<bool> Device::*flag,
            std::atomic<bool> Device::*excluded) {
  if (!call(id))
    return -1;
  Device& d = *dev(id);
  d.*flag = on;
  if (on && excluded != nullptr)
    d.*excluded = false;
  return 0;
}

}  // namespace

extern "C" {

// the SDK's functions (the subset hapticd binds)
int dhdGetDeviceCount() {
  int n = 0;
  for (int i = 0; i < g_count.load(); ++i)
    n += g_dev[i].present.load() ? 1 : 0;
  return n;
}
int dhdOpenID(char index) {
  Device* d = dev(index);
  if (d == nullptr || index >= g_count.load() || !d->present.load()) {
    t_error = 5;
    return -1;
  }
  d->open = true;
  d->forces_on = false;
  d->opens.fetch_add(1);
  t_error = 0;
  return index;
}
int dhdClose(char id) {
  if (Device* d = dev(id))
    d->open = false;
  return 0;
}
int dhdGetSystemType(char id) {
  return call(id) ? dev(id)->type.load() : -1;
}
const char* dhdGetSystemName(char id) {
  if (!call(id))
    return nullptr;
  switch (dev(id)->type.load()) {
    case 104:
      return "sigma.7";
    case 33:
      return "omega.3";
    case 35:
      return "omega.7";
    default:
      return "custom";
  }
}
int dhdGetSerialNumber(unsigned short* sn, char id) {
  if (!call(id))
    return -1;
  *sn = static_cast<unsigned short>(1200 + id);
  return 0;
}
static bool typeHas(char id, bool sigma, bool omega7, bool omega3) {
  const int t = dev(id) != nullptr ? dev(id)->type.load() : 0;
  return t == 104 ? sigma : t == 35 ? omega7 : t == 33 ? omega3 : false;
}
bool dhdHasWrist(char id) {
  return typeHas(id, true, true, false);
}
bool dhdHasActiveWrist(char id) {
  return typeHas(id, true, false, false);
}
bool dhdHasGripper(char id) {
  return typeHas(id, true, true, false);
}
bool dhdHasActiveGripper(char id) {
  return typeHas(id, true, true, false);
}
bool dhdIsLeftHanded(char) {
  return false;
}
int dhdEnableForce(unsigned char on, char id) {
  return setFlag(id, on != 0, &Device::forces_on, &Device::brakes);
}
int dhdSetGravityCompensation(int on, char id) {
  return setFlag(id, on != 0, &Device::gravity, nullptr);
}
int dhdSetBrakes(int on, char id) {
  return setFlag(id, on != 0, &Device::brakes, &Device::forces_on);
}
int dhdGetPosition(double* px, double* py, double* pz, char id) {
  if (!call(id))
    return -1;
  *px = dev(id)->pose.p[0].load();
  *py = dev(id)->pose.p[1].load();
  *pz = dev(id)->pose.p[2].load();
  return 0;
}
int dhdGetOrientationFrame(double m[3][3], char id) {
  if (!call(id))
    return -1;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      m[r][c] = dev(id)->pose.R[r * 3 + c].load();
  return 0;
}
int dhdGetGripperAngleRad(double* a, char id) {
  if (!call(id))
    return -1;
  *a = dev(id)->gripper.load();
  return 0;
}
unsigned int dhdGetButtonMask(char id) {
  return call(id) ? dev(id)->buttons.load() : 0u;
}
int dhdSetForceAndTorqueAndGripperForce(double fx,
                                        double fy,
                                        double fz,
                                        double tx,
                                        double ty,
                                        double tz,
                                        double fg,
                                        char id) {
  if (!call(id))
    return -1;
  Device* d = dev(id);
  const std::uint64_t n = d->force_count.load();
  if (n < kFakeDhdForceCapacity)
    d->forces[n] = FakeDhdForce{{fx, fy, fz}, {tx, ty, tz}, fg, d->forces_on.load() ? 1 : 0};
  d->force_count.store(n + 1);
  return 0;
}
int dhdErrorGetLast() {
  return t_error;
}
const char* dhdErrorGetLastStr() {
  return t_error == 0 ? "no error" : "fake error";
}

}  // extern "C"

namespace {

// the control API (fake_dhd.h)
void reset(int device_count, int type) {
  g_count = device_count;
  for (Device& d : g_dev) {
    d.type = type;
    d.present = true;
    d.open = d.forces_on = d.brakes = d.gravity = false;
    d.fail_error = d.fail_count = 0;
    d.pose.reset();
    d.gripper = 0.0;
    d.buttons = 0;
    d.force_count = 0;
    d.opens = 0;
  }
}
void setPose(int index, const double p[3], const double R[9]) {
  g_dev[index].pose.set(p, R);
}
void setButtons(int index, unsigned mask, double gripper_rad) {
  g_dev[index].buttons = mask;
  g_dev[index].gripper = gripper_rad;
}
void fail(int index, int error, int count) {
  g_dev[index].fail_error = error;
  g_dev[index].fail_count = count;
}
void setPresent(int index, int present) {
  g_dev[index].present = present != 0;
  if (present == 0)
    g_dev[index].open = g_dev[index].forces_on = false;
}
FakeDhdState state(int index) {
  const Device& d = g_dev[index];
  return FakeDhdState{d.open.load(),    d.forces_on.load(),   d.brakes.load(),
                      d.gravity.load(), d.force_count.load(), d.opens.load()};
}
const FakeDhdForce* forces(int index) {
  return g_dev[index].forces;
}

}  // namespace

extern "C" const FakeDhdControl* fakedhd_control() {
  static constexpr FakeDhdControl kControl{reset,      setPose, setButtons, fail,
                                           setPresent, state,   forces};
  return &kControl;
}
