#pragma once
/// \file
/// Writes --record and --record-bodies CSV files from the rows the servo thread hands over
/// through its lock-free rings (ServoLoop::popRecord / popBody). All file I/O happens here, on a
/// normal thread; never on the servo thread. Columns: docs/architecture.md "The interfaces that
/// stay stable" (records) and docs/daemon.md "Running it"; numbers as %.17g so that a record
/// round-trips bit for bit.

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "daemon/realtime.h"
#include "daemon/servo_loop.h"

namespace hapticd::daemon {

class RecordWriter {
 public:
  /// Opens the files (an empty path: not written). Main thread. Error: the file that failed.
  static Result<std::unique_ptr<RecordWriter>> open(ServoLoop& loop,
                                                    const std::string& record_path,
                                                    const std::string& bodies_path);
  ~RecordWriter();

  /// Body names of a scene generation, for the `body` column. Any normal thread.
  void setBodyNames(std::uint64_t generation, std::vector<std::string> names);
  /// Starts the writer thread. Main thread.
  Result<bool> start();
  /// Asks the thread to write what is left and end; joins it; closes the files. Main thread.
  /// Error: a write failed (disk full...).
  Result<bool> finish();

  std::uint64_t rowsWritten() const { return rows_.load(); }

 private:
  RecordWriter(ServoLoop& loop) : loop_(loop) {}
  void run();
  bool drainOnce();

  ServoLoop& loop_;
  std::FILE* record_ = nullptr;
  std::FILE* bodies_ = nullptr;
  std::string record_path_, bodies_path_;
  Thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> rows_{0};
  std::atomic<bool> write_failed_{false};
  std::mutex names_mutex_;
  std::map<std::uint64_t, std::vector<std::string>> names_;
};

}  // namespace hapticd::daemon
