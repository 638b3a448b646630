#pragma once
// Counts the allocations made by the calling thread. A test executable that links
// tests/core/alloc_counter.cpp gets a global operator new (every form: plain, array, nothrow,
// aligned) that bumps a thread-local counter; used to prove that per-tick code allocates nothing
// after warm-up.
#include <cstdint>

namespace testing_alloc {
/// Allocations made so far by the calling thread.
std::uint64_t count();
}  // namespace testing_alloc
