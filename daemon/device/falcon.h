#pragma once
/// \file
/// The Novint Falcon: its firmware's serial packet format (over the FTDI FT232 bulk endpoints)
/// and the kinematics of its delta mechanism. Everything here is pure computation: no I/O, no
/// allocation (servo thread).
///
/// Packets (the Novint SDK firmware, as described by libnifalcon's FalconFirmwareNovintSDK):
/// 16 bytes, '<' + 14 bytes + '>'; each of the 14 inner bytes is a value plus 0x41 ('A').
/// - host -> Falcon: bytes 1-12 three int16 motor commands, four nibbles each, least significant
///   nibble first; byte 13 the LED bits (green 0x02, blue 0x04, red 0x08) or'ed with the homing
///   mode bit 0x01; byte 14 zero.
/// - Falcon -> host: bytes 1-12 three int16 encoder counts in the same nibble order; byte 13 the
///   homing status in bits 4-6 (one bit per axis homed) and the grip buttons in bits 0-3; byte 14
///   unused.
/// The Falcon answers each command with one packet.
///
/// Kinematics: each of the three legs (at angle phi_i about the device's z axis, which points
/// toward the user) is an arm of length a driven by its motor (angle theta_i), then a
/// parallelogram shin of length b whose ends are d and e from the arm and the effector. In the
/// leg's frame (u, v, w) = (R_z(phi_i)^T p - (r, s, 0)) the effector point p satisfies
///   g_i(p, theta_i) = (u + c - a cos theta_i)^2 + (w - a sin theta_i)^2
///                     - (d + e + sqrt(b^2 - (v + f)^2))^2 = 0,
/// an implicit form of the constraint of R. E. Stamper's thesis (1997, "A three degree of
/// freedom parallel manipulator with only translational degrees of freedom", §3), with the
/// Falcon's dimensions measured by the libnifalcon authors (FalconGeometry.h). Forward
/// kinematics solves g(p, theta) = 0 for p by Newton's method; the Jacobian J = dp/dtheta
/// = -(dg/dp)^-1 dg/dtheta; a Cartesian force F maps to the arm torques tau = J^T F.

#include <array>
#include <cstdint>
#include <span>

#include "core/geometry/pose.h"

namespace hapticd::device::falcon {

using geom::Mat3;
using geom::Vec3;

inline constexpr std::uint16_t kVendorId = 0x0403;   ///< FTDI
inline constexpr std::uint16_t kProductId = 0xcb48;  ///< Novint Falcon
inline constexpr std::size_t kPacketSize = 16;

inline constexpr std::uint8_t kLedGreen = 0x02;
inline constexpr std::uint8_t kLedBlue = 0x04;
inline constexpr std::uint8_t kLedRed = 0x08;
inline constexpr std::uint8_t kHomingMode = 0x01;

/// Geometry, metres (libnifalcon include/falcon/core/FalconGeometry.h, after Stamper's figure).
struct Geometry {
  double a = 0.060;     ///< arm (thigh) length
  double b = 0.1025;    ///< shin parallelogram length
  double c = 0.01443;   ///< shin joint to effector centre, u component
  double d = 0.01125;   ///< shin to effector joint
  double e = 0.01125;   ///< arm to shin joint
  double f = -0.025;    ///< shin joint to effector centre, v component
  double r = 0.0400;    ///< frame origin to leg base, u component
  double s = -0.02309;  ///< frame origin to leg base, v component
  /// leg angles about z: 90, -30, -150 degrees, each plus the 15 degree tilt of the legs
  std::array<double, 3> phi_rad = {1.8325957145940461, -0.26179938779914941, -2.3561944901923448};
};

/// Encoder counts to the arm angle (radians): the motor encoder has 320 slots read in quadrature
/// (1280 counts per motor turn); the capstan of diameter 14.25 mm drives the arm's 110 mm drum;
/// 0 counts is the arm at 35 degrees.
double encoderToAngle(std::int16_t counts) noexcept;
/// The inverse of encoderToAngle (rounded to the nearest count, clamped to int16).
std::int16_t angleToEncoder(double angle_rad) noexcept;

/// A decoded Falcon -> host packet.
struct InPacket {
  std::array<std::int16_t, 3> encoders{};
  std::uint8_t homing_status = 0;  ///< bit i: axis i homed
  std::uint8_t buttons = 0;        ///< grip buttons, bits 0-3
};

/// A host -> Falcon packet before encoding.
struct OutPacket {
  std::array<std::int16_t, 3> motor{};
  std::uint8_t leds = 0;
  bool homing_mode = false;
};

void encodeOut(const OutPacket& in, std::span<std::uint8_t, kPacketSize> out) noexcept;
/// Decodes a host -> Falcon packet (for tests and fakes). false when malformed.
bool decodeOut(std::span<const std::uint8_t, kPacketSize> in, OutPacket& out) noexcept;
void encodeIn(const InPacket& in, std::span<std::uint8_t, kPacketSize> out) noexcept;
/// Decodes a Falcon -> host packet. false when malformed (framing, or a nibble byte out of
/// 0x41..0x50).
bool decodeIn(std::span<const std::uint8_t, kPacketSize> in, InPacket& out) noexcept;

/// Reassembles Falcon -> host packets from the byte stream (any chunking), resynchronising on
/// '<' after garbage. No allocation.
class PacketReader {
 public:
  /// Feeds bytes; returns how many complete valid packets they finished; the latest is latest().
  int feed(std::span<const std::uint8_t> bytes) noexcept;
  const InPacket& latest() const noexcept { return latest_; }
  std::uint64_t malformed() const noexcept { return malformed_; }

