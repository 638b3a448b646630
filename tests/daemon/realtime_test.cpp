// The real-time setup and its policy: prefer warns and runs where refused, require refuses with a
// clear error, off touches nothing. Refusal is shown twice: through injected system calls, and for
// real in a child process that has RLIMIT_RTPRIO 0 and no CAP_SYS_NICE.
#include "daemon/realtime.h"

#include <gtest/gtest.h>
#include <linux/capability.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <thread>

namespace hapticd::daemon {
namespace {

RealtimeOps refusing(int* calls = nullptr) {
  RealtimeOps ops;
  ops.lock_memory = [calls](int) {
    if (calls)
      ++*calls;
    return ENOMEM;
  };
  ops.set_fifo = [calls](int) {
    if (calls)
      ++*calls;
    return EPERM;
  };
  ops.pin_to_cpu = [calls](int) {
    if (calls)
      ++*calls;
    return EINVAL;
  };
  return ops;
}

TEST(Realtime, PolicyParsesAndRefusesOtherWords) {
  EXPECT_EQ(parseRealtimePolicy("require").value(), RealtimePolicy::kRequire);
  EXPECT_EQ(parseRealtimePolicy("prefer").value(), RealtimePolicy::kPrefer);
  EXPECT_EQ(parseRealtimePolicy("off").value(), RealtimePolicy::kOff);
  auto bad = parseRealtimePolicy("yes");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("\"yes\""), std::string::npos);
}

TEST(Realtime, PreferWarnsForEveryRefusedStepAndRuns) {
  RealtimeOptions o;
  o.policy = RealtimePolicy::kPrefer;
  o.cpu = 0;
  auto p = setupProcessRealtime(o, refusing());
  ASSERT_TRUE(p);
  ASSERT_EQ(p.value().warnings.size(), 1u);
  EXPECT_NE(p.value().warnings[0].find(memoryLockingSupported()
                                           ? "mlockall(MCL_CURRENT | MCL_FUTURE) refused"
                                           : "mlockall skipped"),
            std::string::npos);
  EXPECT_FALSE(p.value().memory_locked);
  auto t = setupServoThreadRealtime(o, refusing());
  ASSERT_TRUE(t);
  EXPECT_FALSE(t.value().fifo);
  EXPECT_FALSE(t.value().pinned);
  ASSERT_EQ(t.value().warnings.size(), 2u);
  EXPECT_NE(t.value().warnings[0].find("SCHED_FIFO priority 80 refused"), std::string::npos);
  EXPECT_NE(t.value().warnings[0].find("errno 1"), std::string::npos);
  EXPECT_NE(t.value().warnings[1].find("CPU 0"), std::string::npos);
}

TEST(Realtime, RequireRefusesWithTheStepAndTheRemedy) {
  RealtimeOptions o;
  o.policy = RealtimePolicy::kRequire;
  auto t = setupServoThreadRealtime(o, refusing());
  ASSERT_FALSE(t);
  EXPECT_NE(t.error().message.find("realtime = \"require\": SCHED_FIFO priority 80 refused"),
            std::string::npos);
  EXPECT_NE(t.error().message.find("LimitRTPRIO"), std::string::npos);
}

TEST(Realtime, OffCallsNothing) {
  int calls = 0;
  RealtimeOptions o;
  o.policy = RealtimePolicy::kOff;
  o.cpu = 1;
  EXPECT_TRUE(setupProcessRealtime(o, refusing(&calls)));
  auto t = setupServoThreadRealtime(o, refusing(&calls));
  ASSERT_TRUE(t);
  EXPECT_TRUE(t.value().warnings.empty());
  EXPECT_EQ(calls, 0);
}

TEST(Realtime, PriorityOutsideTheRangeIsAnError) {
  RealtimeOptions o;
  o.priority = 0;
  EXPECT_FALSE(setupServoThreadRealtime(o, refusing()));
}

// In a child process: RLIMIT_RTPRIO 0 and CAP_SYS_NICE dropped, so the kernel itself refuses
// SCHED_FIFO. Exit code: 0 when prefer ran with a warning and require refused; else a step number.
int childWithoutRealtime() {
  rlimit zero{0, 0};
  if (setrlimit(RLIMIT_RTPRIO, &zero) != 0)
    return 10;
  __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
  __user_cap_data_struct data[2] = {};
  if (syscall(SYS_capget, &header, data) != 0)
    return 11;
  data[CAP_SYS_NICE / 32].effective &= ~(1u << (CAP_SYS_NICE % 32));
  data[CAP_SYS_NICE / 32].permitted &= ~(1u << (CAP_SYS_NICE % 32));
  data[CAP_SYS_NICE / 32].inheritable &= ~(1u << (CAP_SYS_NICE % 32));
  if (syscall(SYS_capset, &header, data) != 0)
    return 12;
  RealtimeOptions o;
  o.policy = RealtimePolicy::kPrefer;
  o.stack_prefault_bytes = 64 * 1024;
  auto prefer = setupServoThreadRealtime(o);
  if (!prefer)
    return 13;
  if (prefer.value().fifo)
    return 14;
  if (prefer.value().warnings.size() != 1)
    return 15;
  if (prefer.value().warnings[0].find("Operation not permitted") == std::string::npos)
    return 16;
  if (describeThreadScheduling() != "SCHED_OTHER")
    return 17;
  o.policy = RealtimePolicy::kRequire;
  auto require = setupServoThreadRealtime(o);
  if (require)
    return 18;
  return 0;
}

TEST(Realtime, KernelRefusalWithoutRtprioOrCapSysNice) {
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0)
    _exit(childWithoutRealtime());
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "failed step (see childWithoutRealtime)";
}

TEST(Realtime, GrantedFifoIsVisibleAndNotInheritedByNormalThreads) {
  // where this machine grants SCHED_FIFO (root here), the servo thread gets it and a Thread
  // started from it still runs at normal priority; where it is refused, prefer runs anyway
  Thread servo;
  std::string servo_sched, child_sched;
  bool fifo = false;
  ASSERT_TRUE(servo
                  .start("rt-test", 256 * 1024,
                         [&] {
                           RealtimeOptions o;
                           o.priority = 10;
                           o.cpu = 0;
                           auto r = setupServoThreadRealtime(o);
                           fifo = r && r.value().fifo;
                           servo_sched = describeThreadScheduling();
                           Thread normal;
                           (void)normal.start("rt-child", 128 * 1024,
                                              [&] { child_sched = describeThreadScheduling(); });
                           normal.join();
                         })
                  .ok());
  servo.join();
  if (fifo) {
    EXPECT_EQ(servo_sched, "SCHED_FIFO 10");
  } else {
    EXPECT_EQ(servo_sched, "SCHED_OTHER");
  }
  EXPECT_EQ(child_sched, "SCHED_OTHER");
}

}  // namespace
}  // namespace hapticd::daemon
