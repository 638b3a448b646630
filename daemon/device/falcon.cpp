#include "daemon/device/falcon.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/geometry/rotation.h"

namespace hapticd::device::falcon {

namespace {

constexpr double kCountsPerMotorTurn = 320.0 * 4.0;
constexpr double kShaftDiameter_m = 0.01425;
constexpr double kArmDrumDiameter_m = 0.110;
constexpr double kAngleAtZero_rad = 35.0 * std::numbers::pi / 180.0;
constexpr double kRadPerCount =
    2.0 * std::numbers::pi / kCountsPerMotorTurn * (kShaftDiameter_m / kArmDrumDiameter_m);

constexpr std::uint8_t kNibbleBase = 0x41;

void putNibbles(std::uint8_t* p, std::int16_t v) noexcept {
  const auto u = static_cast<std::uint16_t>(v);
  for (int i = 0; i < 4; ++i)
    p[i] = static_cast<std::uint8_t>(kNibbleBase + ((u >> (4 * i)) & 0xf));
}
bool getNibbles(const std::uint8_t* p, std::int16_t& v) noexcept {
  std::uint16_t u = 0;
  for (int i = 0; i < 4; ++i) {
    if (p[i] < kNibbleBase || p[i] > kNibbleBase + 0xf)
      return false;
    u = static_cast<std::uint16_t>(u | ((p[i] - kNibbleBase) << (4 * i)));
  }
  v = static_cast<std::int16_t>(u);
  return true;
}

// the leg frame coordinates of p for leg i
Vec3 legFrame(const Geometry& g, int i, const Vec3& p) noexcept {
  const double cp = std::cos(g.phi_rad[static_cast<std::size_t>(i)]);
  const double sp = std::sin(g.phi_rad[static_cast<std::size_t>(i)]);
  return Vec3(cp * p.x + sp * p.y - g.r, -sp * p.x + cp * p.y - g.s, p.z);
}

// leg i's closure terms at p: U, V, W in the leg's frame, and S2 = b^2 - V^2
struct LegTerms {
  double U, V, W, S2;
};
LegTerms legTerms(const Geometry& g, int i, const Vec3& p) noexcept {
  const Vec3 q = legFrame(g, i, p);
  const double V = q.y + g.f;
  return {q.x + g.c, V, q.z, g.b * g.b - V * V};
}

// dg/dp (rows per leg, world frame) and dg/dtheta (per leg); false when a shin is stretched
bool partials(const Geometry& g,
              const Vec3& p,
              const Vec3& theta,
              Mat3& G_p,
              Vec3& G_theta) noexcept {
  for (int i = 0; i < 3; ++i) {
    const auto [U, V, W, S2] = legTerms(g, i, p);
    if (!(S2 > 1e-12 * g.b * g.b))
      return false;
    const double S = std::sqrt(S2);
    const double ca = std::cos(theta[i]);
    const double sa = std::sin(theta[i]);
    const double du = 2.0 * (U - g.a * ca);
    const double dv = 2.0 * (g.d + g.e + S) * V / S;
    const double dw = 2.0 * (W - g.a * sa);
    const double cp = std::cos(g.phi_rad[static_cast<std::size_t>(i)]);
    const double sp = std::sin(g.phi_rad[static_cast<std::size_t>(i)]);
    // chain rule through legFrame: du/dx = cp, du/dy = sp, dv/dx = -sp, dv/dy = cp, dw/dz = 1;
    // glm matrices are column-major: G_p[col][row]
    G_p[0][i] = du * cp - dv * sp;
    G_p[1][i] = du * sp + dv * cp;
    G_p[2][i] = dw;
    G_theta[i] = 2.0 * g.a * (U * sa - W * ca);
  }
  return true;
}

}  // namespace

double encoderToAngle(std::int16_t counts) noexcept {
  return kAngleAtZero_rad + kRadPerCount * counts;
}

std::int16_t angleToEncoder(double angle_rad) noexcept {
  const double c = std::round((angle_rad - kAngleAtZero_rad) / kRadPerCount);
  if (!(c == c))
    return 0;
  return static_cast<std::int16_t>(std::clamp(c, -32768.0, 32767.0));
}

namespace {

// The frame both directions share: '<', three 16-bit values as nibbles, a status byte, a pad,
// '>'.
void encodeFrame(const std::array<std::int16_t, 3>& values,
                 std::uint8_t status,
                 std::span<std::uint8_t, kPacketSize> out) noexcept {
  out[0] = '<';
  for (std::size_t i = 0; i < 3; ++i)
    putNibbles(&out[1 + 4 * i], values[i]);
  out[13] = static_cast<std::uint8_t>(kNibbleBase + status);
  out[14] = kNibbleBase;
  out[15] = '>';
}

// false when malformed: the delimiters, a value's nibbles, a status above `max_status`
bool decodeFrame(std::span<const std::uint8_t, kPacketSize> in,
                 std::uint8_t max_status,
                 std::array<std::int16_t, 3>& values,
                 std::uint8_t& status) noexcept {
  if (in[0] != '<' || in[15] != '>')
    return false;
  for (std::size_t i = 0; i < 3; ++i)
    if (!getNibbles(&in[1 + 4 * i], values[i]))
      return false;
  if (in[13] < kNibbleBase || in[13] > kNibbleBase + max_status)
    return false;
  status = static_cast<std::uint8_t>(in[13] - kNibbleBase);
  return true;
}

}  // namespace

void encodeOut(const OutPacket& in, std::span<std::uint8_t, kPacketSize> out) noexcept {
  encodeFrame(in.motor, static_cast<std::uint8_t>((in.leds & 0x0e) | (in.homing_mode ? 1 : 0)),
              out);
}

bool decodeOut(std::span<const std::uint8_t, kPacketSize> in, OutPacket& out) noexcept {
  OutPacket r;
  std::uint8_t v = 0;
  if (!decodeFrame(in, 0xf, r.motor, v))
    return false;
  r.leds = static_cast<std::uint8_t>(v & 0x0e);
  r.homing_mode = (v & kHomingMode) != 0;
  out = r;
  return true;
}

void encodeIn(const InPacket& in, std::span<std::uint8_t, kPacketSize> out) noexcept {
  encodeFrame(in.encoders,
              static_cast<std::uint8_t>(((in.homing_status & 7) << 4) | (in.buttons & 0x0f)), out);
}

bool decodeIn(std::span<const std::uint8_t, kPacketSize> in, InPacket& out) noexcept {
  InPacket r;
  std::uint8_t v = 0;
  if (!decodeFrame(in, 0x7f, r.encoders, v))
    return false;
  r.homing_status = static_cast<std::uint8_t>((v >> 4) & 7);
  r.buttons = static_cast<std::uint8_t>(v & 0x0f);
  out = r;
  return true;
}

int PacketReader::feed(std::span<const std::uint8_t> bytes) noexcept {
  int complete = 0;
  for (const std::uint8_t byte : bytes) {
    if (n_ == 0) {
      if (byte != '<')
        continue;  // skip to the start of a packet
    } else if (byte == '<' && n_ < kPacketSize - 1) {
      ++malformed_;  // a new packet starts inside this one: drop the partial one
      n_ = 0;
    }
    buf_[n_++] = byte;
    if (n_ < kPacketSize)
      continue;
    n_ = 0;
    InPacket p;
    if (decodeIn(buf_, p)) {
      latest_ = p;
      ++complete;
    } else {
      ++malformed_;
    }
  }
  return complete;
}

Vec3 constraint(const Geometry& g, const Vec3& p, const Vec3& theta) noexcept {
  Vec3 out;
  for (int i = 0; i < 3; ++i) {
    const auto [U, V, W, S2] = legTerms(g, i, p);
    const double S = std::sqrt(std::max(0.0, S2));
    const double du = U - g.a * std::cos(theta[i]);
    const double dw = W - g.a * std::sin(theta[i]);
    const double L = g.d + g.e + S;
    out[i] = du * du + dw * dw - L * L;
  }
  return out;
}

FkStatus forwardKinematics(const Geometry& g,
                           const Vec3& theta,
                           const Vec3& p_guess,
                           Vec3& p) noexcept {
  constexpr int kMaxIterations = 30;
  constexpr double kStepTolerance_m = 1e-12;
  Vec3 x = p_guess;
  for (int it = 0; it < kMaxIterations; ++it) {
    Mat3 G_p;
    Vec3 G_theta;
    if (!partials(g, x, theta, G_p, G_theta))
      return FkStatus::kSingular;
    const double det = glm::determinant(G_p);
    if (!(std::abs(det) > 1e-18))
      return FkStatus::kSingular;
    Vec3 step = glm::inverse(G_p) * constraint(g, x, theta);
    // damp steps longer than 2 cm so that a poor guess cannot jump to the other assembly
    const double len = glm::length(step);
    if (len > 0.02)
      step *= 0.02 / len;
    x -= step;
    if (!geom::finite(x))
      return FkStatus::kSingular;
    if (len < kStepTolerance_m) {
      p = x;
      return FkStatus::kConverged;
    }
  }
  return FkStatus::kIterationCap;
}

bool inverseKinematics(const Geometry& g, const Vec3& p, Vec3& theta) noexcept {
  Vec3 out;
  for (int i = 0; i < 3; ++i) {
    const auto [U, V, W, S2] = legTerms(g, i, p);
    if (!(S2 >= 0.0))
      return false;
    const double L = g.d + g.e + std::sqrt(S2);
    // U cos(t) + W sin(t) = K / (2a), solved with the half-angle substitution x = tan(t / 2):
    // (K + 2aU) x^2 - 4aW x + (K - 2aU) = 0; the Falcon's arms take the root below
    const double K = U * U + W * W + g.a * g.a - L * L;
    const double l2 = K + 2.0 * g.a * U;
    const double l1 = -4.0 * g.a * W;
    const double l0 = K - 2.0 * g.a * U;
    const double disc = l1 * l1 - 4.0 * l2 * l0;
    if (!(disc >= 0.0))
      return false;
    double x;
    if (std::abs(l2) > 1e-15) {
      x = (-l1 - std::sqrt(disc)) / (2.0 * l2);
    } else {
      if (std::abs(l1) < 1e-15)
        return false;
      x = -l0 / l1;
    }
    out[i] = 2.0 * std::atan(x);
  }
  theta = out;
  return true;
}

bool jacobian(const Geometry& g, const Vec3& p, const Vec3& theta, Mat3& J) noexcept {
  Mat3 G_p;
  Vec3 G_theta;
  if (!partials(g, p, theta, G_p, G_theta))
    return false;
  const double det = glm::determinant(G_p);
  if (!(std::abs(det) > 1e-18))
    return false;
  const Mat3 inv = glm::inverse(G_p);
  // dp/dtheta_j = -inv * (G_theta_j e_j): column j of -inv scaled by G_theta_j
  for (int j = 0; j < 3; ++j)
    J[j] = -G_theta[j] * inv[j];
  return true;
}

Vec3 homePosition(const Geometry& g) noexcept {
  const Vec3 theta(kAngleAtZero_rad);
  // every arm at the same angle puts the effector on the z axis; walk out to it along z
  Vec3 p(0.0, 0.0, 0.0);
  Vec3 best(0.0, 0.0, 0.11);
  for (double z = 0.05; z <= 0.2; z += 0.01) {
    if (forwardKinematics(g, theta, Vec3(0.0, 0.0, z), p) == FkStatus::kConverged) {
      best = p;
      break;
    }
  }
  return best;
}

std::array<std::int16_t, 3> motorCommands(const Geometry& g,
                                          const Vec3& p,
                                          const Vec3& theta,
                                          const Vec3& force_n,
                                          int max_command) noexcept {
  std::array<std::int16_t, 3> out{};
  Mat3 J;
  if (!geom::finite(force_n) || !jacobian(g, p, theta, J))
    return out;
  const Vec3 tau = glm::transpose(J) * force_n;
  Vec3 counts = kMotorCountsPerNm * tau;
  const double limit = std::clamp(max_command, 0, 32767);
  const double largest = std::max({std::abs(counts.x), std::abs(counts.y), std::abs(counts.z)});
  if (largest > limit)
    counts *= limit / largest;
  for (int i = 0; i < 3; ++i)
    out[static_cast<std::size_t>(i)] =
        static_cast<std::int16_t>(std::clamp(std::round(counts[i]), -limit, limit));
  return out;
}

}  // namespace hapticd::device::falcon
