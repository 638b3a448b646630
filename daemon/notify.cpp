#include "daemon/notify.h"

#include <systemd/sd-daemon.h>

namespace hapticd::daemon {

void notifyReady(const std::string& status) {
  sd_notify(0, ("READY=1\nSTATUS=" + status).c_str());
}
void notifyReloading() {
  sd_notify(0, "RELOADING=1");
}
void notifyStopping() {
  sd_notify(0, "STOPPING=1");
}
void notifyStatus(const std::string& status) {
  sd_notify(0, ("STATUS=" + status).c_str());
}
void notifyWatchdog() {
  sd_notify(0, "WATCHDOG=1");
}

std::chrono::microseconds watchdogInterval() {
  uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0)
    return std::chrono::microseconds(usec);
  return std::chrono::microseconds(0);
}

}  // namespace hapticd::daemon
