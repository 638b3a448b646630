#include "daemon/log.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>

namespace hapticd::daemon {
namespace {
std::atomic<LogLevel> g_level{LogLevel::kInfo};
std::mutex g_mutex;
}  // namespace

void setLogLevel(LogLevel level) {
  g_level.store(level);
}

void logLine(LogLevel level, const std::string& message) {
  if (static_cast<int>(level) > static_cast<int>(g_level.load()))
    return;
  static const bool journal = std::getenv("JOURNAL_STREAM") != nullptr;
  // syslog priorities: 3 error, 4 warning, 6 info, 7 debug
  static const int kPriority[] = {3, 4, 6, 7};
  std::lock_guard<std::mutex> lock(g_mutex);
  if (journal)
    std::fprintf(stderr, "<%d>%s\n", kPriority[static_cast<int>(level)], message.c_str());
  else
    std::fprintf(stderr, "hapticd: %s: %s\n", toString(level), message.c_str());
  std::fflush(stderr);
}

}  // namespace hapticd::daemon
