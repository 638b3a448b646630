#pragma once
/// \file
/// The hand-off of a new scene pipeline to the servo thread: built on a normal thread, offered
/// by an atomic pointer exchange, taken by the servo thread at a tick boundary; the one it
/// replaces is handed back the same way and freed on a normal thread. Nothing is ever freed or
/// allocated on the servo thread.
///
/// Threads: offer() and reclaim() on one normal thread (the owner); take() on the servo thread.

#include <atomic>
#include <memory>

namespace hapticd::daemon {

template <class T>
class PointerExchange {
 public:
  PointerExchange() = default;
  PointerExchange(const PointerExchange&) = delete;
  PointerExchange& operator=(const PointerExchange&) = delete;
  ~PointerExchange() {
    delete pending_.exchange(nullptr);
    delete retired_.exchange(nullptr);
  }

  /// Owner thread. Offers `next`; an earlier offer the servo thread has not taken yet is freed.
  void offer(std::unique_ptr<T> next) { delete pending_.exchange(next.release()); }

  /// Servo thread, at a tick boundary. When an offer waits and the previous retiree has been
  /// reclaimed: `current` becomes the offered one and the old one goes back to the owner;
  /// returns true. Otherwise leaves `current` alone and returns false. Never allocates or frees.
  bool take(T*& current) noexcept {
    if (pending_.load(std::memory_order_acquire) == nullptr)
      return false;
    if (retired_.load(std::memory_order_acquire) != nullptr)
      return false;
    T* next = pending_.exchange(nullptr, std::memory_order_acq_rel);
    if (next == nullptr)
      return false;
    retired_.store(current, std::memory_order_release);
    current = next;
    return true;
  }

  /// Owner thread. Frees what the servo thread handed back (if anything).
  void reclaim() { delete retired_.exchange(nullptr, std::memory_order_acq_rel); }

  /// Owner thread: an offer is still waiting.
  bool pending() const { return pending_.load(std::memory_order_acquire) != nullptr; }

 private:
  std::atomic<T*> pending_{nullptr};
  std::atomic<T*> retired_{nullptr};
};

}  // namespace hapticd::daemon
