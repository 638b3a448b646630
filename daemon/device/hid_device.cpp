#include "daemon/device/hid_device.h"

#include <array>
#include <cmath>
#include <cstdio>

#include "core/geometry/rotation.h"

namespace hapticd::device {

namespace {

std::string hex4(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", static_cast<unsigned>(v));
  return buf;
}

std::string describe(const HidDeviceEntry& e, const HidModel& m) {
  std::string s = "hid " + hex4(e.vendor_id) + ":" + hex4(e.product_id) + " ";
  if (m.kind == HidModel::kSpaceMouse)
    s += m.spacemouse->name;
  else
    s += "generic 6-DOF" + (e.product.empty() ? std::string() : " (" + e.product + ")");
  return s + " at " + e.path;
}

Result<bool> checkOptions(const DeviceOptions& o) {
  const std::pair<const char*, double> positive[] = {
      {"hid_spacemouse_full_scale", o.hid_spacemouse_full_scale},
      {"hid_spacemouse_workspace_m", o.hid_spacemouse_workspace_m}};
  for (const auto& [name, v] : positive)
    if (!(std::isfinite(v) && v > 0.0))
      return Error{std::string("device 'hid': ") + name + " must be a finite number > 0"};
  const std::pair<const char*, double> non_negative[] = {
      {"hid_spacemouse_speed_m_per_s", o.hid_spacemouse_speed_m_per_s},
      {"hid_spacemouse_angular_speed_rad_per_s", o.hid_spacemouse_angular_speed_rad_per_s},
      {"hid_spacemouse_deadband", o.hid_spacemouse_deadband}};
  for (const auto& [name, v] : non_negative)
    if (!(std::isfinite(v) && v >= 0.0))
      return Error{std::string("device 'hid': ") + name + " must be a finite number >= 0"};
  return true;
}

}  // namespace

std::optional<HidModel> hidModelOf(const HidDeviceEntry& e) {
  if (const SpaceMouseModel* m = findSpaceMouse(e.vendor_id, e.product_id))
    return HidModel{HidModel::kSpaceMouse, m};
  if (e.usage_page == kGenericUsagePage && e.usage == kGenericUsage)
    return HidModel{HidModel::kGeneric, nullptr};
  return std::nullopt;
}

HidDevice::HidDevice(std::unique_ptr<HidBackend> backend,
                     const HidDeviceEntry& entry,
                     HidModel model,
                     bool explicit_path,
                     const DeviceOptions& options)
    : backend_(std::move(backend)),
      entry_(entry),
      model_(model),
      explicit_path_(explicit_path),
      options_(options) {
  info_.name = describe(entry, model);
  info_.limits = options.limits;
  if (model.kind == HidModel::kSpaceMouse)
    info_.capabilities = kCapPosition | kCapOrientation | kCapButtons;
  else
    info_.capabilities = kCapPosition | kCapOrientation | kCapForce | kCapTorque | kCapButtons;
}

Result<std::unique_ptr<HidDevice>> HidDevice::open(std::unique_ptr<HidBackend> backend,
                                                   std::string_view path,
                                                   const DeviceOptions& options) {
  const std::string spec = path.empty() ? "hid" : "hid:" + std::string(path);
  if (auto ok = checkOptions(options); !ok)
    return ok.error();
  const std::vector<HidDeviceEntry> entries = backend->enumerate();
  const HidDeviceEntry* chosen = nullptr;
  std::optional<HidModel> model;
  if (path.empty()) {
    for (const HidDeviceEntry& e : entries) {
      if ((model = hidModelOf(e))) {
        chosen = &e;
        break;
      }
    }
    if (!chosen)
      return Error{
          "device 'hid': no device found (looked for the SpaceMouse models of "
          "docs/devices.md and HID usage page 0xff48 usage 0x0001 among " +
          std::to_string(entries.size()) +
          " HID interfaces; is the device plugged in and readable by this user?)"};
  } else {
    for (const HidDeviceEntry& e : entries)
      if (e.path == path)
        chosen = &e;
    if (!chosen)
      return Error{"device '" + spec +
                   "': no HID device at this path (missing, or not readable "
                   "by this user)"};
    model = hidModelOf(*chosen);
    // a device named by path that is not a known SpaceMouse is taken to speak the generic layout
    if (!model)
      model = HidModel{HidModel::kGeneric, nullptr};
  }
  auto transport = backend->open(chosen->path);
  if (!transport)
    return Error{"device '" + spec + "': cannot open " + chosen->path + ": " +
                 transport.error().message};
  const HidDeviceEntry entry = *chosen;
  std::unique_ptr<HidDevice> dev(
      new HidDevice(std::move(backend), entry, *model, !path.empty(), options));
  dev->transport_ = std::move(transport).value();
  return dev;
}

void HidDevice::markLost() noexcept {
  link_.markLost();
  has_input_ = false;
  has_previous_ = false;
  spacemouse_.started = false;
  spacemouse_.translation = {};
  spacemouse_.rotation = {};
}

DeviceStatus HidDevice::read(double t_s, DeviceSample& out) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  std::array<std::uint8_t, 64> buf{};
  for (int i = 0; i < kMaxReportsPerRead; ++i) {
    const int n = transport_->readReport(buf);
    if (n < 0) {
      markLost();
      return DeviceStatus::kLost;
    }
    if (n == 0)
      break;
    const auto report = std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n));
    HidReportStatus st;
    if (model_.kind == HidModel::kSpaceMouse) {
      st = parseSpaceMouse(*model_.spacemouse, report, spacemouse_);
    } else {
      GenericInputReport in;
      st = parseGenericInput(report, in);
      if (st == HidReportStatus::kOk) {
        last_input_ = in;
        has_input_ = true;
      }
    }
    if (st == HidReportStatus::kWrongSize || st == HidReportStatus::kBadQuaternion)
      bad_reports_.fetch_add(1, std::memory_order_relaxed);
  }
  if (model_.kind == HidModel::kSpaceMouse) {
    integrateSpaceMouse(spacemouse_, options_, t_s);
    out.X_WD = spacemouse_.X_WD;
    out.linear_velocity = spacemouse_.linear_velocity;
    out.angular_velocity = spacemouse_.angular_velocity;
    out.buttons = spacemouse_.buttons;
    return DeviceStatus::kOk;
  }
  // generic: until the first report the device sits at home
  const Pose X = has_input_ ? last_input_.X_WD : options_.sim_home;
  if (has_previous_ && t_s > previous_t_s_) {
    const double dt = t_s - previous_t_s_;
    velocity_ = (X.translation - previous_pose_.translation) / dt;
    angular_velocity_ =
        geom::rotationVector(X.rotation * glm::conjugate(previous_pose_.rotation)) / dt;
  } else if (!has_previous_) {
    velocity_ = Vec3(0.0);
    angular_velocity_ = Vec3(0.0);
  }
  has_previous_ = true;
  previous_t_s_ = t_s;
  previous_pose_ = X;
  out.X_WD = X;
  out.linear_velocity = velocity_;
  out.angular_velocity = angular_velocity_;
  out.buttons = has_input_ ? last_input_.buttons : 0;
  return DeviceStatus::kOk;
}

