#pragma once
/// \file
/// A std::vector whose copies keep its reserved capacity. The per-tick buffers of the simulation
/// state are reserved once, at create(), so that a tick never allocates; a plain vector's copy
/// has only room for its elements, so a copied state would allocate on its first ticks. Copies
/// are made off the servo thread (they allocate); moves keep the buffer as std::vector's do.

#include <vector>

namespace hapticd {

template <class T>
class ReservedVector : public std::vector<T> {
 public:
  using std::vector<T>::vector;
  ReservedVector() = default;
  ReservedVector(const ReservedVector& other) : std::vector<T>() { copyFrom(other); }
  ReservedVector(ReservedVector&&) noexcept = default;
  ReservedVector& operator=(const ReservedVector& other) {
    if (this != &other)
      copyFrom(other);
    return *this;
  }
  ReservedVector& operator=(ReservedVector&&) noexcept = default;
  ~ReservedVector() = default;

 private:
  void copyFrom(const ReservedVector& other) {
    this->clear();
    this->reserve(other.capacity());
    this->insert(this->end(), other.begin(), other.end());
  }
};

}  // namespace hapticd
