#include "protocol/command_gate.h"

#include "protocol/wire.h"

namespace hapticd::proto {

const char* gateModeName(GateMode m) {
  static constexpr const char* kNames[] = {"disarmed", "armed", "streaming", "ramping", "faulted"};
  return nameOf(m, kNames);
}

CommandGateCore::SessionSeq& CommandGateCore::sessionEntry(std::uint64_t session_id) noexcept {
  SessionSeq* lru = &sessions_[0];
  for (auto& s : sessions_) {
    if (s.session == session_id && s.last_use != 0) {
      s.last_use = ++use_counter_;
      return s;
    }
    if (s.last_use < lru->last_use)
      lru = &s;
  }
  *lru = SessionSeq{session_id, 0, ++use_counter_};
  return *lru;
}

void CommandGateCore::arm(std::uint64_t session_id, std::uint64_t now_ns) noexcept {
  timeTo(now_ns);
  sessionEntry(session_id);
  controller_ = session_id;
  fault_bits_ = 0;
  has_target_ = false;
  last_command_ns_ = now_ns_;
  mode_ = GateMode::kArmedIdle;
}

void CommandGateCore::disarm(std::uint64_t now_ns) noexcept {
  timeTo(now_ns);
  mode_ = GateMode::kDisarmed;
  has_target_ = false;
}

bool CommandGateCore::submit(std::uint64_t session_id,
                             std::uint64_t sequence,
                             std::uint64_t now_ns) noexcept {
  timeTo(now_ns);
  SessionSeq& s = sessionEntry(session_id);
  if (sequence < s.max_seen) {
    drop(DropReason::kOlder);
    return false;
  }
  if (sequence == s.max_seen) {
    drop(DropReason::kDuplicate);
    return false;
  }
  s.max_seen = sequence;  // newest seen, even when dropped below: later stragglers stay older
  if (mode_ == GateMode::kDisarmed) {
    drop(DropReason::kNotArmed);
    return false;
  }
  if (session_id != controller_) {
    drop(DropReason::kNotController);
    return false;
  }
  if (mode_ == GateMode::kFaulted) {
    drop(DropReason::kFaulted);
    return false;
  }
  has_target_ = true;
  last_sequence_ = sequence;
  last_command_ns_ = now_ns_;
  mode_ = GateMode::kStreaming;
  ++accepted_;
  return true;
}

GateStatus CommandGateCore::update(std::uint64_t now_ns) noexcept {
  timeTo(now_ns);
  if (mode_ == GateMode::kStreaming || mode_ == GateMode::kRamping) {
    const std::uint64_t age = now_ns_ - last_command_ns_;
    if (age >= config_.zero_ns) {
      mode_ = GateMode::kFaulted;
      fault_bits_ |= kFaultStreamLost;
    } else if (age > config_.hold_ns) {
      mode_ = GateMode::kRamping;
    }
  }
  GateStatus out{mode_, has_target_, 0.0, fault_bits_, last_sequence_, 0};
  if (has_target_)
    out.command_age_ns = now_ns_ - last_command_ns_;
  switch (mode_) {
    case GateMode::kDisarmed:
    case GateMode::kFaulted:
      out.force_scale = 0.0;
      break;
    case GateMode::kArmedIdle:
    case GateMode::kStreaming:
      out.force_scale = 1.0;
      break;
    case GateMode::kRamping: {
      const double span = static_cast<double>(config_.zero_ns - config_.hold_ns);
      const double left = static_cast<double>(config_.zero_ns - out.command_age_ns);
      out.force_scale = span > 0.0 ? left / span : 0.0;
      break;
    }
  }
  return out;
}

std::uint64_t CommandGateCore::droppedTotal() const noexcept {
  std::uint64_t n = 0;
  for (auto d : dropped_)
    n += d;
  return n;
}

}  // namespace hapticd::proto
