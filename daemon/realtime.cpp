#include "daemon/realtime.h"

#include <alloca.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "core/common/sanitizers.h"
#include "daemon/enum_names.h"

namespace hapticd::daemon {
namespace {

std::string errnoText(int err) {
  return std::string(std::strerror(err)) + " (errno " + std::to_string(err) + ")";
}

// one refused step: an error under `require`, a warning under `prefer`
bool refuse(const RealtimeOptions& options,
            RealtimeReport& report,
            const std::string& what,
            Error& error) {
  if (options.policy == RealtimePolicy::kRequire) {
    error.message = "realtime = \"require\": " + what +
                    " (set [servo] realtime = \"prefer\" to run without it, or grant the "
                    "privilege: CAP_SYS_NICE / LimitRTPRIO, CAP_IPC_LOCK / LimitMEMLOCK)";
    return false;
  }
  report.warnings.push_back("realtime = \"prefer\": " + what + "; running without it");
  return true;
}

// touches a block of stack so that its pages are resident (and, after mlockall, locked) before
// the loop runs: a page fault inside a tick costs microseconds
__attribute__((noinline)) void prefaultStack(std::size_t bytes) {
  auto* block = static_cast<volatile unsigned char*>(alloca(bytes));
  for (std::size_t i = 0; i < bytes; i += 1024)
    block[i] = 0;
}

}  // namespace

bool memoryLockingSupported() {
  return !kAddressSanitizer;
}

namespace {
constexpr EnumName<RealtimePolicy> kPolicyNames[] = {{RealtimePolicy::kRequire, "require"},
                                                     {RealtimePolicy::kPrefer, "prefer"},
                                                     {RealtimePolicy::kOff, "off"}};
}  // namespace

Result<RealtimePolicy> parseRealtimePolicy(std::string_view text) {
  return parseIn(kPolicyNames, text, "realtime: ");
}

const char* toString(RealtimePolicy policy) {
  return nameIn(kPolicyNames, policy);
}

RealtimeOps RealtimeOps::system() {
  RealtimeOps ops;
  ops.lock_memory = [](int flags) { return mlockall(flags) == 0 ? 0 : errno; };
  ops.set_fifo = [](int priority) {
    sched_param param{};
    param.sched_priority = priority;
    // 0: the calling thread; SCHED_RESET_ON_FORK: a child process never inherits SCHED_FIFO
    return sched_setscheduler(0, SCHED_FIFO | SCHED_RESET_ON_FORK, &param) == 0 ? 0 : errno;
  };
  ops.pin_to_cpu = [](int cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<std::size_t>(cpu), &set);
    return sched_setaffinity(0, sizeof set, &set) == 0 ? 0 : errno;
  };
  return ops;
}

Result<RealtimeReport> setupProcessRealtime(const RealtimeOptions& options,
                                            const RealtimeOps& ops) {
  RealtimeReport report;
  if (options.policy == RealtimePolicy::kOff)
    return report;
  if (kAddressSanitizer) {
    report.warnings.push_back(
        "mlockall skipped: AddressSanitizer's shadow memory cannot be locked");
    return report;
  }
  Error error;
  if (const int err = ops.lock_memory(MCL_CURRENT | MCL_FUTURE); err != 0) {
    if (!refuse(options, report, "mlockall(MCL_CURRENT | MCL_FUTURE) refused: " + errnoText(err),
                error))
      return error;
  } else {
    report.memory_locked = true;
  }
  return report;
}

Result<RealtimeReport> setupServoThreadRealtime(const RealtimeOptions& options,
                                                const RealtimeOps& ops) {
  RealtimeReport report;
  // never more than the thread's stack minus a margin for the frames above and below
  std::size_t prefault = options.stack_prefault_bytes;
  pthread_attr_t attr;
  if (pthread_getattr_np(pthread_self(), &attr) == 0) {
    std::size_t stack_size = 0;
    pthread_attr_getstacksize(&attr, &stack_size);
    pthread_attr_destroy(&attr);
    constexpr std::size_t kMargin = std::size_t{64} * 1024;
    if (stack_size > 0)
      prefault =
          std::min(prefault, stack_size > 2 * kMargin ? stack_size - kMargin : stack_size / 2);
  }
  prefaultStack(prefault);
  if (options.policy == RealtimePolicy::kOff)
    return report;
  Error error;
  if (options.priority < 1 || options.priority > 99)
    return Error{"priority " + std::to_string(options.priority) + " is outside 1..99"};
  // a step done (its flag set), or refused: under "prefer" a warning, under "require" the error
  const auto step = [&](int err, const std::string& what, bool& done) {
    if (err == 0) {
      done = true;
      return true;
    }
    return refuse(options, report, what + ": " + errnoText(err), error);
  };
  if (!step(ops.set_fifo(options.priority),
            "SCHED_FIFO priority " + std::to_string(options.priority) +
                " refused for the servo thread",
            report.fifo))
    return error;
  if (options.cpu >= 0) {
    if (options.cpu >= CPU_SETSIZE)
      return Error{"cpu " + std::to_string(options.cpu) + " is outside 0.." +
                   std::to_string(CPU_SETSIZE - 1)};
    if (!step(ops.pin_to_cpu(options.cpu),
              "pinning the servo thread to CPU " + std::to_string(options.cpu) + " refused",
              report.pinned))
      return error;
  }
  return report;
}

std::string describeThreadScheduling() {
  const int policy = sched_getscheduler(0);
  sched_param param{};
  sched_getparam(0, &param);
  switch (policy & ~SCHED_RESET_ON_FORK) {
    case SCHED_FIFO:
      return "SCHED_FIFO " + std::to_string(param.sched_priority);
    case SCHED_RR:
      return "SCHED_RR " + std::to_string(param.sched_priority);
    case SCHED_OTHER:
      return "SCHED_OTHER";
    default:
      return "policy " + std::to_string(policy);
  }
}

Thread::~Thread() {
  join();
}

void* Thread::trampoline(void* self) {
  auto* t = static_cast<Thread*>(self);
  pthread_setname_np(pthread_self(), t->name_.substr(0, 15).c_str());
  t->body_();
  return nullptr;
}

Result<bool> Thread::start(const char* name, std::size_t stack_bytes, std::function<void()> body) {
  if (started_)
    return Error{std::string("thread ") + name + " already started"};
  body_ = std::move(body);
  name_ = name;
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr,
                            std::max(stack_bytes, static_cast<std::size_t>(PTHREAD_STACK_MIN)));
  // never inherit the creator's policy: every thread but the servo thread runs at normal priority
  pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
  pthread_attr_setschedpolicy(&attr, SCHED_OTHER);
  sched_param param{};
  pthread_attr_setschedparam(&attr, &param);
  pthread_t handle{};
  const int err = pthread_create(&handle, &attr, &Thread::trampoline, this);
  pthread_attr_destroy(&attr);
  if (err != 0)
    return Error{std::string("cannot start thread ") + name + ": " + errnoText(err)};
  handle_ = handle;
  started_ = true;
  return true;
}

void Thread::join() {
  if (!started_)
    return;
  pthread_join(static_cast<pthread_t>(handle_), nullptr);
  started_ = false;
}

}  // namespace hapticd::daemon
