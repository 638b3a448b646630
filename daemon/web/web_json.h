#pragma once
/// \file
/// The WebSocket API's JSON (protocol/websocket.md): the protocol's State and StatusReply as JSON
/// objects, and the checks of a client's pose and scene-edit fields. Pure; any non-servo thread;
/// allocates.

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "protocol/messages.h"

namespace hapticd::web {

/// The fault bits by name ("stream_lost", "tick_overrun", ...): the daemon's faultNames().
using FaultNames = std::function<std::string(std::uint32_t)>;

/// A "state" message: every field of `s` (the schema is in protocol/websocket.md).
nlohmann::ordered_json stateJson(const proto::State& s, const FaultNames& names);
/// A "status" message: every field of `r` (the web server adds its own "web" object).
nlohmann::ordered_json statusJson(const proto::StatusReply& r, const FaultNames& names);

/// `message[key]` as a pose: "p" [x, y, z] metres and "q" [x, y, z, w] (keys `p_key`, `q_key`),
/// every element a finite number, q of unit length within the wire's tolerance (1e-3). Error:
/// what is wrong, naming the key ("q has length 1.2, not 1").
std::optional<proto::WirePose> poseOf(const nlohmann::ordered_json& message, std::string* error);
/// `message[key]` as a vector of three finite numbers; absent: zero. Error as poseOf.
std::optional<proto::WireVec3> vec3Of(const nlohmann::ordered_json& message,
                                      const char* key,
                                      std::string* error);
/// `message["body"]` as a body index (an integer 0..2^32-1). Error as poseOf.
std::optional<std::uint32_t> bodyOf(const nlohmann::ordered_json& message, std::string* error);

}  // namespace hapticd::web
