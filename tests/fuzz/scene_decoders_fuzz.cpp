// libFuzzer target for the compressed-geometry decoders of the scene loader (Draco and meshopt,
// core/scene/compression.h), reached directly rather than through a whole glTF: any bytes must
// decode or be refused with an error, never crash, hang or leak (run under ASan+UBSan,
// tests/fuzz/CMakeLists.txt). Input: byte 0 picks the decoder and its parameters the way the
// loader's validation would let them through, byte 1 and 2 more parameters, the rest the stream
// (seeds: scene_corpus_gen --fuzz-seeds).
#include <cstddef>
#include <cstdint>
#include <span>

#include "core/scene/compression.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using hapticd::scene::detail::MeshoptView;
  if (size < 3)
    return 0;
  const std::uint8_t selector = data[0], a = data[1], b = data[2];
  const std::span<const std::uint8_t> stream(data + 3, size - 3);
  if (selector % 4 < 2) {
    // Draco: a mesh or a point cloud, the attribute id from byte 1, the counts the accessors
    // would allow from byte 2
    const std::uint64_t max_points = 64u * (1u + b);
    const auto decoded = hapticd::scene::detail::decodeDraco(stream, a, selector % 4 == 0,
                                                             max_points, 4 * max_points);
    if (decoded && decoded.value().values.size() !=
                       std::size_t{decoded.value().points} * decoded.value().components) {
      __builtin_trap();
    }
    return 0;
  }
  // meshopt: mode from byte 0, stride and filter from byte 1, count from byte 2 (1..256)
  MeshoptView view;
  view.mode = static_cast<MeshoptView::Mode>((selector >> 2) % 3);
  view.count = 1u + b;
  if (view.mode == MeshoptView::Mode::kAttributes) {
    view.stride = 4u * (1u + (a & 15u));
    view.filter = static_cast<MeshoptView::Filter>((a >> 4) % 4);
    if ((view.filter == MeshoptView::Filter::kOctahedral && view.stride != 4 && view.stride != 8) ||
        (view.filter == MeshoptView::Filter::kQuaternion && view.stride != 8))
      return 0;  // the loader's validation refuses these
  } else {
    view.stride = (a & 1u) ? 4u : 2u;
    if (view.mode == MeshoptView::Mode::kTriangles)
      view.count = 3u * (1u + b);
  }
  const auto decoded = hapticd::scene::detail::decodeMeshopt(stream, view);
  if (decoded && decoded.value().size() != view.count * view.stride)
    __builtin_trap();
  return 0;
}
