#pragma once
/// \file
/// The daemon's log: one line per message on stderr, with the syslog priority prefix ("<4>")
/// that journald reads when stderr is the journal (JOURNAL_STREAM set), else "hapticd: warning: ".
/// Threads: any normal thread (a mutex orders lines); never the servo thread, whose events go
/// through ServoLoop::popEvent() to a normal thread.

#include <string>

#include "daemon/config.h"

namespace hapticd::daemon {

void setLogLevel(LogLevel level);
void logLine(LogLevel level, const std::string& message);
inline void logError(const std::string& m) {
  logLine(LogLevel::kError, m);
}
inline void logWarning(const std::string& m) {
  logLine(LogLevel::kWarning, m);
}
inline void logInfo(const std::string& m) {
  logLine(LogLevel::kInfo, m);
}
inline void logDebug(const std::string& m) {
  logLine(LogLevel::kDebug, m);
}

}  // namespace hapticd::daemon
