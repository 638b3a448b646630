#pragma once
// Counts heap allocations per thread (tests/core/alloc_counter.cpp, which a test executable links),
// under the name the daemon's tests use: a test reads the servo thread's own count before and
// after its loop.
#include <cstdint>

#include "tests/core/alloc_counter.h"

namespace hapticd::testing {
/// Allocations made so far by the calling thread.
inline std::uint64_t threadAllocations() {
  return testing_alloc::count();
}
}  // namespace hapticd::testing
