#pragma once
/// \file
/// How hapticctl shows what the daemon sends: fault names, the watch line and its JSON, the
/// record rows (the daemon's --record and --record-bodies columns), and the status report.
/// Any thread; no state.

#include <cstdint>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "protocol/messages.h"

namespace hapticd::client {

/// The fault bits by name, comma-separated ("stream_lost,force_clamped"), "none" for 0.
std::string faultText(std::uint32_t bits);
/// Euclidean length.
double norm(const proto::WireVec3& v);

/// The watch line: the 1.0 figures (tick, compute p50/p99/max, force, torque, scale, contacts,
/// faults, armed), then this tick's compute time, pairs, max penetration, the `deepest`
/// contacts, and with `bodies` every body pose listed ("| bodies N: I at (x, y, z), ..."). No
/// newline.
std::string stateLine(const proto::State& s, std::size_t deepest, bool bodies);
/// The same as one JSON object; with `bodies`, "bodies": [{"body", "p", "q"}, ...].
nlohmann::json stateJson(const proto::State& s, std::size_t deepest, bool bodies);

/// The record header: the daemon's --record columns (docs/architecture.md "Records").
const char* recordHeader();
/// The bodies header: the daemon's --record-bodies columns, tick,t,body,px,py,pz,qx,qy,qz,qw.
const char* bodiesHeader();
/// Writes the record row of `s` (its tick as the daemon's record numbers it, State::tick − 1;
/// numbers as %.17g); false when the write failed.
bool writeRecordRow(std::FILE* f, const proto::State& s);
/// Writes one bodies row per body listed in `s`; `body` is names[index] when there is one, else
/// "body<index>" (as the daemon's writer names a body it has no name for). False when a write
/// failed.
bool writeBodyRows(std::FILE* f, const proto::State& s, const std::vector<std::string>& names);

/// `hapticctl status --json`: the reply's figures and counters, and `state` (force, torque,
/// contacts, deepest contact, max penetration of one recent tick; null when none came).
nlohmann::json statusJson(const proto::StatusReply& r,
                          const std::string& daemon,
                          const std::optional<proto::State>& state);
/// `hapticctl status`: the same as text, lines ending in newlines.
std::string statusText(const proto::StatusReply& r,
                       const std::string& daemon,
                       const std::optional<proto::State>& state);

}  // namespace hapticd::client
