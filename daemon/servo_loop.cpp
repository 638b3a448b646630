#include "daemon/servo_loop.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <ctime>
#include <string>
#include <thread>

#include "core/geometry/rotation.h"
#include "core/sim/output_shaping.h"

namespace hapticd::daemon {
namespace {

std::int64_t realNowNs() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// the one output stage's limits and times: the tighter device limits, the step limits, the
// ramp-in and the fades; its tick is the loop's period
response::OutputLimits outputLimits(const ServoOptions& o, double period_s) noexcept {
  return {.max_force_n = o.limits.max_force_n,
          .max_torque_nm = o.limits.max_torque_nm,
          .max_force_step_n = o.max_force_step_n,
          .max_torque_step_nm = o.max_torque_step_nm,
          .ramp_s = o.ramp_in_s,
          .fault_fade_s = o.fault_fade_s,
          .hold_fade_s = o.stop_ramp_s,
          .tick_s = period_s};
}

void putPose(const geom::Pose& X, double* out) noexcept {
  out[0] = X.translation.x;
  out[1] = X.translation.y;
  out[2] = X.translation.z;
  out[3] = X.rotation.x;
  out[4] = X.rotation.y;
  out[5] = X.rotation.z;
  out[6] = X.rotation.w;
}

const char* editListName(std::int64_t list) {
  return list == 0 ? "poses" : list == 1 ? "added" : "removed";
}

}  // namespace

ServoCommand gatedCommand(CommandKind kind,
                          std::uint64_t session_id,
                          std::uint64_t sequence,
                          const proto::PoseCommand& p) noexcept {
  ServoCommand c;
  c.kind = kind;
  c.gated = true;
  c.session_id = session_id;
  c.sequence = sequence;
  if (kind == CommandKind::kPose) {
    c.pose.X_W_target = geom::Pose::fromXyzw(geom::Vec3(p.X_WT.p[0], p.X_WT.p[1], p.X_WT.p[2]),
                                             p.X_WT.q[0], p.X_WT.q[1], p.X_WT.q[2], p.X_WT.q[3]);
    c.pose.linear_velocity = geom::Vec3(p.v_W[0], p.v_W[1], p.v_W[2]);
    c.pose.angular_velocity = geom::Vec3(p.w_W[0], p.w_W[1], p.w_W[2]);
    c.pose.buttons = p.buttons;
  }
  return c;
}

std::uint32_t wireStateFlags(const ServoState& st) noexcept {
  std::uint32_t w = st.armed ? proto::kStateArmed : 0u;
  const auto mode = static_cast<proto::GateMode>(st.gate_mode);
  if (mode == proto::GateMode::kStreaming)
    w |= proto::kStateStreaming;
  if (mode == proto::GateMode::kRamping)
    w |= proto::kStateRamping;
  return w;
}

ServoLoop::ServoLoop(const ServoOptions& options,
                     Clock& clock,
                     device::Device& device,
                     std::unique_ptr<ServoScene> initial_scene)
    : options_(options),
      clock_(clock),
      device_(device),
      period_ns_(std::max<std::int64_t>(1, std::llround(1e9 / options.rate_hz))),
      period_s_(static_cast<double>(period_ns_) / 1e9),
      commands_(options.command_capacity),
      edits_(options.edit_capacity),
      events_(options.log_capacity),
      records_(options.record ? options.record_capacity : 2),
      bodies_(options.record_bodies ? options.body_capacity : 2),
      current_(initial_scene.release()),
      output_(outputLimits(options, period_s_), options.armed_at_start),
      output_frame_(options.workspace.outputFrame()) {
  s_.armed = options_.armed_at_start;
  s_.output_gain = output_.fadeGain();
  s_.device_connected = true;
  s_.scene_generation = current_ != nullptr ? current_->generation : 0;
  state_.write(s_);
  lists_.write(l_);
}

ServoLoop::~ServoLoop() {
  delete current_;
}

void ServoLoop::emit(ServoEventKind kind, std::int64_t a, std::int64_t b, std::int64_t c) noexcept {
  if (!events_.push(ServoEvent{kind, s_.tick, a, b, c}))
    ++s_.log_dropped;
}

void ServoLoop::drainCommands(std::uint64_t now_ns) noexcept {
  ServoCommand cmd;
  // bounded: at most one ring's worth per tick
  for (std::size_t i = 0; i < commands_.capacity() && commands_.pop(cmd); ++i)
    applyCommand(cmd, now_ns);
}

void ServoLoop::drainShm(std::uint64_t now_ns) noexcept {
  if (shm_ == nullptr)
    return;
  proto::ShmCommandEvent e;
  // bounded: at most one segment ring's worth per tick
  for (std::uint32_t i = 0; i < proto::kShmRingSlots && shm_->popCommand(e); ++i) {
    // the same gate as the network's commands: newest wins, stream-stop fault
    const CommandKind kind = e.kind == proto::ShmCommandEvent::Kind::kArm ? CommandKind::kArm
                             : e.kind == proto::ShmCommandEvent::Kind::kDisarm
                                 ? CommandKind::kDisarm
                                 : CommandKind::kPose;
    const ServoCommand c = gatedCommand(kind, e.session_id, e.sequence, e.pose);
    ++s_.shm_commands;
    applyCommand(c, now_ns);
  }
}

void ServoLoop::applyEdits() noexcept {
  // bounded: at most one ring's worth per tick; every batch whole at this one boundary
  for (std::size_t i = 0; i < edits_.capacity(); ++i) {
    const EditBatch* b = edits_.front();
    if (b == nullptr)
      return;
    const std::uint64_t running = current_ != nullptr ? current_->generation : 0;
    if (current_ == nullptr || b->generation != running) {
      // validated against a scene offered but not taken yet (the swap waits for the owner's
      // reclaim): it waits for that swap. Any other generation is gone: dropped, counted.
      if (current_ != nullptr && b->generation > running && scenes_.pending())
        return;
      ++s_.edit_batches_dropped;
      emit(ServoEventKind::kEditBatchDropped, static_cast<std::int64_t>(b->generation),
           static_cast<std::int64_t>(running), static_cast<std::int64_t>(b->id));
      edits_.dropFront();
      continue;
    }
    sim::Simulation& sim = *current_->sim;
    auto count = [&](sim::EditStatus st, std::uint32_t body, std::int64_t list) {
      if (st == sim::EditStatus::kOk) {
        ++s_.edits_applied;
        return;
      }
      ++s_.edits_refused;
      emit(ServoEventKind::kEditRefused, body, static_cast<std::int64_t>(st), list);
    };
    const std::uint32_t nr = std::min<std::uint32_t>(b->remove_count, kMaxEditEntries);
    const std::uint32_t na = std::min<std::uint32_t>(b->add_count, kMaxEditEntries);
    const std::uint32_t np = std::min<std::uint32_t>(b->pose_count, kMaxEditEntries);
    for (std::uint32_t k = 0; k < nr; ++k)
      count(sim.setBodyActive(b->removed[k], false, geom::Pose{}), b->removed[k], 2);
    for (std::uint32_t k = 0; k < na; ++k)
      count(sim.setBodyActive(b->added[k].body, true, b->added[k].X_WB), b->added[k].body, 1);
    for (std::uint32_t k = 0; k < np; ++k)
      count(sim.setKinematicPose(b->poses[k].body, b->poses[k].X_WB), b->poses[k].body, 0);
    ++s_.edit_batches_applied;
    edits_.dropFront();
  }
}

void ServoLoop::publishLists() noexcept {
  l_.tick = s_.tick;
  l_.scene_generation = s_.scene_generation;
  l_.body_count = l_.bodies_total = l_.contact_count = l_.contacts_total = 0;
  if (current_ != nullptr) {
    const auto poses = current_->sim->bodyPoses();
    const auto contacts = current_->sim->contactPoints();
    // active bodies only: bodyPoses() keeps an inactive body at its last pose, and a client
    // reading the list should not draw a body that was removed
    for (const sim::BodyPose& b : poses) {
      if (!current_->sim->bodyActive(b.body))
        continue;
      if (l_.body_count < kListBodies)
        l_.bodies[l_.body_count++] = b;
      ++l_.bodies_total;
    }
    l_.contacts_total = static_cast<std::uint32_t>(contacts.size());
    l_.contact_count = static_cast<std::uint32_t>(std::min(contacts.size(), kListContacts));
    std::copy_n(contacts.begin(), l_.contact_count, l_.contacts.begin());
  }
  // only what is used: the counts, the used bodies, the used contacts
  using Range = Seqlock<ServoLists>::Range;
  const Range ranges[3] = {
      {0, offsetof(ServoLists, bodies)},
      {offsetof(ServoLists, bodies), l_.body_count * sizeof(sim::BodyPose)},
      {offsetof(ServoLists, contacts), l_.contact_count * sizeof(sim::ContactPoint)}};
  lists_.writeRanges(l_, ranges, 3);
}

void ServoLoop::publishShm(std::int64_t now_real_ns) noexcept {
  if (shm_ == nullptr)
    return;
  proto::ShmState& m = shm_state_;
  m.tick = s_.tick;
  m.sim_time_ns =
      static_cast<std::uint64_t>(s_.period_index) * static_cast<std::uint64_t>(period_ns_);
  m.publish_ns = static_cast<std::uint64_t>(now_real_ns);
  putPose(s_.X_W_device, m.X_WD);
  putPose(s_.X_W_proxy, m.X_WP);
  m.force_n[0] = s_.force_W_n.x;
  m.force_n[1] = s_.force_W_n.y;
  m.force_n[2] = s_.force_W_n.z;
  m.torque_nm[0] = s_.torque_W_nm.x;
  m.torque_nm[1] = s_.torque_W_nm.y;
  m.torque_nm[2] = s_.torque_W_nm.z;
  m.force_scale = std::clamp(s_.output_gain * s_.gate_scale, 0.0, 1.0);
  m.last_command_sequence = s_.last_command_sequence;
  m.tick_misses = s_.overruns;
  if (s_.tick % kShmPercentileEveryTicks == 1) {
    shm_p50_ns_ = static_cast<std::uint64_t>(std::max<std::int64_t>(0, compute_.quantileNs(0.5)));
    shm_p99_ns_ = static_cast<std::uint64_t>(std::max<std::int64_t>(0, compute_.quantileNs(0.99)));
  }
  m.tick_p50_ns = shm_p50_ns_;
  m.tick_p99_ns = shm_p99_ns_;
  m.tick_max_ns = static_cast<std::uint64_t>(std::max<std::int64_t>(0, compute_.maxNs()));
  m.fault_bits = s_.faults;
  m.state_flags = wireStateFlags(s_);
  m.contact_count = s_.contacts;
  m.pairs_tested = s_.pairs_tested;  // layout minor 1
  m.pairs_skipped = s_.pairs_skipped;
  m.max_penetration_m =
      std::isfinite(s_.max_penetration_m) ? std::max(0.0, s_.max_penetration_m) : 0.0;
  m.tick_ns = static_cast<std::uint64_t>(std::max<std::int64_t>(0, s_.last_tick_ns));
  const std::size_t n = std::min<std::size_t>(l_.body_count, proto::kShmBodies);
  m.body_count = n;
  for (std::size_t i = 0; i < n; ++i) {
    m.bodies[i].index = l_.bodies[i].body;
    putPose(l_.bodies[i].X_WB, m.bodies[i].X_WB);
  }
  shm_->publish(m);
  shm_->beat(static_cast<std::uint64_t>(now_real_ns));
}

void ServoLoop::applyCommand(const ServoCommand& cmd, std::uint64_t now_ns) noexcept {
  if (cmd.gated) {
    gate_used_ = true;
    if (cmd.kind == CommandKind::kPose) {
      (void)gate_.submit(cmd.session_id, cmd.sequence, cmd.pose, now_ns);
      return;  // the gate hands the newest to the device in applyGate()
    }
    if (cmd.kind == CommandKind::kArm)
      gate_.arm(cmd.session_id, now_ns);
    else
      gate_.disarm(now_ns);
  } else {
    s_.last_command_sequence = cmd.sequence;
  }
  switch (cmd.kind) {
    case CommandKind::kPose:
      commandDevice(cmd.pose);
      break;
    case CommandKind::kArm:
      s_.faults = 0;
      s_.consecutive_misses = 0;
      s_.armed = true;
      output_.rearm();  // the fade back to 1, the force ramps in from zero
      s_.output_gain = output_.fadeGain();
      s_.ramp_restarts = output_.rampRestarts();
      emit(ServoEventKind::kArmed);
      break;
    case CommandKind::kDisarm:
      if (s_.armed)
        emit(ServoEventKind::kDisarmed);
      s_.armed = false;
      break;
  }
}

void ServoLoop::applyGate(std::uint64_t now_ns) noexcept {
  if (!gate_used_) {
    s_.gate_scale = 1.0;
    return;
  }
  const auto g = gate_.update(now_ns);
  s_.gate_mode = static_cast<std::uint8_t>(g.mode);
  s_.commands_accepted = gate_.accepted();
  s_.commands_dropped = gate_.droppedTotal();
  if (g.last_sequence != 0)
    s_.last_command_sequence = g.last_sequence;
  if (g.has_target &&
      (g.mode == proto::GateMode::kStreaming || g.mode == proto::GateMode::kRamping))
    commandDevice(g.target);
  // a disarmed gate (never armed by a client, or disarmed) leaves the servo's own arm state in
  // charge; an armed gate scales the force by its ramp
  s_.gate_scale = g.mode == proto::GateMode::kDisarmed ? 1.0 : g.force_scale;
  if ((g.fault_bits & proto::kFaultStreamLost) != 0 && latch(kFaultStreamLost))
    emit(ServoEventKind::kStreamLost);
}

void ServoLoop::commandDevice(const device::PoseCommand& c_W) noexcept {
  device::PoseCommand c = c_W;
  c.X_W_target = options_.workspace.toDevice(c_W.X_W_target);
  c.linear_velocity = options_.workspace.velocityToDevice(c_W.linear_velocity);
  c.angular_velocity = options_.workspace.angularToDevice(c_W.angular_velocity);
  device_.command(c);
}

bool ServoLoop::latch(std::uint32_t fault) noexcept {
  if ((s_.faults & fault) != 0)
    return false;
  s_.faults |= fault;
  s_.faults_seen |= fault;
  ++s_.fault_latches;
  return true;
}

void ServoLoop::takeInputs(std::uint64_t now_ns) noexcept {
  drainCommands(now_ns);
  drainShm(now_ns);
  applyGate(now_ns);
  if (stop_requested_.load(std::memory_order_acquire) && !s_.stopping)
    s_.stopping = true;
  if (scenes_.take(current_)) {
    current_->sim->prepareThread();
    if (current_->X_D_home)
      device_.setHome(*current_->X_D_home);  // the sim hand moves around the new scene's start
    s_.scene_generation = current_->generation;
    emit(ServoEventKind::kSceneSwapped, static_cast<std::int64_t>(current_->generation));
  }
  applyEdits();  // after the swap: a batch validated against the new scene meets it
}

device::DeviceStatus ServoLoop::readDevice(double t_s, device::DeviceSample& sample) noexcept {
  const device::DeviceStatus status = device_.read(t_s, sample);
  if (status == device::DeviceStatus::kEndOfStream)
    return status;
  // a device fault: connected (the sample is its last good one), the device fault latched
  const bool connected =
      status == device::DeviceStatus::kOk || status == device::DeviceStatus::kFault;
  if (status == device::DeviceStatus::kFault && latch(kFaultDevice))
    emit(ServoEventKind::kDeviceFault);
  if (!connected && status == device::DeviceStatus::kLost && s_.device_connected) {
    ++s_.device_lost_count;
    emit(ServoEventKind::kDeviceLost);
  } else if (connected && !s_.device_connected) {
    emit(ServoEventKind::kDeviceBack);  // the output stage ramps in again (it cut at the loss)
  }
  s_.device_connected = connected;
  if (connected)
    s_.X_W_device = options_.workspace.toScene(sample.X_WD);
  return status;
}

void ServoLoop::endStream(std::int64_t t0, std::int64_t& tick_ns) noexcept {
  // the stream is over: zero force, no simulation step, no record row; run() returns
  end_of_stream_ = true;
  emit(ServoEventKind::kEndOfStream);
  device_.write(geom::Vec3(0.0), geom::Vec3(0.0));
  output_.zeroLast();
  s_.force_W_n = s_.torque_W_nm = geom::Vec3(0.0);
  tick_ns = realNowNs() - t0;
  state_.write(s_);
  publishShm(realNowNs());
}

void ServoLoop::syncDeviceHold(bool after_write) noexcept {
  // held: the output is held at zero and a zero force and torque have been written; live again
  // is told before the write (so that the tick's force is displayed), held after it
  const bool hold_zero = s_.faults != 0 || !s_.armed || s_.stopping;
  const int held = hold_zero && output_.atZero() ? 1 : 0;
  if (held != device_held_ && (held == 1) == after_write) {
    device_held_ = held;
    device_.setOutputHeld(held == 1);
  }
}

void ServoLoop::writeOutput(const sim::TickOutput& out, bool connected) noexcept {
  // the one output stage: finite, the frame, the clamp, ramp-in x fade x gate, the step limit
  response::OutputInputs in;
  in.device_ok = connected && out.device_ok;
  in.fault = s_.faults != 0;
  in.hold = !s_.armed || s_.stopping;
  in.gate_scale = s_.gate_scale;
  response::OutputReport rep;
  const response::Wrench w =
      output_.apply({out.force_W_n, out.torque_W_nm}, in, output_frame_, &rep);
  if (rep.non_finite && latch(kFaultNonFinite))
    emit(ServoEventKind::kNonFiniteForce);
  s_.tick_flags = out.flags | sim::outputFlags(rep);
  s_.output_gain = output_.fadeGain();
  s_.ramp_restarts = output_.rampRestarts();
  geom::Vec3 force_D = w.force_n, torque_D = w.torque_nm;
  // a lost device: zero at once, nothing written (nothing to ramp on a device that is gone)
  if (connected && device_.write(force_D, torque_D) != device::DeviceStatus::kOk) {
    // counted as lost at the next read; force state goes to zero at once
    emit(ServoEventKind::kDeviceWriteFailed);
    output_.zeroLast();
    force_D = torque_D = geom::Vec3(0.0);
  }
  s_.force_W_n = options_.workspace.forceToScene(force_D);
  s_.torque_W_nm = options_.workspace.torqueToScene(torque_D);
}

void ServoLoop::updateState(const sim::TickOutput& out,
                            double t_s,
                            std::uint64_t period_index) noexcept {
  s_.X_W_proxy = out.X_W_proxy;
  // the held set's contact points: its penalty rows and its contacts with dynamic bodies
  s_.contacts = out.contacts + out.held_dynamic_contacts;
  s_.pairs_tested = out.pairs_tested;
  s_.pairs_skipped = out.pairs_skipped;
  s_.max_penetration_m = out.max_penetration_m;
  s_.t_s = t_s;
  s_.period_index = period_index;
  s_.peak_force_n = std::max(s_.peak_force_n, glm::length(s_.force_W_n));
  s_.peak_penetration_m = std::max(s_.peak_penetration_m, out.max_penetration_m);
  if (s_.contacts > 0)
    ++s_.contact_ticks;
  if (s_.stopping && !stop_done_ && output_.atZero()) {
    stop_done_ = true;
    emit(ServoEventKind::kStopRampDone);
  }
  if (shm_ != nullptr)
    s_.shm_client_alive =
        shm_->clientAlive(static_cast<std::uint64_t>(realNowNs()), kShmAliveTimeoutNs);
}

template <class Row>
bool ServoLoop::pushRow(SpscRing<Row>& ring, const Row& row) noexcept {
  while (!ring.push(row)) {
    if (!options_.wait_for_record_space) {
      ++s_.records_dropped;
      return false;
    }
    std::this_thread::yield();
  }
  return true;
}

void ServoLoop::pushRecords(double t_s, std::int64_t tick_ns) noexcept {
  if (options_.record) {
    // the tick's state as updateState() left it (its counts are the simulation's output's)
    const RecordRow row{
        s_.tick - 1,    t_s,         s_.X_W_device,   s_.X_W_proxy,     s_.force_W_n,
        s_.torque_W_nm, s_.contacts, s_.pairs_tested, s_.pairs_skipped, s_.max_penetration_m,
        tick_ns};
    if (!pushRow(records_, row) && !record_drop_reported_) {
      emit(ServoEventKind::kRecordDropped);
      record_drop_reported_ = true;
    }
  }
  if (options_.record_bodies && current_ != nullptr) {
    for (const sim::BodyPose& b : current_->sim->bodyPoses())
      (void)pushRow(bodies_, BodyRow{s_.tick - 1, t_s, current_->generation, b.body, b.X_WB});
  }
}

void ServoLoop::tick(std::uint64_t period_index, std::int64_t& tick_ns) noexcept {
  const std::int64_t t0 = realNowNs();
  // the tick's time is whole nanoseconds; its seconds are their correctly rounded quotient, the
  // double a pose stream's decimal time parses to (k * period_s rounds up past it at k = 9 of
  // 1 ms, and a replay then ended one tick before its last row)
  const std::uint64_t t_ns =
      static_cast<std::uint64_t>(period_index) * static_cast<std::uint64_t>(period_ns_);
  const double t_s = static_cast<double>(t_ns) / 1e9;
  takeInputs(t_ns);

  device::DeviceSample sample;
  const device::DeviceStatus status = readDevice(t_s, sample);
  if (status == device::DeviceStatus::kEndOfStream)
    return endStream(t0, tick_ns);
  const bool connected = status != device::DeviceStatus::kLost;

  sim::TickOutput out;
  if (current_ != nullptr) {
    sim::TickInput in;
    in.t_s = t_s;
    in.X_W_device = s_.X_W_device;
    in.buttons = sample.buttons;
    in.device_ok = connected;
    out = current_->sim->step(in);
  }
  syncDeviceHold(false);
  writeOutput(out, connected);
  syncDeviceHold(true);
  updateState(out, t_s, period_index);

  ++s_.tick;
  publishLists();
  const std::int64_t t_end = realNowNs();
  tick_ns = t_end - t0;
  s_.last_tick_ns = tick_ns;
  state_.write(s_);
  publishShm(t_end);
  pushRecords(t_s, tick_ns);
}

void ServoLoop::prepareServoThread() {
  if (scenes_.take(current_)) {
    s_.scene_generation = current_->generation;
    emit(ServoEventKind::kSceneSwapped, static_cast<std::int64_t>(current_->generation));
  }
  if (current_ != nullptr)
    current_->sim->prepareThread();
  state_.write(s_);
}

ServoExit ServoLoop::run() noexcept {
  s_.running = true;
  state_.write(s_);
  run_period_index_ = 0;
  run_deadline_ = clock_.nowNs();
  run_exit_ = ServoExit::kStopped;
  // a device that owns the clock runs the periods from its own scheduler; the others, here
  if (!device_.runClocked(&ServoLoop::clockedTick, this)) {
    while (runPeriod()) {
    }
  }
  s_.running = false;
  state_.write(s_);
  return run_exit_;
}

bool ServoLoop::clockedTick(void* self) noexcept {
  return static_cast<ServoLoop*>(self)->runPeriod();
}

bool ServoLoop::runPeriod() noexcept {
  clock_.sleepUntilNs(run_deadline_);
  const std::int64_t wake = clock_.nowNs();
  lateness_.add(wake - run_deadline_);

  std::int64_t tick_ns = 0;
  tick(run_period_index_, tick_ns);
  compute_.add(tick_ns);

  // overrun: the tick ended past the next deadline. The periods it ran into are skipped (the
  // next tick is the first whose deadline is still ahead), never queued.
  const std::int64_t end = clock_.nowNs();
  std::int64_t next = run_deadline_ + period_ns_;
  if (end > next) {
    const std::int64_t late_periods = (end - next) / period_ns_ + 1;
    next += late_periods * period_ns_;
    run_period_index_ += static_cast<std::uint64_t>(late_periods);
    s_.skipped_periods += static_cast<std::uint64_t>(late_periods);
    ++s_.overruns;
    ++s_.consecutive_misses;
    if (s_.consecutive_misses >= options_.miss_fault_count && latch(kFaultMisses))
      emit(ServoEventKind::kMissFault, s_.consecutive_misses);
    state_.write(s_);
  } else {
    s_.consecutive_misses = 0;
  }
  ++run_period_index_;
  run_deadline_ = next;

  if (end_of_stream_) {
    run_exit_ = ServoExit::kEndOfStream;
    return false;
  }
  if (stop_done_) {
    run_exit_ = ServoExit::kStopped;
    return false;
  }
  if (options_.max_ticks != 0 && s_.tick >= options_.max_ticks) {
    run_exit_ = ServoExit::kMaxTicks;
    return false;
  }
  return true;
}

std::string describe(const ServoEvent& e) {
  const std::string at = " at tick " + std::to_string(e.tick);
  switch (e.kind) {
    case ServoEventKind::kDeviceLost:
      return "device lost" + at + ": force set to zero";
    case ServoEventKind::kDeviceBack:
      return "device back" + at + ": force ramps in again";
    case ServoEventKind::kMissFault:
      return "fault latched" + at + ": tick_overrun: " + std::to_string(e.a) +
             " consecutive ticks overran their period; force fades to zero until re-armed";
    case ServoEventKind::kNonFiniteForce:
      return "fault latched" + at +
             ": not_finite: the simulation produced a non-finite force; force zero until "
             "re-armed";
    case ServoEventKind::kStreamLost:
      return "fault latched" + at +
             ": stream_lost: a client's pose stream stopped (no command for 200 ms); force "
             "fades to zero until re-armed";
    case ServoEventKind::kArmed:
      return "armed" + at;
    case ServoEventKind::kDisarmed:
      return "disarmed" + at + ": force ramps to zero";
    case ServoEventKind::kSceneSwapped:
      return "scene " + std::to_string(e.a) + " swapped in" + at;
    case ServoEventKind::kStopRampDone:
      return "force ramped to zero" + at;
    case ServoEventKind::kEndOfStream:
      return "end of the pose stream" + at;
    case ServoEventKind::kRecordDropped:
      return "record ring full" + at + ": rows dropped (the writer is too slow; see status)";
    case ServoEventKind::kDeviceWriteFailed:
      return "device write failed" + at;
    case ServoEventKind::kEditRefused:
      return "scene edit refused" + at + ": " + editListName(e.c) + " entry for body " +
             std::to_string(e.a) + ": " + sim::toString(static_cast<sim::EditStatus>(e.b)) +
             " (the rest of its update was applied)";
    case ServoEventKind::kDeviceFault:
      return "fault latched" + at +
             ": device: the device reported an error (or came back after a loss); force fades "
             "to zero until re-armed";
    case ServoEventKind::kEditBatchDropped:
      return "scene update " + std::to_string(e.c) + " dropped" + at +
             ": validated against scene generation " + std::to_string(e.a) +
             ", the running scene is generation " + std::to_string(e.b);
  }
  return "event" + at;
}

std::string faultNames(std::uint32_t faults) {
  if (faults == 0)
    return "none";
  static constexpr std::pair<std::uint32_t, const char*> kNames[] = {
      {proto::kFaultStreamLost, "stream_lost"},
      {proto::kFaultDevice, "device"},
      {proto::kFaultForceClamped, "force_clamped"},
      {proto::kFaultNotFinite, "not_finite"},
      {proto::kFaultTickOverrun, "tick_overrun"}};
  std::string s;
  for (const auto& [bit, name] : kNames)
    if ((faults & bit) != 0)
      s += (s.empty() ? "" : ",") + std::string(name);
  return s;
}

}  // namespace hapticd::daemon
