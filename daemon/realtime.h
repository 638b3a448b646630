#pragma once
/// \file
/// Every piece of real-time process setup, in this one file (docs/architecture.md rule 7; LinuxCNC
/// src/rtapi/uspace_rtapi_main.cc, libfranka RealtimeConfig): memory locking and stack
/// pre-faulting, SCHED_FIFO with SCHED_RESET_ON_FORK for the servo thread, CPU pinning, the
/// `require | prefer | off` policy, and the threads of the daemon (the servo thread gets its
/// scheduling here; every other thread is created explicitly at normal priority).
///
/// Policy: `require` refuses to start when any step is refused (a clear error names the step and
/// the errno); `prefer` warns and runs where refused; `off` changes nothing.

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/result.h"

namespace hapticd::daemon {

enum class RealtimePolicy : std::uint8_t { kRequire, kPrefer, kOff };

/// "require", "prefer", "off"; anything else is an error naming the value.
Result<RealtimePolicy> parseRealtimePolicy(std::string_view text);
const char* toString(RealtimePolicy policy);

/// Config [servo] realtime settings.
struct RealtimeOptions {
  RealtimePolicy policy = RealtimePolicy::kPrefer;
  int priority = 80;  ///< SCHED_FIFO priority of the servo thread, 1..99
  int cpu = -1;       ///< CPU the servo thread is pinned to; -1: not pinned
  std::size_t stack_prefault_bytes =
      std::size_t{256} * 1024;  ///< servo stack touched before the loop
};

/// The system calls the setup makes, injectable so that tests can simulate a refusal. Each
/// returns 0 or an errno value.
struct RealtimeOps {
  std::function<int(int flags)> lock_memory;  ///< mlockall(flags)
  std::function<int(int priority)> set_fifo;  ///< calling thread to SCHED_FIFO|RESET_ON_FORK
  std::function<int(int cpu)> pin_to_cpu;     ///< calling thread's affinity to one CPU
  /// The real ones.
  static RealtimeOps system();
};

/// What the setup achieved; `warnings` says what was refused under `prefer`.
struct RealtimeReport {
  bool memory_locked = false;
  bool fifo = false;
  bool pinned = false;
  std::vector<std::string> warnings;
};

/// False under AddressSanitizer (its shadow memory cannot be locked): mlockall is skipped.
bool memoryLockingSupported();

/// Process part: mlockall(MCL_CURRENT | MCL_FUTURE). Main thread, before any other thread
/// starts. Skipped (with a warning) under AddressSanitizer, whose shadow memory cannot be locked.
Result<RealtimeReport> setupProcessRealtime(const RealtimeOptions& options,
                                            const RealtimeOps& ops = RealtimeOps::system());

/// Servo-thread part, called ON the servo thread before its loop: pre-faults
/// `stack_prefault_bytes` of stack, then SCHED_FIFO at `priority` with SCHED_RESET_ON_FORK, then
/// pins to `cpu`. Allocates (messages): call before the loop starts.
Result<RealtimeReport> setupServoThreadRealtime(const RealtimeOptions& options,
                                                const RealtimeOps& ops = RealtimeOps::system());

/// The calling thread's scheduling policy as text ("SCHED_FIFO 80", "SCHED_OTHER"). Any thread.
std::string describeThreadScheduling();

/// A thread with a fixed stack size, created at normal priority (SCHED_OTHER, explicitly, so
/// that it never inherits a real-time policy), named for `top -H`.
class Thread {
 public:
  Thread() = default;
  Thread(const Thread&) = delete;
  Thread& operator=(const Thread&) = delete;
  ~Thread();

  /// Starts `body` on a new thread. Off the servo thread. Error: pthread_create's errno.
  Result<bool> start(const char* name, std::size_t stack_bytes, std::function<void()> body);
  /// Waits for the thread to end (no-op when not started).
  void join();
  bool joinable() const { return started_; }

 private:
  static void* trampoline(void* self);
  unsigned long handle_ = 0;  // pthread_t
  bool started_ = false;
  std::function<void()> body_;
  std::string name_;
};

}  // namespace hapticd::daemon
