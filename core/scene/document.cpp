// The scene loader's first pass: the container, the JSON parsed once, the validation walk.
#include "core/scene/document.h"

#include <algorithm>

#include "core/scene/glb.h"

namespace hapticd::scene::detail {
namespace {

constexpr std::size_t kMaxJsonDepth = 64;

/// Nesting depth of JSON text (strings skipped); stops counting past the limit.
std::size_t jsonDepth(std::string_view text) {
  std::size_t depth = 0, worst = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"')
      in_string = true;
    else if (c == '[' || c == '{')
      worst = std::max(worst, ++depth);
    else if ((c == ']' || c == '}') && depth > 0)
      --depth;
    if (worst > kMaxJsonDepth)
      break;
  }
  return worst;
}

/// The JSON text of the file: the GLB JSON chunk, or the whole file when it is a JSON object.
std::optional<std::string_view> containerText(std::span<const std::uint8_t> bytes,
                                              const LoadOptions& options,
                                              Document* doc,
                                              Problems* problems) {
  const std::uint64_t size = bytes.size();
  if (size > options.limits.max_file_bytes || size > 0xFFFFFFF0ull) {
    problems->add("file", std::to_string(size) + " bytes exceeds max_file_bytes (" +
                              std::to_string(options.limits.max_file_bytes) + ")");
    return std::nullopt;
  }
  if (isGlb(bytes)) {
    doc->glb = true;
    auto chunks = splitGlb(bytes);
    if (!chunks) {
      problems->add("file", chunks.error().message);
      return std::nullopt;
    }
    doc->bin = chunks.value().bin;
    return chunks.value().json;
  }
  const auto first = std::find_if(bytes.begin(), bytes.end(), [](std::uint8_t c) {
    return c != ' ' && c != '\t' && c != '\n' && c != '\r';
  });
  if (first == bytes.end() || *first != '{') {
    problems->add("file",
                  "not glTF: wrong magic (a .glb starts with 'glTF', a .gltf with a JSON object "
                  "'{')");
    return std::nullopt;
  }
  return std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

/// The one parse of the JSON (syntax, UTF-8, numbers a double holds).
bool parseJson(std::string_view text, Problems* problems, json* out) {
  if (jsonDepth(text) > kMaxJsonDepth) {
    problems->add("file", "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    return false;
  }
  try {
    *out = json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    problems->add("file", std::string("JSON syntax error at byte ") + std::to_string(e.byte) +
                              ": " + e.what());
    return false;
  } catch (const json::exception& e) {
    // 406: a number like 1e999 that no double holds (JSON has no NaN or Inf)
    problems->add("file", std::string("JSON number not finite: ") + e.what());
    return false;
  }
  if (!out->is_object()) {
    problems->add("file", "the glTF JSON must be an object, got " + std::string(out->type_name()));
    return false;
  }
  return true;
}

}  // namespace

glm::dmat4 NodeDef::local() const {
  if (has_matrix)
    return matrix;
  glm::dmat4 m = glm::mat4_cast(rotation);
  m[0] *= scale.x;
  m[1] *= scale.y;
  m[2] *= scale.z;
  m[3] = glm::dvec4(translation, 1.0);
  return m;
}

std::uint64_t AccessorDef::elementBytes() const {
  return static_cast<std::uint64_t>(componentBytes(component_type)) * components;
}

std::uint64_t AccessorDef::strideBytes(const std::vector<ViewDef>& views) const {
  if (view >= 0 && views[static_cast<std::size_t>(view)].byte_stride != 0)
    return views[static_cast<std::size_t>(view)].byte_stride;
  return elementBytes();
}

std::string nodeWhere(const Document& doc, std::size_t node) {
  std::string s = "node " + std::to_string(node);
  if (node < doc.nodes.size() && !doc.nodes[node].name.empty())
    s += " " + inQuotes(doc.nodes[node].name);
  return s;
}

std::string meshWhere(const Document& doc, std::size_t mesh) {
  std::string s = "mesh " + std::to_string(mesh);
  if (mesh < doc.meshes.size() && !doc.meshes[mesh].name.empty())
    s += " " + inQuotes(doc.meshes[mesh].name);
  return s;
}

bool parseDocument(std::span<const std::uint8_t> bytes,
                   const LoadOptions& options,
                   Document* doc,
                   Problems* problems) {
  const auto text = containerText(bytes, options, doc, problems);
  if (!text)
    return false;
  json root;
  if (!parseJson(*text, problems, &root))
    return false;
  Checker c(problems);
  TopLevel top;
  if (!validateTopLevel(c, root, &top, doc))
    return false;
  validateData(c, top, options, doc);
  validateMeshes(c, top, doc);
  validatePhysicsRoot(c, root, doc);
  if (!validateNodes(c, top, options.limits, doc))
    return false;
  validateScenes(c, root, top, doc);
  return !problems->any();
}

}  // namespace hapticd::scene::detail
