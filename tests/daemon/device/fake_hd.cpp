// A fake OpenHaptics HD library for the tests: a shared library exporting the HD API's function
// names (as declared in daemon/device/hd_api.h, from the OpenHaptics documentation) over one
// scripted device, with its own servo scheduler thread that runs the scheduled callback frame
// after frame, back to back (the tests' loop runs on a virtual clock), and a control API of its
// own (fake_hd.h). Nothing called inside a frame allocates or locks.
#include "tests/daemon/device/fake_hd.h"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <thread>

#include "daemon/device/hd_api.h"

namespace {

constexpr unsigned kCommError = 0x0302;
constexpr unsigned kDeviceFault = 0x0300;

// the very type the daemon calls hdGetError() through (a struct of the same layout under another
// name is another function type: UBSan's -fsanitize=function refuses the call)
using hapticd::device::hd::ErrorInfo;

struct Scripted {
  std::uint64_t frame;
  int event;
  int arg;
};

struct State {
  char model[64] = "Touch";
  int output_dof = 3;
  double force_n = 3.3;
  double torque_mnm = 0.0;
  std::atomic<bool> present{true};
  std::atomic<int> calibration{0x5000};
  FakePose pose;  // millimetres, R column-major
  std::atomic<int> buttons{0};
  std::atomic<unsigned> errors[16] = {};
  std::atomic<int> error_count{0};
  Scripted script[16] = {};
  std::atomic<int> script_count{0};
  unsigned (*callback)(void*) = nullptr;
  void* callback_data = nullptr;
  std::thread scheduler;
  std::atomic<std::thread::id> scheduler_id{};
  std::atomic<bool> stop{false};
  std::atomic<bool> paused{false};
  std::atomic<bool> resume{false};
  std::atomic<std::uint64_t> frames{0};
  std::atomic<bool> in_frame{false};
  std::atomic<std::uint64_t> misuse{0};
  FakeHdFrame current{};
  bool force_set = false;
  std::atomic<std::uint64_t> recorded{0};
  FakeHdFrame records[kFakeHdForceCapacity];
  void (*hook)(void*) = nullptr;
  void* hook_data = nullptr;
};

State g;

void pushError(unsigned code) {
  const int n = g.error_count.load();
  if (n < 16) {
    g.errors[n] = code;
    g.error_count = n + 1;
  }
}

// a state call: inside a frame, on the scheduler thread; fails while disconnected
bool stateCall() {
  if (!g.in_frame.load() || std::this_thread::get_id() != g.scheduler_id.load())
    g.misuse.fetch_add(1);
  if (!g.present.load()) {
    pushError(kCommError);
    return false;
  }
  return true;
}

void runEvents(std::uint64_t frame) {
  for (int i = 0; i < g.script_count.load(); ++i) {
    const Scripted& s = g.script[i];
    if (s.frame != frame)
      continue;
    switch (s.event) {
      case kFakeHdDisconnect:
        g.present = false;
        break;
      case kFakeHdReconnect:
        g.present = true;
        break;
      case kFakeHdError:
        pushError(static_cast<unsigned>(s.arg));
        break;
      case kFakeHdButtons:
        g.buttons = s.arg;
        break;
      case kFakeHdPause:
        g.resume = false;
        g.paused = true;
        while (!g.resume.load() && !g.stop.load())
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        g.paused = false;
        break;
      default:
        break;
    }
  }
}

void schedulerMain() {
  g.scheduler_id = std::this_thread::get_id();
  while (!g.stop.load() && g.callback != nullptr) {
    const std::uint64_t frame = g.frames.load() + 1;
    g.frames = frame;
    runEvents(frame);
    const unsigned r = g.callback(g.callback_data);
    if (g.hook != nullptr)
      g.hook(g.hook_data);
    if (r == 0)  // HD_CALLBACK_DONE
      break;
  }
}

}  // namespace

