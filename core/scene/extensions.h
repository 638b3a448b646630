#pragma once
/// \file
/// The glTF extensions the scene loader knows, by what they change (docs/scenes.md,
/// "Extensions"): physics ones it reads, geometry ones it decodes, appearance-only ones it ignores
/// (a haptic server renders nothing: lights, materials, textures, variants, animation pointers,
/// metadata). Any other extension is unknown: refused when required (it may change what is
/// touched), noted and not read when only used.
/// Any thread.

#include <span>
#include <string>
#include <string_view>

namespace hapticd::scene::detail {

enum class ExtensionKind {
  kPhysics,   ///< read: KHR_physics_rigid_bodies, KHR_implicit_shapes, OMI_physics_*, OMI_collider
  kGeometry,  ///< decoded: quantization, Draco, meshopt
  kAppearance,  ///< ignored, with a note
  kUnknown,
};

/// What `name` changes.
ExtensionKind extensionKind(std::string_view name);

/// The names of one kind, for messages and the documentation.
std::span<const std::string_view> extensionsOf(ExtensionKind kind);

/// True for the extensions that declare bodies or colliders (KHR_physics_rigid_bodies,
/// OMI_physics_body, OMI_collider): a document naming none of them is a plain model.
bool declaresPhysics(std::string_view name);

/// The meshopt compression extensions (EXT_meshopt_compression, KHR_meshopt_compression), which
/// share one JSON layout.
inline constexpr std::string_view kMeshoptNames[] = {"EXT_meshopt_compression",
                                                     "KHR_meshopt_compression"};

}  // namespace hapticd::scene::detail
