#pragma once
/// \file
/// Puts the states of a stream back in tick order and counts the ticks that never came (lost
/// datagrams, or a state rate below the tick rate), for `hapticctl record`. A small window of
/// states is held back so that a datagram overtaken by a few later ones still lands in its
/// place; a duplicate, or a state older than one already written, is dropped and counted.
/// One thread (the caller's).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>

#include "protocol/messages.h"

namespace hapticd::client {

class TickOrder {
 public:
  using Emit = std::function<void(const proto::State&)>;

  /// `window`: states held back before the oldest is written (≥ 1).
  explicit TickOrder(Emit emit, std::size_t window = 64)
      : emit_(std::move(emit)), window_(window == 0 ? 1 : window) {}

  /// Offers a state. Returns false (and counts it) when it is a duplicate or older than a state
  /// already written.
  bool push(const proto::State& s) {
    if ((any_ && s.tick <= last_) || held_.count(s.tick) != 0) {
      if (any_ && s.tick < last_ && held_.count(s.tick) == 0)
        ++late_;
      else
        ++duplicates_;
      return false;
    }
    held_.emplace(s.tick, s);
    while (held_.size() > window_)
      emitOldest();
    return true;
  }
  /// Writes every state still held.
  void flush() {
    while (!held_.empty())
      emitOldest();
  }

  std::uint64_t written() const { return written_; }
  /// Ticks between the first and the last written that were not written.
  std::uint64_t missing() const { return missing_; }
  std::uint64_t duplicates() const { return duplicates_; }
  /// States that came after a later tick had been written (their tick stays missing).
  std::uint64_t late() const { return late_; }
  std::uint64_t firstTick() const { return first_; }
  std::uint64_t lastTick() const { return last_; }

 private:
  void emitOldest() {
    auto it = held_.begin();
    if (any_)
      missing_ += it->first - last_ - 1;
    else
      first_ = it->first;
    any_ = true;
    last_ = it->first;
    emit_(it->second);
    ++written_;
    held_.erase(it);
  }

  Emit emit_;
  std::size_t window_;
  std::map<std::uint64_t, proto::State> held_;
  bool any_ = false;
  std::uint64_t first_ = 0;
  std::uint64_t last_ = 0;
  std::uint64_t written_ = 0;
  std::uint64_t missing_ = 0;
  std::uint64_t duplicates_ = 0;
  std::uint64_t late_ = 0;
};

}  // namespace hapticd::client
