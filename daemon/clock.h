#pragma once
/// \file
/// The servo loop's time source. The loop paces itself by sleepUntilNs() and reads nowNs() to
/// measure lateness and overruns, so the same loop runs on the real monotonic clock, on a virtual
/// clock (ticks back to back on simulated time: headless replay, CI), or on a scripted test clock.
///
/// Threads: a Clock is used by the servo thread only (after construction).

#include <cstdint>
#include <utility>
#include <vector>

namespace hapticd::daemon {

class Clock {
 public:
  virtual ~Clock() = default;
  /// Now, in nanoseconds on this clock's time line. Servo thread; never allocates.
  virtual std::int64_t nowNs() noexcept = 0;
  /// Returns at or after `deadline_ns` (TIMER_ABSTIME semantics: a past deadline returns at once).
  /// Servo thread; never allocates.
  virtual void sleepUntilNs(std::int64_t deadline_ns) noexcept = 0;
  /// True when time only advances by sleeping (no real waiting).
  virtual bool isVirtual() const noexcept { return false; }
};

/// CLOCK_MONOTONIC, slept on with clock_nanosleep(TIMER_ABSTIME) (EINTR resumes the same sleep).
class MonotonicClock final : public Clock {
 public:
  std::int64_t nowNs() noexcept override;
  void sleepUntilNs(std::int64_t deadline_ns) noexcept override;
};

/// The clock of a device that owns it (device::Device::ownsClock(), openhaptics): the device's
/// scheduler paces the ticks, so sleeping returns at once; now is CLOCK_MONOTONIC, so lateness
/// and overruns are measured against the nominal period as on the daemon's own clock.
class DeviceClock final : public Clock {
 public:
  std::int64_t nowNs() noexcept override { return monotonic_.nowNs(); }
  void sleepUntilNs(std::int64_t /*deadline_ns*/) noexcept override {}

 private:
  MonotonicClock monotonic_;
};

/// Simulated time: starts at 0, jumps to each deadline at once.
class VirtualClock final : public Clock {
 public:
  std::int64_t nowNs() noexcept override { return now_ns_; }
  void sleepUntilNs(std::int64_t deadline_ns) noexcept override {
    if (deadline_ns > now_ns_)
      now_ns_ = deadline_ns;
  }
  bool isVirtual() const noexcept override { return true; }

 private:
  std::int64_t now_ns_ = 0;
};

/// A test clock on virtual time whose chosen ticks overrun. The loop reads the clock twice per
/// tick, at its wake-up and at its end; this clock charges script entry i (ns) to tick i's end
/// reading (past the script: `fallback_ns`), so a test decides each tick's compute time.
class ScriptedClock final : public Clock {
 public:
  /// Off the servo thread (allocates).
  explicit ScriptedClock(std::vector<std::int64_t> compute_ns, std::int64_t fallback_ns = 0)
      : script_(std::move(compute_ns)), fallback_ns_(fallback_ns) {}

  std::int64_t nowNs() noexcept override {
    if (phase_ == Phase::kWake) {
      phase_ = Phase::kEnd;
    } else if (phase_ == Phase::kEnd) {
      now_ns_ += tick_ < script_.size() ? script_[tick_] : fallback_ns_;
      ++tick_;
      phase_ = Phase::kIdle;
    }
    return now_ns_;
  }
  void sleepUntilNs(std::int64_t deadline_ns) noexcept override {
    if (deadline_ns > now_ns_)
      now_ns_ = deadline_ns;
    phase_ = Phase::kWake;
  }
  bool isVirtual() const noexcept override { return true; }
  /// Ticks charged so far.
  std::size_t ticks() const noexcept { return tick_; }

 private:
  enum class Phase { kIdle, kWake, kEnd };
  std::vector<std::int64_t> script_;
  std::int64_t fallback_ns_;
  std::int64_t now_ns_ = 0;
  std::size_t tick_ = 0;
  Phase phase_ = Phase::kIdle;
};

}  // namespace hapticd::daemon
