#pragma once
/// \file
/// The canonical byte stream of a simulation state (core/sim/scene_state.h): each class that
/// holds per-tick state writes its fields through a StateWriter in a fixed order, field by field
/// (never a struct's raw bytes: padding is not state), numbers by their bits. Two sinks: a
/// 64-bit hash (StateHash) and the bytes themselves (StateBytes, for an exact comparison).
/// Any thread; StateHash allocates nothing, StateBytes does.

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace hapticd {

/// Where a state's fields go. The helpers write fixed-width values, so that the stream is the
/// same on every run and in every process of one platform (little-endian, IEEE 754 doubles).
class StateWriter {
 public:
  virtual ~StateWriter() = default;
  /// The raw bytes; the helpers below are the only callers.
  virtual void bytes(const void* data, std::size_t n) = 0;

  void u64(std::uint64_t v) { bytes(&v, sizeof v); }
  void i64(std::int64_t v) { bytes(&v, sizeof v); }
  void f64(double v) { bytes(&v, sizeof v); }
  void flag(bool v) { u64(v ? 1u : 0u); }
  /// An enum or any integer, widened to 64 bits.
  template <class E>
  void integer(E v) {
    static_assert(std::is_integral_v<E> || std::is_enum_v<E>);
    if constexpr (std::is_enum_v<E>)
      i64(static_cast<std::int64_t>(v));
    else if constexpr (std::is_signed_v<E>)
      i64(v);
    else
      u64(v);
  }
  /// An array of integers or doubles: its length, then its elements as they are in memory.
  template <class T>
  void array(const T* data, std::size_t n) {
    static_assert(std::is_arithmetic_v<T>);
    u64(n);
    bytes(data, n * sizeof(T));
  }
  /// The same for a container with data() and size() (std::vector, std::array).
  template <class C>
  void array(const C& c) {
    array(c.data(), c.size());
  }
  /// A GLM vector, quaternion or matrix of doubles (contiguous, no padding).
  template <class G>
  void glm(const G& v) {
    static_assert(sizeof(G) % sizeof(double) == 0 && std::is_trivially_copyable_v<G>);
    bytes(&v, sizeof(G));
  }
};

/// FNV-1a over the stream in 64-bit words (bytes for a tail): a stable 64-bit hash. No
/// allocation.
class StateHash final : public StateWriter {
 public:
  void bytes(const void* data, std::size_t n) override {
    const auto* p = static_cast<const unsigned char*>(data);
    for (; n >= 8; n -= 8, p += 8) {
      std::uint64_t w;
      std::memcpy(&w, p, 8);
      h_ = (h_ ^ w) * kPrime;
    }
    for (; n > 0; --n, ++p)
      h_ = (h_ ^ *p) * kPrime;
  }
  std::uint64_t digest() const { return h_; }

 private:
  static constexpr std::uint64_t kPrime = 1099511628211ull;
  std::uint64_t h_ = 14695981039346656037ull;
};

/// The stream's bytes, for comparing two states exactly. Allocates.
class StateBytes final : public StateWriter {
 public:
  void bytes(const void* data, std::size_t n) override {
    const auto* p = static_cast<const unsigned char*>(data);
    data_.insert(data_.end(), p, p + n);
  }
  const std::vector<unsigned char>& data() const { return data_; }

 private:
  std::vector<unsigned char> data_;
};

}  // namespace hapticd
