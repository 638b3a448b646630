#pragma once
/// \file
/// The Haply Inverse Service's simulation channel (its WebSocket, the 3.x JSON format, as Haply's
/// documentation of Inverse Service 3.5 describes it; docs/devices.md says what was guessed): the
/// messages hapticd reads (the device list sent on connecting, then one state message per
/// command) and the one it sends (set_cursor_force), and Haply's frame to hapticd's.
///
/// Threads: any; every function allocates (the haply device's I/O thread calls them, never the
/// servo thread), except the frame conversions, which the servo thread uses.

#include <cstdint>
#include <string>
#include <string_view>

#include "core/common/result.h"
#include "core/geometry/pose.h"

namespace hapticd::device::haply {

/// What hapticd takes from one message, in Haply's frame (x right, y forward, z up; metres,
/// seconds). Trivially copyable: it crosses from the I/O thread to the servo thread in a seqlock.
struct State {
  double position_m[3] = {0.0, 0.0, 0.0};             ///< the Inverse3's cursor_position
  double velocity_m_per_s[3] = {0.0, 0.0, 0.0};       ///< its cursor_velocity
  double orientation_xyzw[4] = {0.0, 0.0, 0.0, 1.0};  ///< the VerseGrip's (identity without one)
  std::uint32_t buttons =
      0;  ///< the VerseGrip's: bit 0 `a` (or a wired grip's `button`), 1 `b`, 2 `c`
  std::uint32_t fault = 0;  ///< the service reported an error or a device not ready (see below)
};

/// The device list the service sends on connecting: the first Inverse3 and the first VerseGrip
/// (wired `verse_grip`, else `wireless_verse_grip`), and their state.
struct Inventory {
  std::string inverse3_id;  ///< its device_id
  std::string type;         ///< config.type ("inverse3", "inverse3x", "minverse"), "" when absent
  std::string handedness;   ///< config.handedness ("left", "right"), "" when absent
  std::string grip_id;      ///< "" without a VerseGrip
  std::string grip_array;   ///< "verse_grip" or "wireless_verse_grip"
  State state;
};

/// The first message: fails when it is not JSON, lists no Inverse3 or its state lacks a
/// cursor_position.
Result<Inventory> parseInventory(std::string_view text);

/// How reading a state message ended.
enum class Parsed : std::uint8_t {
  kOk,
  kBad,     ///< not JSON, or the Inverse3's state is malformed: counted, the last state kept
  kMissing  ///< the Inverse3 is no longer listed (unplugged from the service): the device is lost
};

/// A state message for the devices of `inventory`: fills `out` (fields absent from the message
/// keep their value). `fault` is set when the message has a top-level `error`, or the Inverse3's
/// or the grip's `status` has an `error` that is not false, 0, "" or null, or the Inverse3's
/// status says `"ready": false`.
Parsed parseState(std::string_view text, const Inventory& inventory, State& out);

/// The command sent once per exchange: set_cursor_force for the Inverse3 (N, Haply's frame).
std::string forceCommand(std::string_view inverse3_id, const double force_n[3]);

/// Haply's frame (x right, y forward away from the user, z up) to hapticd's device frame (x right,
/// y up, z toward the user): (x, z, -y), a proper rotation. Servo thread (no allocation).
geom::Vec3 toDevice(const double v[3]) noexcept;
/// An orientation in Haply's frame (x, y, z, w) as one in the device frame (P R P^T).
geom::Quat orientationToDevice(const double xyzw[4]) noexcept;
/// A force in the device frame to Haply's: (x, -z, y).
void forceToHaply(const geom::Vec3& f_D, double out[3]) noexcept;

}  // namespace hapticd::device::haply
