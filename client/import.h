#pragma once
/// \file
/// `hapticctl import MODEL -o SCENE.glb`: reads a polygonal model (.obj, .stl ASCII or binary,
/// .off through assimp; .ply by its own reader, client/ply.h; .gltf/.glb mesh nodes in world
/// coordinates through the scene loader's reader, core/scene/triangles.h), decomposes it into
/// convex pieces (core/decomp, docs/decomposition.md) and writes a glTF 2.0 scene that keeps the
/// visual mesh and adds one KHR_physics_rigid_bodies `convexHull: true` collider per piece; `--add`
/// appends the model to an existing scene. Exit 0 written, 1 unreadable or unusable input, 2 bad
/// arguments. Main thread of hapticctl.

#include <iosfwd>
#include <string>
#include <vector>

#include "core/common/result.h"
#include "core/decomp/decompose.h"

namespace CLI {
class App;
}

namespace hapticd::client {

/// The command line of `import`, as typed (validated by runImport, so every mistake exits 2).
struct ImportOptions {
  std::string model;
  std::string output;
  std::string units;  ///< m, cm, mm, in; empty: m (assumed, and said)
  std::string role = "static";
  std::string mass;     ///< kg
  std::string density;  ///< kg/m³
  std::string concavity = "0.01";
  std::string max_pieces = "64";
  std::string time_limit = "0";
  bool json = false;
  std::string add;              ///< an existing scene to append to
  std::vector<std::string> at;  ///< X Y Z [QX QY QZ QW]
  /// X Y Z, m/s², the scene's gravity; empty: a scene with a dynamic body and no gravity declared
  /// gets 0 -9.81 0 (glTF's +Y up), and says so
  std::vector<std::string> gravity;
};

/// Registers the subcommand on `app`; its values land in `o`.
CLI::App* defineImport(CLI::App& app, ImportOptions& o);

/// Runs it; the report (or JSON) on `out`, progress and errors on `err`. Returns the exit code.
int runImport(const ImportOptions& o, std::ostream& out, std::ostream& err);

/// The triangles of a model file in its own units and frame (glTF: world coordinates of the default
/// scene's mesh nodes). Errors name the file and what is wrong.
Result<decomp::TriangleMesh> readModel(const std::string& path);

}  // namespace hapticd::client
