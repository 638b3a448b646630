#pragma once
/// \file
/// The simulation's raw wrench and the one output stage (response::OutputStage), glued: the
/// stage's limits from the simulation's options, its report as TickFlags, and a Simulation that
/// runs the stage after every step for the offline users of the simulation (tests, benchmarks,
/// the accuracy study), so that they see what the daemon's servo loop writes to a device: the
/// same stage with the identity device frame, armed, no command gate. The daemon's servo loop
/// runs its own stage (in the device frame, with its faults, fades and gate) and uses
/// outputFlags().
///
/// Threads: withOutputStage() off the servo thread (allocates); the rest as Simulation.

#include <cstdint>
#include <memory>

#include "core/response/output_stage.h"
#include "core/sim/simulation.h"

namespace hapticd::sim {

/// The output stage's limits from the simulation's options (max_force_n, max_torque_nm,
/// max_force_step_n, max_torque_step_nm, ramp_s, tick_s; the fades keep their defaults). Any
/// thread.
response::OutputLimits outputLimits(const ResponseOptions& r);

/// kTickRamping, kTickForceClamped, kTickStepLimited, kTickNonFinite for what the stage did. Any
/// thread; inline, so that code which does not link the simulation (the servo loop with test
/// fakes) maps them the same way.
inline std::uint32_t outputFlags(const response::OutputReport& r) {
  return (r.ramping ? kTickRamping : 0u) | (r.clamped ? kTickForceClamped : 0u) |
         (r.step_limited ? kTickStepLimited : 0u) | (r.non_finite ? kTickNonFinite : 0u);
}

/// `sim` followed by an output stage of outputLimits(r): step() is sim's step() with its wrench
/// shaped (TickOutput::device_ok drives the stage) and the stage's flags added; restartRamp()
/// restarts the stage's ramp; everything else is sim's. nullptr for a null `sim`. Off the servo
/// thread.
std::unique_ptr<Simulation> withOutputStage(std::unique_ptr<Simulation> sim,
                                            const ResponseOptions& r);

}  // namespace hapticd::sim
