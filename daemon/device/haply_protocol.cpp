#include "daemon/device/haply_protocol.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

namespace hapticd::device::haply {

namespace {

using nlohmann::json;

// {x, y, z} (or {x, y, z, w}) of numbers into out; false when absent or malformed
bool readVector(const json& parent, const char* key, double* out, bool with_w) {
  const auto it = parent.find(key);
  if (it == parent.end() || !it->is_object())
    return false;
  const char* names[4] = {"x", "y", "z", "w"};
  double v[4] = {0.0, 0.0, 0.0, 0.0};
  for (int i = 0; i < (with_w ? 4 : 3); ++i) {
    const auto c = it->find(names[i]);
    if (c == it->end() || !c->is_number())
      return false;
    v[i] = c->get<double>();
    if (!std::isfinite(v[i]))
      return false;
  }
  std::copy(v, v + (with_w ? 4 : 3), out);
  return true;
}

// an `error` that says something: not false, 0, "", null or an empty object or array
bool saysError(const json& object) {
  if (!object.is_object())
    return false;
  const auto e = object.find("error");
  if (e == object.end() || e->is_null())
    return false;
  if (e->is_boolean())
    return e->get<bool>();
  if (e->is_number())
    return e->get<double>() != 0.0;
  if (e->is_string() || e->is_object() || e->is_array())
    return !e->empty() && !(e->is_string() && e->get<std::string>().empty());
  return true;
}

const json* findDevice(const json& message, const char* array, const std::string& id) {
  const auto a = message.find(array);
  if (a == message.end() || !a->is_array())
    return nullptr;
  for (const json& d : *a) {
    if (!d.is_object())
      continue;
    const auto i = d.find("device_id");
    if (i != d.end() && i->is_string() && i->get<std::string>() == id)
      return &d;
  }
  return nullptr;
}

std::uint32_t readButtons(const json& state, std::uint32_t previous) {
  const auto b = state.find("buttons");
  if (b != state.end() && b->is_object()) {
    std::uint32_t mask = 0;
    const char* names[3] = {"a", "b", "c"};
    for (std::uint32_t i = 0; i < 3; ++i) {
      const auto k = b->find(names[i]);
      if (k != b->end() && k->is_boolean() && k->get<bool>())
        mask |= 1u << i;
    }
    return mask;
  }
  const auto one = state.find("button");  // a wired VerseGrip's single button
  if (one != state.end() && one->is_boolean())
    return one->get<bool>() ? 1u : 0u;
  return previous;
}

// the Inverse3's and the grip's state and status into out; false when the Inverse3's state is
// malformed
bool readDevices(const json& message, const json& inverse3, const json* grip, State& out) {
  const auto state = inverse3.find("state");
  if (state == inverse3.end() || !state->is_object())
    return false;
  State next = out;
  if (!readVector(*state, "cursor_position", next.position_m, false))
    return false;
  if (state->contains("cursor_velocity") &&
      !readVector(*state, "cursor_velocity", next.velocity_m_per_s, false))
    return false;
  next.fault = saysError(message) ? 1u : 0u;
  const auto status = inverse3.find("status");
  if (status != inverse3.end() && status->is_object()) {
    const auto ready = status->find("ready");
    if (saysError(*status) ||
        (ready != status->end() && ready->is_boolean() && !ready->get<bool>()))
      next.fault = 1u;
  }
  if (grip != nullptr) {
    const auto gs = grip->find("state");
    if (gs != grip->end() && gs->is_object()) {
      double q[4];
      if (readVector(*gs, "orientation", q, true)) {
        const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (n > 0.5 && n < 1.5)
          for (int i = 0; i < 4; ++i)
            next.orientation_xyzw[i] = q[i] / n;
      }
      next.buttons = readButtons(*gs, next.buttons);
    }
    const auto gst = grip->find("status");
    if (gst != grip->end() && saysError(*gst))
      next.fault = 1u;
  }
  out = next;
  return true;
}

std::string stringAt(const json& object, const char* key) {
  const auto it = object.find(key);
  return it != object.end() && it->is_string() ? it->get<std::string>() : std::string();
}

}  // namespace

Result<Inventory> parseInventory(std::string_view text) {
  const json message = json::parse(text, nullptr, false);
  if (message.is_discarded() || !message.is_object())
    return Error{
        "its first message is not a JSON object (is it the Haply Inverse Service's "
        "simulation channel, of the 3.x JSON format?)"};
  const auto list = message.find("inverse3");
  if (list == message.end() || !list->is_array() || list->empty() || !(*list)[0].is_object())
    return Error{
        "the service lists no Inverse3 (is it plugged in, powered and seen by the Haply "
        "Hub?)"};
  const json& inverse3 = (*list)[0];
  Inventory out;
  out.inverse3_id = stringAt(inverse3, "device_id");
  if (out.inverse3_id.empty())
    return Error{"the service's Inverse3 has no device_id"};
  const auto config = inverse3.find("config");
  if (config != inverse3.end() && config->is_object()) {
    out.type = stringAt(*config, "type");
    out.handedness = stringAt(*config, "handedness");
  }
  const json* grip = nullptr;
  for (const char* array : {"verse_grip", "wireless_verse_grip"}) {
    const auto g = message.find(array);
    if (g != message.end() && g->is_array() && !g->empty() && (*g)[0].is_object()) {
      out.grip_id = stringAt((*g)[0], "device_id");
      out.grip_array = array;
      grip = &(*g)[0];
      break;
    }
  }
  if (!readDevices(message, inverse3, grip, out.state))
    return Error{"the service's Inverse3 state has no cursor_position {x, y, z}"};
  return out;
}

Parsed parseState(std::string_view text, const Inventory& inventory, State& out) {
  const json message = json::parse(text, nullptr, false);
  if (message.is_discarded() || !message.is_object())
    return Parsed::kBad;
  const json* inverse3 = findDevice(message, "inverse3", inventory.inverse3_id);
  if (inverse3 == nullptr)
    return message.contains("inverse3") ? Parsed::kMissing : Parsed::kBad;
  const json* grip = inventory.grip_id.empty()
                         ? nullptr
                         : findDevice(message, inventory.grip_array.c_str(), inventory.grip_id);
  return readDevices(message, *inverse3, grip, out) ? Parsed::kOk : Parsed::kBad;
}

std::string forceCommand(std::string_view inverse3_id, const double force_n[3]) {
  json vector = {{"x", force_n[0]}, {"y", force_n[1]}, {"z", force_n[2]}};
  json device = {{"device_id", inverse3_id},
                 {"commands", {{"set_cursor_force", {{"vector", std::move(vector)}}}}}};
  return json{{"inverse3", json::array({std::move(device)})}}.dump();
}

geom::Vec3 toDevice(const double v[3]) noexcept {
  return geom::Vec3(v[0], v[2], -v[1]);
}

geom::Quat orientationToDevice(const double xyzw[4]) noexcept {
  // the vector part rotated by the same proper rotation as positions
  return geom::Quat(xyzw[3], xyzw[0], xyzw[2], -xyzw[1]);
}

void forceToHaply(const geom::Vec3& f_D, double out[3]) noexcept {
  out[0] = f_D.x;
  out[1] = -f_D.z;
  out[2] = f_D.y;
}

}  // namespace hapticd::device::haply