extern "C" {

unsigned int hdInitDevice(const char* name) {
  if (name != nullptr && std::strcmp(name, "Default Device") != 0) {
    pushError(kDeviceFault);
    return 0xFFFFFFFF;
  }
  return 1;
}
void hdDisableDevice(unsigned int) {}
void hdMakeCurrentDevice(unsigned int) {}
void hdEnable(unsigned int) {}
void hdDisable(unsigned int) {}
unsigned long hdScheduleAsynchronous(unsigned (*cb)(void*), void* data, unsigned short) {
  g.callback = cb;
  g.callback_data = data;
  return 7;
}
void hdUnschedule(unsigned long) {
  g.callback = nullptr;
}
void hdStartScheduler() {
  g.stop = false;
  g.scheduler = std::thread(schedulerMain);
}
void hdStopScheduler() {
  g.stop = true;
  if (g.scheduler.joinable())
    g.scheduler.join();
}
void hdBeginFrame(unsigned int) {
  g.in_frame = true;
  g.current = FakeHdFrame{};
  g.force_set = false;
}
void hdEndFrame(unsigned int) {
  if (g.force_set) {
    const std::uint64_t n = g.recorded.load();
    if (n < kFakeHdForceCapacity)
      g.records[n] = g.current;
    g.recorded = n + 1;
  }
  g.in_frame = false;
}
void hdGetDoublev(unsigned int what, double* v) {
  switch (what) {
    case 0x2052:  // HD_CURRENT_TRANSFORM, column-major, millimetres
      if (!stateCall())
        return;
      for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r)
          v[4 * c + r] = g.pose.R[3 * c + r].load();
        v[4 * c + 3] = 0.0;
      }
      v[12] = g.pose.p[0].load();
      v[13] = g.pose.p[1].load();
      v[14] = g.pose.p[2].load();
      v[15] = 1.0;
      return;
    case 0x2604:  // HD_NOMINAL_MAX_CONTINUOUS_FORCE
      *v = g.force_n;
      return;
    case 0x2623:  // HD_NOMINAL_MAX_TORQUE_CONTINUOUS_FORCE
      *v = g.torque_mnm;
      return;
    default:
      pushError(0x0100);  // HD_INVALID_ENUM
  }
}
void hdGetIntegerv(unsigned int what, int* v) {
  switch (what) {
    case 0x2000:  // HD_CURRENT_BUTTONS
      if (stateCall())
        *v = g.buttons.load();
      return;
    case 0x2553:  // HD_INPUT_DOF
      *v = 6;
      return;
    case 0x2554:  // HD_OUTPUT_DOF
      *v = g.output_dof;
      return;
    default:
      pushError(0x0100);
  }
}
const char* hdGetString(unsigned int what) {
  return what == 0x2501 ? g.model : what == 0x2504 ? "21100000042" : "";
}
void hdSetDoublev(unsigned int what, const double* v) {
  if (!stateCall())
    return;
  if (what == 0x2700) {  // HD_CURRENT_FORCE
    std::memcpy(g.current.force, v, sizeof g.current.force);
    g.force_set = true;
  } else if (what == 0x2704) {  // HD_CURRENT_GIMBAL_TORQUE
    std::memcpy(g.current.torque, v, sizeof g.current.torque);
  } else {
    pushError(0x0100);
  }
}
ErrorInfo hdGetError() {
  const int n = g.error_count.load();
  if (n == 0)
    return ErrorInfo{0, 0, 1};
  g.error_count = n - 1;
  return ErrorInfo{g.errors[n - 1].load(), 0, 1};
}
int hdCheckCalibration() {
  if (!stateCall())
    return 0x5001;
  return g.calibration.load();
}

}  // extern "C"

namespace {

// the control API (fake_hd.h)
void reset(const char* model, int output_dof, double force_n, double torque_mnm) {
  std::strncpy(g.model, model, sizeof g.model - 1);
  g.output_dof = output_dof;
  g.force_n = force_n;
  g.torque_mnm = torque_mnm;
  g.present = true;
  g.calibration = 0x5000;
  g.pose.reset();
  g.buttons = 0;
  g.error_count = 0;
  g.script_count = 0;
  g.frames = 0;
  g.misuse = 0;
  g.recorded = 0;
  g.hook = nullptr;
}
void setPose(const double p_mm[3], const double R[9]) {
  g.pose.set(p_mm, R);
}
void setCalibration(int state) {
  g.calibration = state;
}
void at(std::uint64_t frame, int event, int arg) {
  const int n = g.script_count.load();
  if (n < 16) {
    g.script[n] = Scripted{frame, event, arg};
    g.script_count = n + 1;
  }
}
int paused() {
  return g.paused.load() ? 1 : 0;
}
void resume() {
  g.resume = true;
}
std::uint64_t frames() {
  return g.frames.load();
}
std::uint64_t frameCount() {
  return g.recorded.load();
}
const FakeHdFrame* records() {
  return g.records;
}
std::uint64_t misuse() {
  return g.misuse.load();
}
void setFrameHook(void (*hook)(void*), void* data) {
  g.hook = hook;
  g.hook_data = data;
}

}  // namespace

extern "C" const FakeHdControl* fakehd_control() {
  static constexpr FakeHdControl kControl{reset,   setPose, setCalibration, at,
                                          paused,  resume,  frames,         frameCount,
                                          records, misuse,  setFrameHook};
  return &kControl;
}
