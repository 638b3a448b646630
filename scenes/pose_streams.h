#pragma once
/// \file
/// Pose streams that exercise the demo scenes, in the replay format of docs/architecture.md
/// (header `t,px,py,pz,qx,qy,qz,qw,buttons`; seconds from 0, metres, glTF quaternion order; the
/// target pose of the held body's origin in scene coordinates). tests/streams/<scene>.csv are
/// this module's output (written by `make_scenes`); docs/demo-scenes.md says what each stream
/// does. Deterministic: fixed-point text, one row every 4 ms. Any thread; allocates.

#include <string>
#include <string_view>

namespace hapticd::scenes {

/// Rows per second of the generated streams.
inline constexpr int kPoseStreamRate_hz = 250;

/// The CSV text of the named demo scene's pose stream; empty when `scene` is not a demo scene.
std::string makePoseStream(std::string_view scene);

}  // namespace hapticd::scenes
