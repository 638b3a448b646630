#include "daemon/device/hid_reports.h"

#include <algorithm>
#include <cmath>

#include "core/geometry/rotation.h"

namespace hapticd::device {

namespace {

std::uint16_t getU16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::int16_t getI16(const std::uint8_t* p) noexcept {
  return static_cast<std::int16_t>(getU16(p));
}
std::uint32_t getU32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
void putU16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v & 0xff);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void putU32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i)
    p[i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xff);
}
// rounds x / unit to the nearest integer within [lo, hi]; NaN gives 0
long long quantise(double x, double unit, long long lo, long long hi) noexcept {
  const double q = std::round(x / unit);
  if (!(q == q))
    return 0;
  if (q <= static_cast<double>(lo))
    return lo;
  if (q >= static_cast<double>(hi))
    return hi;
  return static_cast<long long>(q);
}
void putI16(std::uint8_t* p, double x, double unit) noexcept {
  const auto v = static_cast<std::int16_t>(quantise(x, unit, -32767, 32767));
  putU16(p, static_cast<std::uint16_t>(v));
}

constexpr SpaceMouseModel kModels[] = {
    {0x046d, 0xc603, "SpaceMouse Plus XT", SpaceMouseReports::kSeparate},
    {0x046d, 0xc605, "CADman", SpaceMouseReports::kSeparate},
    {0x046d, 0xc606, "SpaceMouse Classic", SpaceMouseReports::kSeparate},
    {0x046d, 0xc621, "SpaceBall 5000", SpaceMouseReports::kSeparate},
    {0x046d, 0xc623, "SpaceTraveler", SpaceMouseReports::kSeparate},
    {0x046d, 0xc625, "SpacePilot", SpaceMouseReports::kSeparate},
    {0x046d, 0xc626, "SpaceNavigator", SpaceMouseReports::kSeparate},
    {0x046d, 0xc627, "SpaceExplorer", SpaceMouseReports::kSeparate},
    {0x046d, 0xc628, "SpaceNavigator for Notebooks", SpaceMouseReports::kSeparate},
    {0x046d, 0xc629, "SpacePilot Pro", SpaceMouseReports::kSeparate},
    {0x046d, 0xc62b, "SpaceMouse Pro", SpaceMouseReports::kSeparate},
    {0x256f, 0xc62e, "SpaceMouse Wireless (cabled)", SpaceMouseReports::kCombined},
    {0x256f, 0xc62f, "SpaceMouse Wireless (receiver)", SpaceMouseReports::kCombined},
    {0x256f, 0xc631, "SpaceMouse Pro Wireless (cabled)", SpaceMouseReports::kCombined},
    {0x256f, 0xc632, "SpaceMouse Pro Wireless (receiver)", SpaceMouseReports::kCombined},
    {0x256f, 0xc633, "SpaceMouse Enterprise", SpaceMouseReports::kCombined},
    {0x256f, 0xc635, "SpaceMouse Compact", SpaceMouseReports::kCombined},
    {0x256f, 0xc652, "3Dconnexion Universal Receiver", SpaceMouseReports::kCombined},
};

// kOk when `r` is report `id` with at least `size` bytes; else kIgnored (another report) or
// kWrongSize
HidReportStatus checkReport(std::span<const std::uint8_t> r,
                            std::uint8_t id,
                            std::size_t size) noexcept {
  if (r.empty() || r[0] != id)
    return HidReportStatus::kIgnored;
  if (r.size() < size)
    return HidReportStatus::kWrongSize;
  return HidReportStatus::kOk;
}

}  // namespace