 private:
  std::array<std::uint8_t, kPacketSize> buf_{};
  std::size_t n_ = 0;
  InPacket latest_;
  std::uint64_t malformed_ = 0;
};

/// g_i(p, theta_i) of the file comment, for the three legs; metres squared.
Vec3 constraint(const Geometry& g, const Vec3& p, const Vec3& theta) noexcept;

/// How a forward kinematics solve ended.
enum class FkStatus : std::uint8_t {
  kConverged,
  kIterationCap,  ///< no convergence within the cap (out of the workspace?)
  kSingular,      ///< dg/dp singular or a leg's shin fully stretched
};

/// Forward kinematics: the effector position p for the arm angles theta, by Newton's method from
/// p_guess (the last position, or kHomePosition), at most 30 iterations, converged when the step
/// is below 1e-12 m. p unchanged unless kConverged.
FkStatus forwardKinematics(const Geometry& g,
                           const Vec3& theta,
                           const Vec3& p_guess,
                           Vec3& p) noexcept;

/// Inverse kinematics: the arm angles for the effector at p (closed form per leg, the branch of
/// the Falcon's assembly). false when p is out of reach.
bool inverseKinematics(const Geometry& g, const Vec3& p, Vec3& theta) noexcept;

/// J = dp/dtheta at (p, theta) (columns: the effector velocity per unit arm rate). false when
/// singular.
bool jacobian(const Geometry& g, const Vec3& p, const Vec3& theta, Mat3& J) noexcept;

/// A point near the middle of the workspace: the effector with every arm at 35 degrees
/// (encoders at 0), computed once. Metres, Falcon frame.
Vec3 homePosition(const Geometry& g) noexcept;

/// Motor command per N*m of arm torque (libnifalcon's scale; the sign makes a positive torque
/// turn the arm toward larger theta).
inline constexpr double kMotorCountsPerNm = -10000.0;

/// The motor commands for a Cartesian force F (N, Falcon frame) at (p, theta): tau = J^T F, then
/// counts = kMotorCountsPerNm * tau, scaled down together so that none exceeds max_command.
/// Zero when the Jacobian is singular or F not finite.
std::array<std::int16_t, 3> motorCommands(const Geometry& g,
                                          const Vec3& p,
                                          const Vec3& theta,
                                          const Vec3& force_n,
                                          int max_command) noexcept;

}  // namespace hapticd::device::falcon
