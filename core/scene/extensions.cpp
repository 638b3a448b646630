#include "core/scene/extensions.h"

#include <algorithm>

namespace hapticd::scene::detail {
namespace {

constexpr std::string_view kPhysics[] = {"KHR_physics_rigid_bodies", "KHR_implicit_shapes",
                                         "OMI_physics_body",         "OMI_physics_shape",
                                         "OMI_physics_joint",        "OMI_collider"};

constexpr std::string_view kGeometry[] = {"KHR_mesh_quantization", "KHR_draco_mesh_compression",
                                          "EXT_meshopt_compression", "KHR_meshopt_compression"};

// Extensions that change only how a scene looks, sounds or is described: lights, materials
// (every KHR_materials_*), textures and their transforms, variants, animation pointers, node
// visibility, audio, metadata. docs/scenes.md lists them; keep the two the same.
constexpr std::string_view kAppearance[] = {
    "KHR_lights_punctual",
    "KHR_materials_anisotropy",
    "KHR_materials_clearcoat",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_dispersion",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_volume",
    "KHR_materials_volume_scatter",
    "KHR_texture_transform",
    "KHR_texture_basisu",
    "KHR_animation_pointer",
    "KHR_node_visibility",
    "KHR_xmp",
    "KHR_xmp_json_ld",
    "KHR_audio",
    "KHR_audio_emitter",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "EXT_lights_image_based",
    "EXT_lights_ies",
    "MSFT_texture_dds",
    "MSFT_packing_normalRoughnessMetallic",
    "MSFT_packing_occlusionRoughnessMetallic",
};

bool listed(std::span<const std::string_view> list, std::string_view name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

}  // namespace

ExtensionKind extensionKind(std::string_view name) {
  if (listed(kPhysics, name))
    return ExtensionKind::kPhysics;
  if (listed(kGeometry, name))
    return ExtensionKind::kGeometry;
  // every material extension changes only shading
  if (listed(kAppearance, name) || name.rfind("KHR_materials_", 0) == 0)
    return ExtensionKind::kAppearance;
  return ExtensionKind::kUnknown;
}

std::span<const std::string_view> extensionsOf(ExtensionKind kind) {
  switch (kind) {
    case ExtensionKind::kPhysics:
      return kPhysics;
    case ExtensionKind::kGeometry:
      return kGeometry;
    case ExtensionKind::kAppearance:
      return kAppearance;
    case ExtensionKind::kUnknown:
      break;
  }
  return {};
}

bool declaresPhysics(std::string_view name) {
  return name == "KHR_physics_rigid_bodies" || name == "OMI_physics_body" || name == "OMI_collider";
}

}  // namespace hapticd::scene::detail