HidReportStatus parseGenericInput(std::span<const std::uint8_t> r,
                                  GenericInputReport& out) noexcept {
  if (const auto st = checkReport(r, kGenericInputReportId, kGenericInputReportSize);
      st != HidReportStatus::kOk)
    return st;
  const std::uint8_t* p = r.data();
  const double qx = getI16(p + 15) * kGenericQuatUnit;
  const double qy = getI16(p + 17) * kGenericQuatUnit;
  const double qz = getI16(p + 19) * kGenericQuatUnit;
  const double qw = getI16(p + 21) * kGenericQuatUnit;
  const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  if (std::abs(norm - 1.0) > kGenericQuatTolerance)
    return HidReportStatus::kBadQuaternion;
  out.sequence = getU16(p + 1);
  out.X_WD.translation =
      Vec3(static_cast<std::int32_t>(getU32(p + 3)), static_cast<std::int32_t>(getU32(p + 7)),
           static_cast<std::int32_t>(getU32(p + 11))) *
      kGenericPositionUnit_m;
  out.X_WD.rotation = geom::Quat(qw / norm, qx / norm, qy / norm, qz / norm);
  out.buttons = getU32(p + 23);
  out.flags = p[27];
  return HidReportStatus::kOk;
}

void composeGenericInput(const GenericInputReport& in,
                         std::span<std::uint8_t, kGenericInputReportSize> out) noexcept {
  std::uint8_t* p = out.data();
  p[0] = kGenericInputReportId;
  putU16(p + 1, in.sequence);
  for (int i = 0; i < 3; ++i) {
    const auto v = static_cast<std::int32_t>(
        quantise(in.X_WD.translation[i], kGenericPositionUnit_m, -2147483647LL, 2147483647LL));
    putU32(p + 3 + 4 * static_cast<std::ptrdiff_t>(i), static_cast<std::uint32_t>(v));
  }
  const geom::Quat q = glm::normalize(in.X_WD.rotation);
  putI16(p + 15, q.x, kGenericQuatUnit);
  putI16(p + 17, q.y, kGenericQuatUnit);
  putI16(p + 19, q.z, kGenericQuatUnit);
  putI16(p + 21, q.w, kGenericQuatUnit);
  putU32(p + 23, in.buttons);
  p[27] = in.flags;
}

void composeGenericOutput(const GenericOutputReport& in,
                          std::span<std::uint8_t, kGenericOutputReportSize> out) noexcept {
  std::uint8_t* p = out.data();
  p[0] = kGenericOutputReportId;
  putU16(p + 1, in.sequence);
  for (int i = 0; i < 3; ++i)
    putI16(p + 3 + 2 * static_cast<std::ptrdiff_t>(i), in.force_n[i], kGenericForceUnit_n);
  for (int i = 0; i < 3; ++i)
    putI16(p + 9 + 2 * static_cast<std::ptrdiff_t>(i), in.torque_nm[i], kGenericTorqueUnit_nm);
  p[15] = in.flags;
}

HidReportStatus parseGenericOutput(std::span<const std::uint8_t> r,
                                   GenericOutputReport& out) noexcept {
  if (const auto st = checkReport(r, kGenericOutputReportId, kGenericOutputReportSize);
      st != HidReportStatus::kOk)
    return st;
  const std::uint8_t* p = r.data();
  out.sequence = getU16(p + 1);
  for (int i = 0; i < 3; ++i)
    out.force_n[i] = getI16(p + 3 + 2 * static_cast<std::ptrdiff_t>(i)) * kGenericForceUnit_n;
  for (int i = 0; i < 3; ++i)
    out.torque_nm[i] = getI16(p + 9 + 2 * static_cast<std::ptrdiff_t>(i)) * kGenericTorqueUnit_nm;
  out.flags = p[15];
  return HidReportStatus::kOk;
}

std::span<const SpaceMouseModel> spaceMouseModels() noexcept {
  return kModels;
}

const SpaceMouseModel* findSpaceMouse(std::uint16_t vendor_id, std::uint16_t product_id) noexcept {
  for (const SpaceMouseModel& m : kModels)
    if (m.vendor_id == vendor_id && m.product_id == product_id)
      return &m;
  return nullptr;
}

