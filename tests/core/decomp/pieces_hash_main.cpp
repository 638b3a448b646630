// decomp_pieces_hash MODEL THREADS: decomposes a generated model and prints the SHA-256 of its
// pieces' bytes (vertices as IEEE doubles, then triangles). decompose_test runs it in two
// processes and compares: the same input gives the same pieces bit for bit.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/decomp/sha256.h"
#include "tests/core/decomp/models.h"

int main(int argc, char** argv) {
  using namespace hapticd::decomp;
  if (argc != 3)
    return 2;
  const std::string model = argv[1];
  TriangleMesh mesh = model == "gear"    ? models::gear()
                      : model == "torus" ? models::torus()
                                         : models::lBlock();
  DecompOptions options;
  options.concavity = 0.02;
  options.threads = static_cast<unsigned>(std::atoi(argv[2]));
  const auto result = decompose(mesh, options);
  if (!result)
    return 1;
  Sha256 h;
  for (const ConvexPiece& p : result.value().pieces) {
    h.update(p.vertices.data(), p.vertices.size() * sizeof(Vec3));
    h.update(p.triangles.data(), p.triangles.size() * sizeof(Triangle));
  }
  std::printf("%zu %s\n", result.value().pieces.size(), h.hexDigest().c_str());
  return 0;
}
