// The validation walk over a document's data: buffers (external URIs under the folder policy,
// meshopt fallback buffers), bufferViews (EXT_meshopt_compression / KHR_meshopt_compression),
// accessors (their byte ranges, sparse storage) (document.h).
#include "core/scene/document.h"
#include "core/scene/extensions.h"
#include "core/scene/glb.h"
#include "core/scene/uri.h"

namespace hapticd::scene::detail {
namespace {

/// a + b and a * b, false on 64-bit overflow
bool addU64(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  return !__builtin_add_overflow(a, b, out);
}
bool mulU64(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  return !__builtin_mul_overflow(a, b, out);
}

/// An external URI checked against the folder policy: the resolved file, or a problem.
std::string checkUri(Checker& c,
                     const std::string& uri,
                     const LoadOptions& options,
                     const std::string& where) {
  std::string why;
  const auto path = resolveUri(uri, options, &why);
  if (!path)
    c.add(where, why);
  return path.value_or("");
}

/// The meshopt extension object of a buffer or bufferView, or null.
const json* meshoptOf(Checker& c, const json& o, const std::string& where) {
  const json* ext = nullptr;
  if (c.object(o, "extensions", where, &ext) != Got::kOk)
    return nullptr;
  for (const std::string_view name : kMeshoptNames) {
    const json* m = nullptr;
    if (c.object(*ext, std::string(name).c_str(), where + " extensions", &m) == Got::kOk)
      return m;
  }
  return nullptr;
}

void validateBuffers(Checker& c,
                     const json& buffers,
                     const LoadOptions& options,
                     bool meshopt_used,
                     Document* doc) {
  for (std::size_t i = 0; i < buffers.size(); ++i) {
    const json& b = buffers[i];
    const std::string w = "buffer " + std::to_string(i);
    BufferDef def;
    if (c.uinteger(b, "byteLength", w, &def.byte_length, true) == Got::kOk &&
        def.byte_length == 0) {
      c.add(w, "byteLength must be at least 1");
    }
    bool fallback = false;
    if (const json* m = meshoptOf(c, b, w))
      c.boolean(*m, "fallback", w + " meshopt", &fallback);
    if (c.string(b, "uri", w, &def.uri) == Got::kOk) {
      if (!isDataUri(def.uri))
        def.path = checkUri(c, def.uri, options, w);
    } else if (fallback || (meshopt_used && !(doc->glb && i == 0))) {
      def.placeholder = true;  // read only through compressed views (checked with the views)
    } else if (!(doc->glb && i == 0)) {
      c.add(w, "has no uri and is not the GLB binary chunk");
    } else if (def.byte_length > doc->bin.size()) {
      c.add(w, "byteLength " + std::to_string(def.byte_length) + " exceeds the GLB BIN chunk (" +
                   std::to_string(doc->bin.size()) + " bytes)");
    }
    doc->buffers.push_back(def);
  }
}

/// A byte range [offset, offset + length) inside buffer `buffer` (an index already checked).
void checkRange(Checker& c,
                std::uint64_t offset,
                std::uint64_t length,
                std::uint32_t buffer,
                const Document& doc,
                const std::string& where) {
  std::uint64_t end = 0;
  const std::uint64_t blen = doc.buffers[buffer].byte_length;
  if (!addU64(offset, length, &end) || end > blen) {
    c.add(where, "byteOffset " + std::to_string(offset) + " + byteLength " +
                     std::to_string(length) + " runs past the end of buffer " +
                     std::to_string(buffer) + " (" + std::to_string(blen) + " bytes)");
  }
}

/// The meshopt codec of a view, with every rule of the extension checked.
std::optional<MeshoptDef> validateMeshopt(Checker& c,
                                          const json& m,
                                          const ViewDef& view,
                                          const std::string& w,
                                          const Document& doc) {
  static const std::vector<std::string> kModes = {"ATTRIBUTES", "TRIANGLES", "INDICES"};
  static const std::vector<std::string> kFilters = {"NONE", "OCTAHEDRAL", "QUATERNION",
                                                    "EXPONENTIAL"};
  MeshoptDef def;
  std::int32_t buffer = -1;
  std::size_t mode = 0, filter = 0;
  const bool ok =
      c.index(m, "buffer", doc.buffers.size(), "buffers", w, &buffer, true) == Got::kOk &&
      c.uinteger(m, "byteLength", w, &def.byte_length, true) == Got::kOk &&
      c.uinteger(m, "byteStride", w, &def.codec.stride, true) == Got::kOk &&
      c.uinteger(m, "count", w, &def.codec.count, true) == Got::kOk &&
      c.choice(m, "mode", w, kModes, &mode) == Got::kOk &&
      c.choice(m, "filter", w, kFilters, &filter) != Got::kBad &&
      c.uinteger(m, "byteOffset", w, &def.byte_offset) != Got::kBad;
  if (!ok) {
    if (!Checker::find(m, "mode"))
      c.add(w, "required property mode is missing");
    return std::nullopt;
  }
  def.buffer = static_cast<std::uint32_t>(buffer);
  def.codec.mode = static_cast<MeshoptView::Mode>(mode);
  def.codec.filter = static_cast<MeshoptView::Filter>(filter);
  checkRange(c, def.byte_offset, def.byte_length, def.buffer, doc, w);
  if (doc.buffers[def.buffer].placeholder)
    c.add(w, "the compressed data's buffer " + std::to_string(def.buffer) + " holds no data");
  const std::uint64_t stride = def.codec.stride, count = def.codec.count;
  const bool attributes = def.codec.mode == MeshoptView::Mode::kAttributes;
  std::uint64_t bytes = 0;
  std::string why;
  if (count == 0 || !mulU64(count, stride, &bytes) || bytes != view.byte_length)
    why = "count x byteStride must equal the bufferView's byteLength";
  else if (view.byte_stride != 0 && view.byte_stride != stride)
    why = "byteStride differs from the bufferView's";
  else if (attributes && (stride == 0 || stride % 4 != 0 || stride > 256))
    why = "ATTRIBUTES needs a byteStride that is a multiple of 4 up to 256";
  else if (!attributes && stride != 2 && stride != 4)
    why = "TRIANGLES and INDICES need a byteStride of 2 or 4";
  else if (def.codec.mode == MeshoptView::Mode::kTriangles && count % 3 != 0)
    why = "TRIANGLES needs a count that is a multiple of 3";
  else if (!attributes && def.codec.filter != MeshoptView::Filter::kNone)
    why = "a filter is only for ATTRIBUTES";
  else if (def.codec.filter == MeshoptView::Filter::kOctahedral && stride != 4 && stride != 8)
    why = "OCTAHEDRAL needs a byteStride of 4 or 8";
  else if (def.codec.filter == MeshoptView::Filter::kQuaternion && stride != 8)
    why = "QUATERNION needs a byteStride of 8";
  if (!why.empty()) {
    c.add(w, why + " (byteStride " + std::to_string(stride) + ", count " + std::to_string(count) +
                 ", bufferView byteLength " + std::to_string(view.byte_length) + ")");
    return std::nullopt;
  }
  return def;
}

void validateViews(Checker& c, const json& views, Document* doc) {
  for (std::size_t i = 0; i < views.size(); ++i) {
    const json& v = views[i];
    const std::string w = "bufferView " + std::to_string(i);
    ViewDef def;
    std::int32_t buffer = -1;
    const Got gb = c.index(v, "buffer", doc->buffers.size(), "buffers", w, &buffer, true);
    c.uinteger(v, "byteOffset", w, &def.byte_offset);
    const Got gl = c.uinteger(v, "byteLength", w, &def.byte_length, true);
    if (c.uinteger(v, "byteStride", w, &def.byte_stride) == Got::kOk &&
        (def.byte_stride < 4 || def.byte_stride > 252 || def.byte_stride % 4 != 0)) {
      c.add(w, "byteStride " + std::to_string(def.byte_stride) +
                   " must be a multiple of 4 in [4, 252]");
    }
    if (gb == Got::kOk && gl == Got::kOk) {
      def.buffer = static_cast<std::uint32_t>(buffer);
      checkRange(c, def.byte_offset, def.byte_length, def.buffer, *doc, w);
      if (const json* m = meshoptOf(c, v, w))
        def.meshopt = validateMeshopt(c, *m, def, w + " meshopt", *doc);
      else if (doc->buffers[def.buffer].placeholder)
        c.add(w, "buffer " + std::to_string(def.buffer) +
                     " holds no data (a meshopt fallback) and this view is not compressed");
    }
    doc->views.push_back(def);
  }
}

/// `count` elements of `element` bytes at `offset` lie inside view `view` (no stride).
void checkPacked(Checker& c,
                 std::int32_t view,
                 std::uint64_t offset,
                 std::uint64_t count,
                 std::uint64_t element,
                 const Document& doc,
                 const std::string& where) {
  const ViewDef& v = doc.views[static_cast<std::size_t>(view)];
  std::uint64_t bytes = 0, end = 0;
  if (!mulU64(count, element, &bytes) || !addU64(bytes, offset, &end) || end > v.byte_length) {
    c.add(where, "byteOffset " + std::to_string(offset) + " + " + std::to_string(count) + " x " +
                     std::to_string(element) + " bytes runs past the end of bufferView " +
                     std::to_string(view) + " (" + std::to_string(v.byte_length) + " bytes)");
  }
}

std::optional<SparseDef> validateSparse(Checker& c,
                                        const json& s,
                                        const AccessorDef& accessor,
                                        const std::string& w,
                                        const Document& doc) {
  SparseDef def;
  const json* indices = nullptr;
  const json* values = nullptr;
  std::uint64_t ct = 0;
  bool ok = c.uinteger(s, "count", w, &def.count, true) == Got::kOk &&
            c.object(s, "indices", w, &indices, true) == Got::kOk &&
            c.object(s, "values", w, &values, true) == Got::kOk;
  ok = ok &&
       c.index(*indices, "bufferView", doc.views.size(), "bufferViews", w + " indices",
               &def.indices_view, true) == Got::kOk &&
       c.uinteger(*indices, "byteOffset", w + " indices", &def.indices_offset) != Got::kBad &&
       c.uinteger(*indices, "componentType", w + " indices", &ct, true) == Got::kOk &&
       c.index(*values, "bufferView", doc.views.size(), "bufferViews", w + " values",
               &def.values_view, true) == Got::kOk &&
       c.uinteger(*values, "byteOffset", w + " values", &def.values_offset) != Got::kBad;
  if (!ok)
    return std::nullopt;
  if (ct != kComponentUnsignedByte && ct != kComponentUnsignedShort &&
      ct != kComponentUnsignedInt) {
    c.add(w + " indices", "componentType " + std::to_string(ct) +
                              " must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    return std::nullopt;
  }
  def.indices_component = static_cast<std::uint32_t>(ct);
  if (def.count == 0 || def.count > accessor.count) {
    c.add(w, "count " + std::to_string(def.count) + " must be in [1, the accessor's count " +
                 std::to_string(accessor.count) + "]");
    return std::nullopt;
  }
  checkPacked(c, def.indices_view, def.indices_offset, def.count, componentBytes(ct), doc,
              w + " indices");
  checkPacked(c, def.values_view, def.values_offset, def.count, accessor.elementBytes(), doc,
              w + " values");
  return def;
}

/// The accessor's data lies inside its view: offset + (count - 1) * stride + element <= length,
/// in 64 bits with overflow checks (a count near 2^32 must not wrap).
void checkAccessorRange(Checker& c,
                        const AccessorDef& def,
                        const Document& doc,
                        const std::string& where) {
  if (def.view < 0 || def.component_type == 0 || def.components == 0 || def.count == 0)
    return;
  const ViewDef& view = doc.views[static_cast<std::size_t>(def.view)];
  const std::uint64_t element = def.elementBytes();
  const std::uint64_t stride = def.strideBytes(doc.views);
  std::uint64_t span = 0, end = 0;
  const bool fits = mulU64(def.count - 1, stride, &span) && addU64(span, element, &span) &&
                    addU64(span, def.byte_offset, &end);
  if (!fits || end > view.byte_length) {
    c.add(where, "byteOffset " + std::to_string(def.byte_offset) + " + count " +
                     std::to_string(def.count) + " x stride " + std::to_string(stride) +
                     (fits ? " = " + std::to_string(end) : std::string(" overflows and")) +
                     " runs past the end of bufferView " + std::to_string(def.view) + " (" +
                     std::to_string(view.byte_length) + " bytes)");
  }
  if (def.byte_offset % componentBytes(def.component_type) != 0) {
    c.add(where, "byteOffset " + std::to_string(def.byte_offset) +
                     " is not a multiple of the component size");
  }
}

void validateAccessors(Checker& c, const json& accessors, Document* doc) {
  for (std::size_t i = 0; i < accessors.size(); ++i) {
    const json& a = accessors[i];
    const std::string w = "accessor " + std::to_string(i);
    AccessorDef def;
    std::string name;
    c.string(a, "name", w, &name);
    const std::string wn = name.empty() ? w : w + " " + inQuotes(name);
    c.index(a, "bufferView", doc->views.size(), "bufferViews", wn, &def.view);
    c.uinteger(a, "byteOffset", wn, &def.byte_offset);
    std::uint64_t ct = 0;
    if (c.uinteger(a, "componentType", wn, &ct, true) == Got::kOk) {
      if (componentBytes(ct) == 0)
        c.add(wn, "componentType " + std::to_string(ct) + " is not a glTF component type");
      else
        def.component_type = static_cast<std::uint32_t>(ct);
    }
    if (c.uinteger(a, "count", wn, &def.count, true) == Got::kOk && def.count == 0)
      c.add(wn, "count must be at least 1");
    if (c.string(a, "type", wn, &def.type, true) == Got::kOk) {
      def.components = typeComponents(def.type);
      if (def.components == 0)
        c.add(wn, "type " + inQuotes(def.type) + " is not a glTF type");
    }
    c.boolean(a, "normalized", wn, &def.normalized);
    checkAccessorRange(c, def, *doc, wn);
    const json* sparse = nullptr;
    if (c.object(a, "sparse", wn, &sparse) == Got::kOk && def.component_type != 0 &&
        def.components != 0 && def.count != 0) {
      def.sparse = validateSparse(c, *sparse, def, wn + " sparse", *doc);
    }
    doc->accessors.push_back(def);
  }
}

}  // namespace

void validateData(Checker& c, const TopLevel& top, const LoadOptions& options, Document* doc) {
  if (top.buffers)
    validateBuffers(c, *top.buffers, options, top.meshopt_used, doc);
  // images are appearance only: their URIs are never resolved, read or required (a texture
  // beside the file, elsewhere, on the web or missing changes nothing that is touched)
  if (top.views)
    validateViews(c, *top.views, doc);
  if (top.accessors)
    validateAccessors(c, *top.accessors, doc);
}

}  // namespace hapticd::scene::detail