HidReportStatus parseSpaceMouse(const SpaceMouseModel& model,
                                std::span<const std::uint8_t> r,
                                SpaceMouseState& state) noexcept {
  if (r.empty())
    return HidReportStatus::kWrongSize;
  const std::uint8_t* p = r.data();
  switch (r[0]) {
    case 0x01:
      if (model.reports == SpaceMouseReports::kCombined) {
        if (r.size() < 13)
          return HidReportStatus::kWrongSize;
        for (std::size_t i = 0; i < 3; ++i)
          state.translation[i] = getI16(p + 1 + 2 * i);
        for (std::size_t i = 0; i < 3; ++i)
          state.rotation[i] = getI16(p + 7 + 2 * i);
      } else {
        if (r.size() < 7)
          return HidReportStatus::kWrongSize;
        for (std::size_t i = 0; i < 3; ++i)
          state.translation[i] = getI16(p + 1 + 2 * i);
      }
      return HidReportStatus::kOk;
    case 0x02:
      if (model.reports == SpaceMouseReports::kCombined)
        return HidReportStatus::kIgnored;
      if (r.size() < 7)
        return HidReportStatus::kWrongSize;
      for (std::size_t i = 0; i < 3; ++i)
        state.rotation[i] = getI16(p + 1 + 2 * i);
      return HidReportStatus::kOk;
    case 0x03: {  // buttons: a little-endian bit mask of 1 to 4 (or more) bytes
      if (r.size() < 2)
        return HidReportStatus::kWrongSize;
      std::uint32_t b = 0;
      const std::size_t n = std::min<std::size_t>(r.size() - 1, 4);
      for (std::size_t i = 0; i < n; ++i)
        b |= static_cast<std::uint32_t>(p[1 + i]) << (8 * i);
      state.buttons = b;
      return HidReportStatus::kOk;
    }
    default:
      return HidReportStatus::kIgnored;
  }
}

void integrateSpaceMouse(SpaceMouseState& s, const DeviceOptions& o, double t_s) noexcept {
  if (!s.started) {
    s.started = true;
    s.t_s = t_s;
    s.X_WD = o.sim_home;
    s.linear_velocity = Vec3(0.0);
    s.angular_velocity = Vec3(0.0);
    return;
  }
  const double dt = std::clamp(t_s - s.t_s, 0.0, 0.1);
  if (!(t_s > s.t_s))
    return;
  s.t_s = t_s;
  auto scaled = [&o](std::int16_t c) {
    const double x = static_cast<double>(c);
    if (std::abs(x) <= o.hid_spacemouse_deadband)
      return 0.0;
    return std::clamp(x / o.hid_spacemouse_full_scale, -2.0, 2.0);
  };
  Vec3 v = o.hid_spacemouse_speed_m_per_s * spaceMouseToDevice(scaled(s.translation[0]),
                                                               scaled(s.translation[1]),
                                                               scaled(s.translation[2]));
  const Vec3 w =
      o.hid_spacemouse_angular_speed_rad_per_s *
      spaceMouseToDevice(scaled(s.rotation[0]), scaled(s.rotation[1]), scaled(s.rotation[2]));
  Vec3 p = s.X_WD.translation + dt * v;
  const Vec3 lo = o.sim_home.translation - Vec3(o.hid_spacemouse_workspace_m);
  const Vec3 hi = o.sim_home.translation + Vec3(o.hid_spacemouse_workspace_m);
  for (int i = 0; i < 3; ++i) {
    if (p[i] < lo[i] || p[i] > hi[i]) {
      p[i] = std::clamp(p[i], lo[i], hi[i]);
      v[i] = 0.0;
    }
  }
  s.X_WD.translation = p;
  s.X_WD.rotation = glm::normalize(geom::quatFromRotationVector(dt * w) * s.X_WD.rotation);
  s.linear_velocity = v;
  s.angular_velocity = w;
}

}  // namespace hapticd::device
