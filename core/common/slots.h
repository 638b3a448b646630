#pragma once
/// \file
/// Slot reuse for index-addressed pools: a freed index is handed out again before the pool grows.

#include <cstdint>
#include <vector>

namespace hapticd {

/// An index into `items` for a new element: the last freed one, else a new default element at the
/// end (the only case that may allocate).
template <class T>
std::uint32_t takeSlot(std::vector<T>& items, std::vector<std::uint32_t>& free_slots) {
  if (!free_slots.empty()) {
    const std::uint32_t i = free_slots.back();
    free_slots.pop_back();
    items[i] = T{};
    return i;
  }
  items.emplace_back();
  return static_cast<std::uint32_t>(items.size() - 1);
}

}  // namespace hapticd
