#pragma once
/// \file
/// An open-addressing hash map from 64-bit keys to 32-bit values (linear probing, backward-shift
/// deletion, load at most 1/2). Allocates only when it grows past the largest size it has held
/// (reserve() sets that in advance). Single-threaded.

#include <cstdint>
#include <vector>

namespace hapticd {

class FlatMap {
 public:
  static constexpr std::uint32_t kNone = 0xffffffffu;

  /// The value stored for `key`, or kNone.
  std::uint32_t find(std::uint64_t key) const {
    if (keys_.empty())
      return kNone;
    const std::size_t s = slot(key + 1);
    return keys_[s] == key + 1 ? values_[s] : kNone;
  }
  /// Inserts or overwrites.
  void insert(std::uint64_t key, std::uint32_t value) {
    if ((size_ + 1) * 2 > keys_.size())
      grow(keys_.size() * 2);
    const std::size_t s = slot(key + 1);
    if (keys_[s] == 0)
      ++size_;
    keys_[s] = key + 1;
    values_[s] = value;
  }
  /// Removes `key` if present; returns whether it was.
  bool erase(std::uint64_t key) {
    if (keys_.empty())
      return false;
    const std::size_t mask = keys_.size() - 1;
    std::size_t hole = slot(key + 1);
    if (keys_[hole] != key + 1)
      return false;
    for (std::size_t next = (hole + 1) & mask; keys_[next] != 0; next = (next + 1) & mask) {
      const std::size_t home = hash(keys_[next], mask);
      if (((next - home) & mask) >= ((next - hole) & mask)) {
        keys_[hole] = keys_[next];
        values_[hole] = values_[next];
        hole = next;
      }
    }
    keys_[hole] = 0;
    --size_;
    return true;
  }
  void reserve(std::size_t n) {
    std::size_t cap = 64;
    while (cap < 2 * n)
      cap *= 2;
    if (cap > keys_.size())
      grow(cap);
  }
  std::size_t size() const { return size_; }

 private:
  static std::size_t hash(std::uint64_t k, std::size_t mask) {
    return static_cast<std::size_t>((k * 0x9E3779B97F4A7C15ull) >> 20) & mask;
  }
  std::size_t slot(std::uint64_t stored) const {
    const std::size_t mask = keys_.size() - 1;
    std::size_t s = hash(stored, mask);
    while (keys_[s] != 0 && keys_[s] != stored)
      s = (s + 1) & mask;
    return s;
  }
  void grow(std::size_t capacity) {
    if (capacity < 64)
      capacity = 64;
    std::vector<std::uint64_t> old_keys(capacity, 0);
    std::vector<std::uint32_t> old_values(capacity, 0);
    old_keys.swap(keys_);
    old_values.swap(values_);
    size_ = 0;
    for (std::size_t i = 0; i < old_keys.size(); ++i) {
      if (old_keys[i] == 0)
        continue;
      const std::size_t s = slot(old_keys[i]);
      keys_[s] = old_keys[i];
      values_[s] = old_values[i];
      ++size_;
    }
  }

  std::vector<std::uint64_t> keys_;  // 0 = empty, else key + 1
  std::vector<std::uint32_t> values_;
  std::size_t size_ = 0;
};

}  // namespace hapticd
