#pragma once
// Counts the allocations made by the calling thread. A test executable that links
// tests/core/alloc_counter.cpp gets a global operator new that counts; used to prove that
// per-tick code allocates nothing after warm-up.
#include <cstdint>

namespace testing_alloc {
std::uint64_t count();
}  // namespace testing_alloc
