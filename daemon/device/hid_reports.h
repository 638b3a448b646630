#pragma once
/// \file
/// HID report layouts (byte layouts and units in docs/devices.md "hid"):
/// - the hapticd generic 6-DOF force-feedback device: input report 0x01 (pose, buttons), output
///   report 0x02 (force, torque), little-endian, fixed sizes;
/// - 3Dconnexion SpaceMouse models: translation report 0x01 and rotation report 0x02 (older
///   models) or one combined report 0x01 (newer models), buttons report 0x03; speed-like values
///   integrated into a pose.
/// Parsing and composing never allocate (servo thread).

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "daemon/device/device.h"

namespace hapticd::device {

/// The generic device's HID usage page and usage (vendor-defined page, "HH"); a device with this
/// usage page is taken to speak the generic layout.
inline constexpr std::uint16_t kGenericUsagePage = 0xFF48;
inline constexpr std::uint16_t kGenericUsage = 0x0001;
inline constexpr std::uint8_t kGenericInputReportId = 0x01;
inline constexpr std::uint8_t kGenericOutputReportId = 0x02;
/// Sizes include the report id byte.
inline constexpr std::size_t kGenericInputReportSize = 28;
inline constexpr std::size_t kGenericOutputReportSize = 16;
/// Units on the wire: position micrometres (int32), quaternion 1/32767 (int16), force millinewtons
/// (int16), torque 1e-4 N*m (int16).
inline constexpr double kGenericPositionUnit_m = 1e-6;
inline constexpr double kGenericQuatUnit = 1.0 / 32767.0;
inline constexpr double kGenericForceUnit_n = 1e-3;
inline constexpr double kGenericTorqueUnit_nm = 1e-4;
/// A quaternion on the wire farther than this from unit length refuses the report.
inline constexpr double kGenericQuatTolerance = 0.01;

/// Input report flag bits.
inline constexpr std::uint8_t kGenericFlagArmed = 1u << 0;  ///< motors enabled
inline constexpr std::uint8_t kGenericFlagFault = 1u << 1;  ///< the device latched a fault
/// Output report flag bits.
inline constexpr std::uint8_t kGenericFlagEnable = 1u << 0;  ///< apply the force (else zero)

struct GenericInputReport {
  std::uint16_t sequence = 0;  ///< incremented by the device per report (wraps)
  Pose X_WD;                   ///< metres; rotation normalised
  std::uint32_t buttons = 0;
  std::uint8_t flags = 0;
};

struct GenericOutputReport {
  std::uint16_t sequence = 0;  ///< incremented by hapticd per report (wraps)
  Vec3 force_n{0.0};           ///< device frame; clamped to +-32.767 N on the wire
  Vec3 torque_nm{0.0};         ///< device frame; clamped to +-3.2767 N*m on the wire
  std::uint8_t flags = 0;
};

/// How a report parse ended.
enum class HidReportStatus : std::uint8_t {
  kOk,
  kIgnored,        ///< a report id this layout does not use (not an error)
  kWrongSize,      ///< too short for its id
  kBadQuaternion,  ///< generic input: quaternion not near unit length
};

HidReportStatus parseGenericInput(std::span<const std::uint8_t> report,
                                  GenericInputReport& out) noexcept;
/// Writes the 28-byte input report (what a generic device sends; used by tests and fakes).
void composeGenericInput(const GenericInputReport& in,
                         std::span<std::uint8_t, kGenericInputReportSize> out) noexcept;
/// Writes the 16-byte output report; values rounded to the wire units and clamped to int16.
void composeGenericOutput(const GenericOutputReport& in,
                          std::span<std::uint8_t, kGenericOutputReportSize> out) noexcept;
HidReportStatus parseGenericOutput(std::span<const std::uint8_t> report,
                                   GenericOutputReport& out) noexcept;

/// How a SpaceMouse model sends its axes.
enum class SpaceMouseReports : std::uint8_t {
  kSeparate,  ///< report 0x01: tx ty tz, report 0x02: rx ry rz (int16 LE each; 7 bytes)
  kCombined,  ///< report 0x01: tx ty tz rx ry rz (int16 LE; 13 bytes)
};

struct SpaceMouseModel {
  std::uint16_t vendor_id;
  std::uint16_t product_id;
  const char* name;
  SpaceMouseReports reports;
};

/// The known SpaceMouse models (vendor 0x046d Logitech-era and 0x256f 3Dconnexion).
std::span<const SpaceMouseModel> spaceMouseModels() noexcept;
const SpaceMouseModel* findSpaceMouse(std::uint16_t vendor_id, std::uint16_t product_id) noexcept;

/// What layout a HID device speaks.
struct HidModel {
  enum Kind : std::uint8_t { kGeneric, kSpaceMouse } kind = kGeneric;
  const SpaceMouseModel* spacemouse = nullptr;  ///< kSpaceMouse only
};

/// A SpaceMouse's latest axes and its integrated pose.
struct SpaceMouseState {
  std::array<std::int16_t, 3> translation{};  ///< raw counts, HID axes (x right, y toward the
                                              ///< user, z down)
  std::array<std::int16_t, 3> rotation{};     ///< raw counts, about the same HID axes
  std::uint32_t buttons = 0;
  Pose X_WD;                   ///< integrated pose, device frame (x right, y up, z toward the user)
  Vec3 linear_velocity{0.0};   ///< device frame, m/s
  Vec3 angular_velocity{0.0};  ///< device frame, rad/s
  bool started = false;
  double t_s = 0.0;
};

/// Takes one report of a SpaceMouse of the given model into state (axes and buttons; no
/// integration). Servo thread.
HidReportStatus parseSpaceMouse(const SpaceMouseModel& model,
                                std::span<const std::uint8_t> report,
                                SpaceMouseState& state) noexcept;

/// Integrates the latest axes from state.t_s to t_s: counts within the deadband read zero, the
/// rest scale as count / full_scale (capped at 2) times the speeds of options; the position is
/// kept within the box of half-size hid_spacemouse_workspace_m around sim_home. The first call
/// only starts the clock (at sim_home). Servo thread.
void integrateSpaceMouse(SpaceMouseState& state, const DeviceOptions& options, double t_s) noexcept;

/// HID axes to the device frame: (x, y, z) -> (x, -z, y); a proper rotation, so rotation axes map
/// the same way.
inline Vec3 spaceMouseToDevice(double x, double y, double z) noexcept {
  return Vec3(x, -z, y);
}

}  // namespace hapticd::device