DeviceStatus HidDevice::write(const Vec3& force_n, const Vec3& torque_nm) noexcept {
  if (!link_.connected())
    return DeviceStatus::kLost;
  if (model_.kind == HidModel::kSpaceMouse)
    return DeviceStatus::kOk;
  GenericOutputReport r;
  r.sequence = ++out_sequence_;
  const bool finite = geom::finite(force_n) && geom::finite(torque_nm);
  r.force_n = finite ? force_n : Vec3(0.0);
  r.torque_nm = finite ? torque_nm : Vec3(0.0);
  r.flags = finite ? kGenericFlagEnable : 0;
  std::array<std::uint8_t, kGenericOutputReportSize> bytes{};
  composeGenericOutput(r, bytes);
  if (transport_->writeReport(bytes) < 0) {
    markLost();
    return DeviceStatus::kLost;
  }
  return DeviceStatus::kOk;
}

bool HidDevice::service() {
  if (link_.connected())
    return true;
  // the servo thread stopped touching the transport when it marked the device lost
  transport_.reset();
  for (const HidDeviceEntry& e : backend_->enumerate()) {
    const bool same = explicit_path_
                          ? e.path == entry_.path
                          : (e.vendor_id == entry_.vendor_id && e.product_id == entry_.product_id &&
                             e.usage_page == entry_.usage_page && e.usage == entry_.usage);
    if (!same)
      continue;
    auto t = backend_->open(e.path);
    if (!t)
      continue;
    transport_ = std::move(t).value();
    entry_.path = e.path;  // a replugged device may come back under another hidraw node
    link_.markConnected();
    return true;
  }
  return false;
}

Result<std::unique_ptr<Device>> makeHidDevice(std::string_view path, const DeviceOptions& options) {
  auto d = HidDevice::open(makeHidapiBackend(), path, options);
  if (!d)
    return d.error();
  return std::unique_ptr<Device>(std::move(d).value());
}

}  // namespace hapticd::device
