#pragma once
/// \file
/// hapticctl's commands that talk to a running hapticd over the UDP protocol (protocol/client.h):
/// status, load, pose, replay, record, watch, arm, disarm (docs/architecture.md "hapticctl"), and
/// the scene edits move, add, remove (SceneUpdate). pose, replay, watch and record can use the
/// shared-memory segment instead (DaemonTarget::shm_name, protocol/shm.h). The transports are in
/// client/link.h, what the commands print in client/state_format.h.
/// Each returns the process exit code: 0 done, 1 refused or no daemon answered, 2 bad input
/// (a file that cannot be read, a bad CSV line, a bad number). Messages go to `err`, results to
/// `out`. Thread: the caller's (one Client, one thread).

#include <cstdint>
#include <iosfwd>
#include <string>

namespace hapticd::client {

/// How to reach the daemon. Every field has its default.
struct DaemonTarget {
  std::string host = "127.0.0.1";
  std::uint16_t port = 47100;
  std::string key_file;   ///< 64 hex digits; empty: no key
  int timeout_ms = 2000;  ///< per request; no answer this long: "no daemon at HOST:PORT"
  /// Shared-memory segment for pose, replay, watch and record ("/hapticd" for `--shm` alone);
  /// empty (the default): UDP. Other commands always use UDP.
  std::string shm_name;
};

struct StatusOptions {
  bool json = false;
};
/// A target pose as typed: position (metres, scene frame) and quaternion (glTF order x, y, z, w),
/// normalised before sending; it must be finite and the quaternion nonzero (else exit 2).
struct TargetPose {
  double px = 0, py = 0, pz = 0;
  double qx = 0, qy = 0, qz = 0, qw = 1;
};
struct PoseOptions : TargetPose {
  double seconds = 0.5;  ///< the pose is streamed this long (then the daemon's gate ramps), ≥ 0
  double rate_hz = 200;  ///< stream rate, > 0
  bool arm = true;       ///< take control (arm) first: the gate takes commands of its controller
};
struct ReplayOptions {
  std::string file;  ///< pose stream CSV (t,px,py,pz,qx,qy,qz,qw,buttons), client/replay_stream.h
  /// Send rate, Hz: the stream is interpolated (lerp, slerp, buttons held) at t_0 + k/rate and
  /// sent at those times. 0 (default): the daemon's tick rate (Welcome; over shared memory,
  /// measured from the state's clock, else 1000); a larger rate is clamped to the tick rate.
  double rate_hz = 0;
  bool arm = true;
  bool quiet = false;  ///< no progress lines (else one a second on `err` for replays over 2 s)
};
struct RecordOptions {
  std::string file;      ///< output CSV, the daemon's --record columns
  double seconds = 1.0;  ///< how long to record, finite and ≥ 0
  /// State rate, Hz; 0 (default): the daemon's tick rate, at most its max state rate (1000).
  std::uint32_t rate_hz = 0;
  /// Also the body poses, as the daemon's --record-bodies CSV (empty: not recorded). Each state
  /// lists at most 64 bodies (16 over shared memory).
  std::string bodies_file;
  /// The scene the daemon runs (.glb/.gltf), read for the bodies' names (the daemon's
  /// --record-bodies names bodies by node name); empty: "body<index>".
  std::string scene_file;
};
struct WatchOptions {
  std::uint32_t rate_hz = 10;  ///< lines per second
  std::uint64_t count = 0;     ///< stop after this many lines; 0: until interrupted
  bool json = false;           ///< one JSON object per line instead of text
  std::size_t deepest = 3;     ///< contacts listed per line, deepest first
  bool bodies = false;         ///< also every body pose the state lists (index, position)
};
/// `hapticctl move|add|remove BODY [PX PY PZ [QX QY QZ QW]]`: one SceneUpdate.
struct SceneEditOptions : TargetPose {
  enum class Kind { kMove, kAdd, kRemove };
  Kind kind = Kind::kMove;
  std::uint32_t body = 0;  ///< body index in the loaded scene (`hapticctl check` lists them)
};

int runStatus(const DaemonTarget& t, const StatusOptions& o, std::ostream& out, std::ostream& err);
int runLoad(const DaemonTarget& t, const std::string& file, std::ostream& out, std::ostream& err);
int runPose(const DaemonTarget& t, const PoseOptions& o, std::ostream& out, std::ostream& err);
int runReplay(const DaemonTarget& t, const ReplayOptions& o, std::ostream& out, std::ostream& err);
int runRecord(const DaemonTarget& t, const RecordOptions& o, std::ostream& out, std::ostream& err);
int runWatch(const DaemonTarget& t, const WatchOptions& o, std::ostream& out, std::ostream& err);
/// arm = true: arm (clear latched faults); false: disarm.
int runArm(const DaemonTarget& t, bool arm, std::ostream& out, std::ostream& err);
/// move: a kinematic body's new pose; add: an inactive body made active at a pose; remove: a
/// body made inactive. 0 when the daemon acknowledged, 1 with its refusal text on `err`.
int runSceneEdit(const DaemonTarget& t,
                 const SceneEditOptions& o,
                 std::ostream& out,
                 std::ostream& err);

}  // namespace hapticd::client
