#pragma once
/// \file
/// systemd service notification (sd_notify through libsystemd): READY=1 once the servo loop
/// runs, WATCHDOG=1 while it is healthy, RELOADING=1 / STOPPING=1, STATUS=. Outside systemd
/// (no NOTIFY_SOCKET) every call does nothing. Main thread.

#include <chrono>
#include <string>

namespace hapticd::daemon {

void notifyReady(const std::string& status);
void notifyReloading();
void notifyStopping();
void notifyStatus(const std::string& status);
void notifyWatchdog();
/// The watchdog interval systemd asks for (WatchdogSec), or zero when there is none.
std::chrono::microseconds watchdogInterval();

}  // namespace hapticd::daemon
