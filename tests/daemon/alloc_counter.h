#pragma once
// Counts heap allocations per thread. A test executable that links tests/daemon/alloc_counter.cpp
// gets a global operator new (every form) that bumps a thread-local counter, so a test can read
// the servo thread's own count before and after its loop.
#include <cstdint>

namespace hapticd::testing {
/// Allocations made so far by the calling thread.
std::uint64_t threadAllocations();
}  // namespace hapticd::testing
