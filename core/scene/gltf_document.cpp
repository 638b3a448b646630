#include "core/scene/gltf_document.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

namespace hapticd::scene::detail {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxJsonDepth = 64;
/// A rotation quaternion whose norm is farther than this from 1 is refused; closer ones are
/// normalised (exporters write float32 quaternions).
constexpr double kUnitQuaternionTolerance = 1e-3;

const char* const kSupportedExtensions[] = {"KHR_physics_rigid_bodies", "KHR_implicit_shapes"};

std::string inQuotes(const std::string& s) {
  return "'" + s + "'";
}

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

enum class Got { kAbsent, kOk, kBad };

const char* typeName(const json& j) {
  return j.type_name();
}

/// Typed access to JSON members, each reporting its own problem.
class Checker {
 public:
  explicit Checker(Problems* problems) : p_(problems) {}

  void add(const std::string& where, std::string what) { p_->add(where, std::move(what)); }

  static const json* find(const json& o, const char* key) {
    if (!o.is_object())
      return nullptr;
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
  }

  Got object(const json& o,
             const char* key,
             const std::string& where,
             const json** out,
             bool required = false) {
    const json* j = find(o, key);
    if (!j)
      return missing(where, key, required);
    if (!j->is_object())
      return wrong(where, key, "an object", *j);
    *out = j;
    return Got::kOk;
  }

  Got array(const json& o,
            const char* key,
            const std::string& where,
            const json** out,
            bool required = false) {
    const json* j = find(o, key);
    if (!j)
      return missing(where, key, required);
    if (!j->is_array())
      return wrong(where, key, "an array", *j);
    *out = j;
    return Got::kOk;
  }

  Got boolean(const json& o, const char* key, const std::string& where, bool* out) {
    const json* j = find(o, key);
    if (!j)
      return Got::kAbsent;
    if (!j->is_boolean())
      return wrong(where, key, "a boolean", *j);
    *out = j->get<bool>();
    return Got::kOk;
  }

  Got string(const json& o,
             const char* key,
             const std::string& where,
             std::string* out,
             bool required = false) {
    const json* j = find(o, key);
    if (!j)
      return missing(where, key, required);
    if (!j->is_string())
      return wrong(where, key, "a string", *j);
    *out = j->get<std::string>();
    return Got::kOk;
  }

  Got uinteger(const json& o,
               const char* key,
               const std::string& where,
               std::uint64_t* out,
               bool required = false) {
    const json* j = find(o, key);
    if (!j)
      return missing(where, key, required);
    if (j->is_number_unsigned()) {
      *out = j->get<std::uint64_t>();
      return Got::kOk;
    }
    if (j->is_number_integer()) {
      add(where,
          std::string(key) + " is negative (" + std::to_string(j->get<std::int64_t>()) + ")");
      return Got::kBad;
    }
    return wrong(where, key, "a non-negative integer", *j);
  }

  /// An index into an array of `count` `things`.
  Got index(const json& o,
            const char* key,
            std::size_t count,
            const char* things,
            const std::string& where,
            std::int32_t* out,
            bool required = false) {
    const json* j = find(o, key);
    if (!j)
      return missing(where, key, required);
    return indexValue(*j, key, count, things, where, out);
  }

  Got indexValue(const json& j,
                 const std::string& key,
                 std::size_t count,
                 const char* things,
                 const std::string& where,
                 std::int32_t* out) {
    if (j.is_number_unsigned()) {
      const std::uint64_t v = j.get<std::uint64_t>();
      if (v >= count) {
        add(where, key + " index " + std::to_string(v) + " out of range (" + std::to_string(count) +
                       " " + things + ")");
        return Got::kBad;
      }
      *out = static_cast<std::int32_t>(v);
      return Got::kOk;
    }
    if (j.is_number_integer()) {
      add(where, key + " index " + std::to_string(j.get<std::int64_t>()) + " out of range (" +
                     std::to_string(count) + " " + things + ")");
      return Got::kBad;
    }
    add(where, key + " must be an integer index, got " + std::string(typeName(j)));
    return Got::kBad;
  }

  Got number(const json& o, const char* key, const std::string& where, double* out) {
    const json* j = find(o, key);
    if (!j)
      return Got::kAbsent;
    if (!j->is_number())
      return wrong(where, key, "a number", *j);
    const double v = j->get<double>();
    if (!std::isfinite(v)) {
      add(where, std::string(key) + " is not finite");
      return Got::kBad;
    }
    *out = v;
    return Got::kOk;
  }

  /// A number that must be >= min (or > min when exclusive).
  Got bounded(const json& o,
              const char* key,
              const std::string& where,
              double* out,
              double min,
              bool exclusive) {
    double v = 0.0;
    const Got got = number(o, key, where, &v);
    if (got != Got::kOk)
      return got;
    if (exclusive ? !(v > min) : !(v >= min)) {
      add(where, std::string(key) + " must be " + (exclusive ? "> " : ">= ") + num(min) + ", got " +
                     num(v));
      return Got::kBad;
    }
    *out = v;
    return Got::kOk;
  }

  Got vector(const json& o, const char* key, std::size_t n, const std::string& where, double* out) {
    const json* j = find(o, key);
    if (!j)
      return Got::kAbsent;
    if (!j->is_array() || j->size() != n) {
      add(where, std::string(key) + " must be an array of " + std::to_string(n) + " numbers");
      return Got::kBad;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const json& e = (*j)[i];
      if (!e.is_number()) {
        add(where,
            std::string(key) + "[" + std::to_string(i) + "] must be a number, got " + typeName(e));
        return Got::kBad;
      }
      out[i] = e.get<double>();
      if (!std::isfinite(out[i])) {
        add(where, std::string(key) + "[" + std::to_string(i) + "] is not finite");
        return Got::kBad;
      }
    }
    return Got::kOk;
  }

  Got vec3(const json& o, const char* key, const std::string& where, Vec3* out) {
    double v[3];
    const Got got = vector(o, key, 3, where, v);
    if (got == Got::kOk)
      *out = {v[0], v[1], v[2]};
    return got;
  }

  /// A glTF quaternion (x, y, z, w): normalised when close to unit, refused otherwise.
  Got quaternion(const json& o, const char* key, const std::string& where, geom::Quat* out) {
    double v[4];
    const Got got = vector(o, key, 4, where, v);
    if (got != Got::kOk)
      return got;
    const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance)) {
      add(where, std::string(key) + " is not a unit quaternion (norm " + num(norm) +
                     "; tolerance " + num(kUnitQuaternionTolerance) + ")");
      return Got::kBad;
    }
    *out = geom::Quat(v[3] / norm, v[0] / norm, v[1] / norm, v[2] / norm);
    return Got::kOk;
  }

  /// An array of strings.
  Got strings(const json& o,
              const char* key,
              const std::string& where,
              std::vector<std::string>* out) {
    const json* j = find(o, key);
    if (!j)
      return Got::kAbsent;
    if (!j->is_array())
      return wrong(where, key, "an array of strings", *j);
    for (const json& e : *j) {
      if (!e.is_string())
        return wrong(where, key, "an array of strings", *j);
      out->push_back(e.get<std::string>());
    }
    return Got::kOk;
  }

 private:
  Got missing(const std::string& where, const char* key, bool required) {
    if (!required)
      return Got::kAbsent;
    add(where, std::string("required property ") + key + " is missing");
    return Got::kBad;
  }
  Got wrong(const std::string& where, const char* key, const char* expected, const json& j) {
    add(where, std::string(key) + " must be " + expected + ", got " + typeName(j));
    return Got::kBad;
  }

  Problems* p_;
};

std::uint32_t readU32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

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

std::uint32_t componentBytes(std::uint32_t component_type) {
  switch (component_type) {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case 5126:
      return 4;
    default:
      return 0;
  }
}

std::uint32_t typeComponents(const std::string& type) {
  if (type == "SCALAR")
    return 1;
  if (type == "VEC2")
    return 2;
  if (type == "VEC3")
    return 3;
  if (type == "VEC4")
    return 4;
  if (type == "MAT2")
    return 4;
  if (type == "MAT3")
    return 9;
  if (type == "MAT4")
    return 16;
  return 0;
}

/// a + b and a * b, false on 64-bit overflow
bool addU64(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  return !__builtin_add_overflow(a, b, out);
}
bool mulU64(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  return !__builtin_mul_overflow(a, b, out);
}

}  // namespace

void Problems::add(std::string where, std::string what) {
  if (list_.size() >= kMax) {
    ++dropped_;
    return;
  }
  list_.push_back({std::move(where), std::move(what)});
}

std::vector<Problem> Problems::take() {
  std::vector<Problem> out = std::move(list_);
  if (dropped_ > 0) {
    out.push_back({"file", std::to_string(dropped_) + " more problems not listed"});
  }
  list_.clear();
  dropped_ = 0;
  return out;
}

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
  if (view >= 0 && views[static_cast<std::size_t>(view)].byte_stride != 0) {
    return views[static_cast<std::size_t>(view)].byte_stride;
  }
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

std::optional<std::string> resolveUri(const std::string& uri,
                                      const LoadOptions& options,
                                      std::string* why) {
  namespace fs = std::filesystem;
  if (!options.allowed_uri_dir) {
    *why = "external URI " + inQuotes(uri) +
           " refused: no folder is allowed for external files (LoadOptions::allowed_uri_dir, "
           "config [scene] allowed_uri_dir)";
    return std::nullopt;
  }
  // percent-decoding, as tinygltf does before it opens the file
  std::string decoded;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      decoded.push_back(static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      decoded.push_back(uri[i]);
    }
  }
  if (decoded.empty() || decoded.find('\0') != std::string::npos) {
    *why = "external URI " + inQuotes(uri) + " is empty or holds a NUL byte";
    return std::nullopt;
  }
  if (decoded.front() == '/' || decoded.front() == '\\') {
    *why = "external URI " + inQuotes(uri) +
           " is an absolute path (only paths inside the allowed "
           "folder are read)";
    return std::nullopt;
  }
  const std::size_t colon = decoded.find(':');
  if (colon != std::string::npos && decoded.find('/') > colon) {
    *why = "external URI " + inQuotes(uri) + " has a scheme (only relative file paths are read)";
    return std::nullopt;
  }
  std::size_t start = 0;
  while (start <= decoded.size()) {
    const std::size_t end = decoded.find_first_of("/\\", start);
    const std::string part =
        decoded.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (part == "..") {
      *why = "external URI " + inQuotes(uri) + " traverses out of the allowed folder ('..')";
      return std::nullopt;
    }
    if (end == std::string::npos)
      break;
    start = end + 1;
  }
  std::error_code ec;
  const fs::path dir = fs::canonical(*options.allowed_uri_dir, ec);
  if (ec) {
    *why = "the allowed folder " + inQuotes(options.allowed_uri_dir->string()) + " does not exist";
    return std::nullopt;
  }
  const fs::path file = fs::canonical(dir / decoded, ec);
  if (ec) {
    *why = "external URI " + inQuotes(uri) + ": no such file in the allowed folder";
    return std::nullopt;
  }
  // the canonical path (symbolic links resolved) must still be inside the folder
  const auto [d, f] = std::mismatch(dir.begin(), dir.end(), file.begin(), file.end());
  if (d != dir.end()) {
    *why = "external URI " + inQuotes(uri) +
           " resolves outside the allowed folder (a symbolic link out of it?)";
    return std::nullopt;
  }
  if (!fs::is_regular_file(file, ec)) {
    *why = "external URI " + inQuotes(uri) + " is not a regular file";
    return std::nullopt;
  }
  return file.string();
}

bool parseContainer(std::span<const std::uint8_t> bytes,
                    const LoadOptions& options,
                    Document* doc,
                    Problems* problems,
                    nlohmann::json* out) {
  const std::uint64_t size = bytes.size();
  if (size > options.limits.max_file_bytes || size > 0xFFFFFFF0ull) {
    problems->add("file", std::to_string(size) + " bytes exceeds max_file_bytes (" +
                              std::to_string(options.limits.max_file_bytes) + ")");
    return false;
  }
  const std::uint8_t* p = bytes.data();
  std::string_view text;
  if (size >= 4 && std::memcmp(p, "glTF", 4) == 0) {
    doc->glb = true;
    if (size < 20) {
      problems->add("file", "truncated GLB: " + std::to_string(size) +
                                " bytes, the header and first chunk header need 20");
      return false;
    }
    const std::uint32_t version = readU32(p + 4);
    const std::uint32_t length = readU32(p + 8);
    if (version != 2) {
      problems->add("file", "GLB version " + std::to_string(version) + " (only 2 is supported)");
      return false;
    }
    if (length > size) {
      problems->add("file", "truncated GLB: the header says " + std::to_string(length) +
                                " bytes, the file has " + std::to_string(size));
      return false;
    }
    if (length < size) {
      problems->add("file", "GLB header length " + std::to_string(length) +
                                " does not match the file size " + std::to_string(size));
      return false;
    }
    const std::uint64_t json_length = readU32(p + 12);
    const std::uint32_t json_type = readU32(p + 16);
    if (json_type != 0x4E4F534Au) {
      problems->add(
          "file", "GLB chunk 0 is not JSON (type 0x" + [&] {
            char b[16];
            std::snprintf(b, sizeof b, "%08X", json_type);
            return std::string(b);
          }() + ")");
      return false;
    }
    if (json_length == 0 || 20 + json_length > size) {
      problems->add("file", "GLB JSON chunk length " + std::to_string(json_length) +
                                " runs past the end of the file (" + std::to_string(size) +
                                " bytes)");
      return false;
    }
    text = std::string_view(reinterpret_cast<const char*>(p + 20), json_length);
    std::uint64_t at = 20 + json_length;
    if (at % 4 != 0) {
      problems->add("file", "GLB JSON chunk length " + std::to_string(json_length) +
                                " is not a multiple of 4");
      return false;
    }
    if (at < size) {
      if (at + 8 > size) {
        problems->add("file", "truncated GLB: chunk 1 header runs past the end of the file");
        return false;
      }
      const std::uint64_t bin_length = readU32(p + at);
      const std::uint32_t bin_type = readU32(p + at + 4);
      if (at + 8 + bin_length > size) {
        problems->add("file", "GLB BIN chunk length " + std::to_string(bin_length) +
                                  " runs past the end of the file (" +
                                  std::to_string(size - at - 8) + " bytes left)");
        return false;
      }
      if (bin_type != 0x004E4942u) {
        problems->add("file", "GLB chunk 1 is not BIN");
        return false;
      }
      if (bin_length % 4 != 0) {
        problems->add("file", "GLB BIN chunk length " + std::to_string(bin_length) +
                                  " is not a multiple of 4");
        return false;
      }
      doc->bin = bytes.subspan(at + 8, bin_length);
    }
  } else {
    std::size_t first = 0;
    while (first < size &&
           (p[first] == ' ' || p[first] == '\t' || p[first] == '\n' || p[first] == '\r')) {
      ++first;
    }
    if (first == size || p[first] != '{') {
      problems->add("file",
                    "not glTF: wrong magic (a .glb starts with 'glTF', a .gltf with a "
                    "JSON object '{')");
      return false;
    }
    text = std::string_view(reinterpret_cast<const char*>(p), size);
  }
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
  doc->json_text.assign(text.begin(), text.end());
  return true;
}

namespace {

void parseHapticExtras(Checker& c,
                       const json& owner,
                       const std::string& where,
                       bool* probe,
                       std::optional<double>* stiffness,
                       std::optional<Vec3>* gravity,
                       std::optional<bool>* active) {
  const json* extras = Checker::find(owner, "extras");
  if (!extras || !extras->is_object())
    return;  // extras are free-form; only ours are checked
  const json* haptic = nullptr;
  if (c.object(*extras, "haptic", where + " extras", &haptic) != Got::kOk)
    return;
  const std::string w = where + " extras.haptic";
  for (auto it = haptic->begin(); it != haptic->end(); ++it) {
    const std::string& key = it.key();
    const bool known = (probe && key == "probe") || (stiffness && key == "stiffness") ||
                       (gravity && key == "gravity") || (active && key == "active");
    if (!known)
      c.add(w, "unknown property " + inQuotes(key));
  }
  if (probe)
    c.boolean(*haptic, "probe", w, probe);
  double k = 0.0;
  if (stiffness && c.bounded(*haptic, "stiffness", w, &k, 0.0, true) == Got::kOk)
    *stiffness = k;
  Vec3 g{0.0};
  if (gravity && c.vec3(*haptic, "gravity", w, &g) == Got::kOk)
    *gravity = g;
  bool on = true;
  if (active && c.boolean(*haptic, "active", w, &on) == Got::kOk)
    *active = on;
}

Combine parseCombine(Checker& c, const json& o, const char* key, const std::string& where) {
  std::string s;
  if (c.string(o, key, where, &s) != Got::kOk)
    return Combine::kAverage;
  if (s == "average")
    return Combine::kAverage;
  if (s == "minimum")
    return Combine::kMinimum;
  if (s == "maximum")
    return Combine::kMaximum;
  if (s == "multiply")
    return Combine::kMultiply;
  c.add(where, std::string(key) + " " + inQuotes(s) +
                   " is not one of 'average', 'minimum', 'maximum', 'multiply'");
  return Combine::kAverage;
}

void parseShapes(Checker& c, const json& ext, Document* doc) {
  const json* shapes = nullptr;
  if (c.array(ext, "shapes", "KHR_implicit_shapes", &shapes) != Got::kOk)
    return;
  for (std::size_t i = 0; i < shapes->size(); ++i) {
    const json& s = (*shapes)[i];
    const std::string w = "KHR_implicit_shapes shape " + std::to_string(i);
    ShapeDef def;
    if (!s.is_object()) {
      c.add(w, "must be an object");
      doc->shapes.push_back(def);
      continue;
    }
    std::string type;
    if (c.string(s, "type", w, &type, true) == Got::kOk) {
      const json* p = nullptr;
      const Got got = c.object(s, type.c_str(), w, &p);
      static const json kEmpty = json::object();
      if (got == Got::kAbsent)
        p = &kEmpty;  // every parameter has a default
      if (p) {
        if (type == "box") {
          def.type = ShapeType::kBox;
          if (c.vec3(*p, "size", w + " box", &def.size) == Got::kOk &&
              !(def.size.x > 0.0 && def.size.y > 0.0 && def.size.z > 0.0)) {
            c.add(w + " box",
                  "size must be positive on every axis (degenerate shapes are "
                  "prohibited)");
          }
        } else if (type == "sphere") {
          def.type = ShapeType::kSphere;
          c.bounded(*p, "radius", w + " sphere", &def.radius, 0.0, true);
        } else if (type == "capsule" || type == "cylinder") {
          def.type = type == "capsule" ? ShapeType::kCapsule : ShapeType::kCylinder;
          const std::string ww = w + " " + type;
          c.bounded(*p, "height", ww, &def.height, 0.0, true);
          c.bounded(*p, "radiusTop", ww, &def.radius_top, 0.0, false);
          c.bounded(*p, "radiusBottom", ww, &def.radius_bottom, 0.0, false);
          if (!(def.radius_top > 0.0) && !(def.radius_bottom > 0.0)) {
            c.add(ww, "radiusTop and radiusBottom are both 0 (degenerate shapes are prohibited)");
          }
        } else if (type == "plane") {
          def.type = ShapeType::kPlane;
          double v = 0.0;
          if (c.bounded(*p, "sizeX", w + " plane", &v, 0.0, true) == Got::kOk)
            def.size_x = v;
          if (c.bounded(*p, "sizeZ", w + " plane", &v, 0.0, true) == Got::kOk)
            def.size_z = v;
          if (def.size_x.has_value() != def.size_z.has_value()) {
            c.add(w + " plane", "give both sizeX and sizeZ, or neither (infinite)");
          }
          c.boolean(*p, "doubleSided", w + " plane", &def.double_sided);
        } else {
          c.add(w, "shape type " + inQuotes(type) +
                       " is not supported (box, sphere, capsule, cylinder, plane)");
        }
      }
    }
    doc->shapes.push_back(def);
  }
}

void parsePhysicsRoot(Checker& c, const json& ext, Document* doc) {
  const std::string root = "KHR_physics_rigid_bodies";
  const json* arr = nullptr;
  if (c.array(ext, "physicsMaterials", root, &arr) == Got::kOk) {
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const json& m = (*arr)[i];
      const std::string w = "physicsMaterial " + std::to_string(i);
      Material mat;
      mat.name = "material" + std::to_string(i);
      if (!m.is_object()) {
        c.add(w, "must be an object");
      } else {
        c.string(m, "name", w, &mat.name);
        c.bounded(m, "staticFriction", w, &mat.static_friction, 0.0, false);
        c.bounded(m, "dynamicFriction", w, &mat.dynamic_friction, 0.0, false);
        c.bounded(m, "restitution", w, &mat.restitution, 0.0, false);
        mat.friction_combine = parseCombine(c, m, "frictionCombine", w);
        mat.restitution_combine = parseCombine(c, m, "restitutionCombine", w);
      }
      doc->materials.push_back(mat);
    }
  }
  if (c.array(ext, "collisionFilters", root, &arr) == Got::kOk) {
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const json& f = (*arr)[i];
      const std::string w = "collisionFilter " + std::to_string(i);
      FilterDef def;
      if (!f.is_object()) {
        c.add(w, "must be an object");
      } else {
        c.strings(f, "collisionSystems", w, &def.systems);
        const Got with = c.strings(f, "collideWithSystems", w, &def.collide_with);
        const Got not_with = c.strings(f, "notCollideWithSystems", w, &def.not_collide_with);
        if (with == Got::kOk && not_with == Got::kOk) {
          c.add(w, "give collideWithSystems or notCollideWithSystems, not both");
        }
      }
      doc->filters.push_back(def);
    }
  }
  if (c.array(ext, "physicsJoints", root, &arr) == Got::kOk) {
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const json& j = (*arr)[i];
      const std::string w = "physicsJoint " + std::to_string(i);
      JointDef def;
      if (!j.is_object()) {
        c.add(w, "must be an object");
        doc->joints.push_back(def);
        continue;
      }
      const json* drives = nullptr;
      if (c.array(j, "drives", w, &drives) == Got::kOk && !drives->empty()) {
        c.add(w, "joint drives are not supported");
      }
      const json* limits = nullptr;
      if (c.array(j, "limits", w, &limits) == Got::kOk) {
        for (std::size_t k = 0; k < limits->size(); ++k) {
          const json& l = (*limits)[k];
          const std::string lw = w + " limit " + std::to_string(k);
          JointLimit lim;
          if (!l.is_object()) {
            c.add(lw, "must be an object");
            continue;
          }
          const auto axes = [&](const char* key, std::uint8_t* bits) {
            const json* a = nullptr;
            if (c.array(l, key, lw, &a) != Got::kOk)
              return false;
            if (a->empty() || a->size() > 3)
              c.add(lw, std::string(key) + " must list 1 to 3 axes");
            for (const json& e : *a) {
              std::int32_t axis = 0;
              if (c.indexValue(e, key, 3, "axes", lw, &axis) != Got::kOk)
                continue;
              const auto bit = static_cast<std::uint8_t>(1u << axis);
              if (*bits & bit)
                c.add(lw, std::string(key) + " lists axis " + std::to_string(axis) + " twice");
              *bits = static_cast<std::uint8_t>(*bits | bit);
            }
            return true;
          };
          const bool linear = axes("linearAxes", &lim.linear_axes);
          const bool angular = axes("angularAxes", &lim.angular_axes);
          if (linear == angular) {
            c.add(lw, "give exactly one of linearAxes and angularAxes");
          }
          double v = 0.0;
          if (c.number(l, "min", lw, &v) == Got::kOk)
            lim.min = v;
          if (c.number(l, "max", lw, &v) == Got::kOk)
            lim.max = v;
          if (lim.min && lim.max && *lim.min > *lim.max) {
            c.add(lw, "min " + num(*lim.min) + " is above max " + num(*lim.max));
          }
          if (c.bounded(l, "stiffness", lw, &v, 0.0, false) == Got::kOk)
            lim.stiffness = v;
          c.bounded(l, "damping", lw, &lim.damping, 0.0, false);
          def.limits.push_back(lim);
        }
      }
      doc->joints.push_back(def);
    }
  }
}

void parseNodePhysics(Checker& c,
                      const json& ext,
                      const std::string& w,
                      std::size_t node_count,
                      const Document& doc,
                      NodeDef* node) {
  const json* motion = nullptr;
  if (c.object(ext, "motion", w, &motion) == Got::kOk) {
    const std::string mw = w + " motion";
    MotionDef m;
    c.boolean(*motion, "isKinematic", mw, &m.kinematic);
    double v = 0.0;
    if (c.bounded(*motion, "mass", mw, &v, 0.0, false) == Got::kOk)
      m.mass = v;
    Vec3 vec{0.0};
    if (c.vec3(*motion, "centerOfMass", mw, &vec) == Got::kOk)
      m.center_of_mass = vec;
    if (c.vec3(*motion, "inertiaDiagonal", mw, &vec) == Got::kOk) {
      if (vec.x < 0.0 || vec.y < 0.0 || vec.z < 0.0) {
        c.add(mw, "inertiaDiagonal must not be negative");
      } else {
        m.inertia_diagonal = vec;
      }
    }
    c.quaternion(*motion, "inertiaOrientation", mw, &m.inertia_orientation);
    c.vec3(*motion, "linearVelocity", mw, &m.linear_velocity);
    c.vec3(*motion, "angularVelocity", mw, &m.angular_velocity);
    c.number(*motion, "gravityFactor", mw, &m.gravity_factor);
    node->motion = m;
  }
  const json* collider = nullptr;
  if (c.object(ext, "collider", w, &collider) == Got::kOk) {
    const std::string cw = w + " collider";
    ColliderDef def;
    const json* geometry = nullptr;
    if (c.object(*collider, "geometry", cw, &geometry, true) == Got::kOk) {
      const std::string gw = cw + " geometry";
      const Got shape = c.index(*geometry, "shape", doc.shapes.size(), "KHR_implicit_shapes shapes",
                                gw, &def.shape);
      const Got mesh_node = c.index(*geometry, "node", node_count, "nodes", gw, &def.geometry_node);
      if ((shape == Got::kAbsent) == (mesh_node == Got::kAbsent)) {
        c.add(gw, "give exactly one of shape and node");
      }
      c.boolean(*geometry, "convexHull", gw, &def.convex_hull);
    }
    c.index(*collider, "physicsMaterial", doc.materials.size(), "physicsMaterials", cw,
            &def.material);
    c.index(*collider, "collisionFilter", doc.filters.size(), "collisionFilters", cw, &def.filter);
    node->collider = def;
  }
  const json* joint = nullptr;
  if (c.object(ext, "joint", w, &joint) == Got::kOk) {
    const std::string jw = w + " joint";
    JointRef ref;
    c.index(*joint, "connectedNode", node_count, "nodes", jw, &ref.connected_node, true);
    c.index(*joint, "joint", doc.joints.size(), "physicsJoints", jw, &ref.joint, true);
    c.boolean(*joint, "enableCollision", jw, &ref.enable_collision);
    node->joint = ref;
  }
}

}  // namespace

bool validateDocument(const nlohmann::json& root,
                      const LoadOptions& options,
                      Document* doc,
                      Problems* problems) {
  Checker c(problems);
  const SceneLimits& limits = options.limits;

  // asset
  const json* asset = nullptr;
  if (c.object(root, "asset", "asset", &asset, true) == Got::kOk) {
    std::string version;
    if (c.string(*asset, "version", "asset", &version, true) == Got::kOk &&
        version.rfind("2.", 0) != 0) {
      c.add("asset", "glTF version " + inQuotes(version) + " is not 2.x");
    }
  }

  // required extensions
  std::vector<std::string> required;
  if (c.strings(root, "extensionsRequired", "extensionsRequired", &required) == Got::kOk) {
    for (const std::string& e : required) {
      if (std::find(std::begin(kSupportedExtensions), std::end(kSupportedExtensions), e) ==
          std::end(kSupportedExtensions)) {
        c.add("extensionsRequired", "unsupported required extension " + inQuotes(e) +
                                        " (supported: KHR_physics_rigid_bodies, "
                                        "KHR_implicit_shapes)");
      }
    }
  }
  std::vector<std::string> used;
  c.strings(root, "extensionsUsed", "extensionsUsed", &used);

  bool structure_ok = true;
  const auto top = [&](const char* key) -> const json* {
    const json* a = nullptr;
    const Got got = c.array(root, key, key, &a);
    if (got == Got::kBad)
      structure_ok = false;
    if (got != Got::kOk)
      return nullptr;
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (!(*a)[i].is_object()) {
        structure_ok = false;
        c.add(std::string(key) + " " + std::to_string(i),
              "must be an object, got " + std::string((*a)[i].type_name()));
        return nullptr;
      }
    }
    return a;
  };
  const json* buffers = top("buffers");
  const json* views = top("bufferViews");
  const json* accessors = top("accessors");
  const json* meshes = top("meshes");
  const json* nodes = top("nodes");
  const json* scenes = top("scenes");
  const json* materials = top("materials");
  const json* images = top("images");
  if (!structure_ok)
    return false;

  // buffers: external URIs only inside the allowed folder
  if (buffers) {
    for (std::size_t i = 0; i < buffers->size(); ++i) {
      const json& b = (*buffers)[i];
      const std::string w = "buffer " + std::to_string(i);
      BufferDef def;
      if (c.uinteger(b, "byteLength", w, &def.byte_length, true) == Got::kOk &&
          def.byte_length == 0) {
        c.add(w, "byteLength must be at least 1");
      }
      if (c.string(b, "uri", w, &def.uri) == Got::kOk) {
        if (def.uri.rfind("data:", 0) != 0) {
          std::string why;
          if (!resolveUri(def.uri, options, &why))
            c.add(w, why);
        }
      } else if (!(doc->glb && i == 0)) {
        c.add(w, "has no uri and is not the GLB binary chunk");
      } else if (def.byte_length > doc->bin.size()) {
        c.add(w, "byteLength " + std::to_string(def.byte_length) + " exceeds the GLB BIN chunk (" +
                     std::to_string(doc->bin.size()) + " bytes)");
      }
      doc->buffers.push_back(def);
    }
  }
  if (images) {
    for (std::size_t i = 0; i < images->size(); ++i) {
      std::string uri;
      const std::string w = "image " + std::to_string(i);
      if (c.string((*images)[i], "uri", w, &uri) == Got::kOk && uri.rfind("data:", 0) != 0) {
        std::string why;
        if (!resolveUri(uri, options, &why))
          c.add(w, why);
      }
    }
  }

  if (views) {
    for (std::size_t i = 0; i < views->size(); ++i) {
      const json& v = (*views)[i];
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
        std::uint64_t end = 0;
        const std::uint64_t blen = doc->buffers[def.buffer].byte_length;
        if (!addU64(def.byte_offset, def.byte_length, &end) || end > blen) {
          c.add(w, "byteOffset " + std::to_string(def.byte_offset) + " + byteLength " +
                       std::to_string(def.byte_length) + " runs past the end of buffer " +
                       std::to_string(def.buffer) + " (" + std::to_string(blen) + " bytes)");
        }
      }
      doc->views.push_back(def);
    }
  }

  if (accessors) {
    for (std::size_t i = 0; i < accessors->size(); ++i) {
      const json& a = (*accessors)[i];
      const std::string w = "accessor " + std::to_string(i);
      AccessorDef def;
      std::string name;
      c.string(a, "name", w, &name);
      const std::string wn = name.empty() ? w : w + " " + inQuotes(name);
      c.index(a, "bufferView", doc->views.size(), "bufferViews", wn, &def.view);
      c.uinteger(a, "byteOffset", wn, &def.byte_offset);
      std::uint64_t ct = 0;
      if (c.uinteger(a, "componentType", wn, &ct, true) == Got::kOk) {
        if (ct > 0xFFFF || componentBytes(static_cast<std::uint32_t>(ct)) == 0) {
          c.add(wn, "componentType " + std::to_string(ct) + " is not a glTF component type");
        } else {
          def.component_type = static_cast<std::uint32_t>(ct);
        }
      }
      if (c.uinteger(a, "count", wn, &def.count, true) == Got::kOk && def.count == 0) {
        c.add(wn, "count must be at least 1");
      }
      if (c.string(a, "type", wn, &def.type, true) == Got::kOk) {
        def.components = typeComponents(def.type);
        if (def.components == 0)
          c.add(wn, "type " + inQuotes(def.type) + " is not a glTF type");
      }
      c.boolean(a, "normalized", wn, &def.normalized);
      if (Checker::find(a, "sparse"))
        c.add(wn, "sparse accessors are not supported");
      // the data must lie inside the view: offset + (count - 1) * stride + element <= length,
      // in 64 bits with overflow checks (a count near 2^32 must not wrap)
      if (def.view >= 0 && def.component_type != 0 && def.components != 0 && def.count > 0) {
        const ViewDef& view = doc->views[static_cast<std::size_t>(def.view)];
        const std::uint64_t element = def.elementBytes();
        const std::uint64_t stride = def.strideBytes(doc->views);
        std::uint64_t span = 0, end = 0;
        const bool fits = mulU64(def.count - 1, stride, &span) && addU64(span, element, &span) &&
                          addU64(span, def.byte_offset, &end);
        if (!fits || end > view.byte_length) {
          c.add(wn, "byteOffset " + std::to_string(def.byte_offset) + " + count " +
                        std::to_string(def.count) + " x stride " + std::to_string(stride) +
                        (fits ? " = " + std::to_string(end) : std::string(" overflows and")) +
                        " runs past the end of bufferView " + std::to_string(def.view) + " (" +
                        std::to_string(view.byte_length) + " bytes)");
        }
        if (def.byte_offset % componentBytes(def.component_type) != 0) {
          c.add(wn, "byteOffset " + std::to_string(def.byte_offset) +
                        " is not a multiple of the component size");
        }
      }
      doc->accessors.push_back(def);
    }
  }

  const std::size_t material_count = materials ? materials->size() : 0;
  if (meshes) {
    for (std::size_t i = 0; i < meshes->size(); ++i) {
      const json& m = (*meshes)[i];
      MeshDef def;
      c.string(m, "name", "mesh " + std::to_string(i), &def.name);
      const std::string w =
          "mesh " + std::to_string(i) + (def.name.empty() ? "" : " " + inQuotes(def.name));
      const json* prims = nullptr;
      if (c.array(m, "primitives", w, &prims, true) == Got::kOk) {
        if (prims->empty())
          c.add(w, "primitives is empty");
        for (std::size_t k = 0; k < prims->size(); ++k) {
          const json& p = (*prims)[k];
          const std::string pw = w + " primitive " + std::to_string(k);
          MeshPrimitiveDef pd;
          if (!p.is_object()) {
            c.add(pw, "must be an object");
            continue;
          }
          const json* attributes = nullptr;
          if (c.object(p, "attributes", pw, &attributes, true) == Got::kOk) {
            for (auto it = attributes->begin(); it != attributes->end(); ++it) {
              std::int32_t idx = -1;
              if (c.indexValue(it.value(), "attribute " + it.key(), doc->accessors.size(),
                               "accessors", pw, &idx) == Got::kOk &&
                  it.key() == "POSITION") {
                pd.position = idx;
              }
            }
          }
          c.index(p, "indices", doc->accessors.size(), "accessors", pw, &pd.indices);
          std::int32_t material = -1;
          c.index(p, "material", material_count, "materials", pw, &material);
          std::uint64_t mode = 4;
          if (c.uinteger(p, "mode", pw, &mode) == Got::kOk && mode > 6) {
            c.add(pw, "mode " + std::to_string(mode) + " is not a glTF primitive mode");
          }
          pd.mode = static_cast<std::int32_t>(std::min<std::uint64_t>(mode, 7));
          def.primitives.push_back(pd);
        }
      }
      doc->meshes.push_back(def);
    }
  }

  // root extensions: shapes first, then materials, filters, joints (nodes index them)
  const json* extensions = nullptr;
  if (c.object(root, "extensions", "extensions", &extensions) == Got::kOk) {
    const json* shapes = nullptr;
    if (c.object(*extensions, "KHR_implicit_shapes", "extensions", &shapes) == Got::kOk) {
      parseShapes(c, *shapes, doc);
    }
    const json* physics = nullptr;
    if (c.object(*extensions, "KHR_physics_rigid_bodies", "extensions", &physics) == Got::kOk) {
      parsePhysicsRoot(c, *physics, doc);
    }
  }

  // nodes
  const std::size_t node_count = nodes ? nodes->size() : 0;
  if (node_count > limits.max_nodes) {
    c.add("nodes", std::to_string(node_count) + " nodes exceeds max_nodes (" +
                       std::to_string(limits.max_nodes) + ")");
    return false;
  }
  doc->nodes.resize(node_count);
  for (std::size_t i = 0; i < node_count; ++i) {
    const json& n = (*nodes)[i];
    NodeDef& def = doc->nodes[i];
    c.string(n, "name", "node " + std::to_string(i), &def.name);
  }
  for (std::size_t i = 0; i < node_count; ++i) {
    const json& n = (*nodes)[i];
    NodeDef& def = doc->nodes[i];
    const std::string w = nodeWhere(*doc, i);
    const json* children = nullptr;
    if (c.array(n, "children", w, &children) == Got::kOk) {
      for (const json& e : *children) {
        std::int32_t child = -1;
        if (c.indexValue(e, "children", node_count, "nodes", w, &child) != Got::kOk)
          continue;
        if (static_cast<std::size_t>(child) == i) {
          c.add(w, "lists itself as a child (a node cycle)");
          continue;
        }
        def.children.push_back(static_cast<std::uint32_t>(child));
      }
    }
    c.index(n, "mesh", doc->meshes.size(), "meshes", w, &def.mesh);
    double m[16];
    const Got matrix = c.vector(n, "matrix", 16, w, m);
    const Got t = c.vec3(n, "translation", w, &def.translation);
    const Got r = c.quaternion(n, "rotation", w, &def.rotation);
    const Got s = c.vec3(n, "scale", w, &def.scale);
    if (matrix == Got::kOk) {
      if (t != Got::kAbsent || r != Got::kAbsent || s != Got::kAbsent) {
        c.add(w, "has both matrix and translation/rotation/scale");
      }
      if (m[3] != 0.0 || m[7] != 0.0 || m[11] != 0.0 || m[15] != 1.0) {
        c.add(w, "matrix is not affine (its last row must be 0 0 0 1)");
      }
      def.has_matrix = true;
      for (int col = 0; col < 4; ++col) {
        for (int row = 0; row < 4; ++row)
          def.matrix[col][row] = m[col * 4 + row];
      }
    }
    const json* ext = nullptr;
    if (c.object(n, "extensions", w, &ext) == Got::kOk) {
      const json* physics = nullptr;
      if (c.object(*ext, "KHR_physics_rigid_bodies", w + " extensions", &physics) == Got::kOk) {
        parseNodePhysics(c, *physics, w, node_count, *doc, &def);
      }
    }
    parseHapticExtras(c, n, w, &def.probe, &def.stiffness, nullptr, &def.active);
  }

  // hierarchy: one parent per node, no cycles
  for (std::size_t i = 0; i < node_count; ++i) {
    for (std::uint32_t child : doc->nodes[i].children) {
      NodeDef& cn = doc->nodes[child];
      if (cn.parent == static_cast<std::int32_t>(i)) {
        c.add(nodeWhere(*doc, child),
              "is listed twice among the children of " + nodeWhere(*doc, i));
      } else if (cn.parent >= 0) {
        c.add(nodeWhere(*doc, child), "has two parents (" +
                                          nodeWhere(*doc, static_cast<std::size_t>(cn.parent)) +
                                          " and " + nodeWhere(*doc, i) + ")");
      } else {
        cn.parent = static_cast<std::int32_t>(i);
      }
    }
  }
  {
    // walk up the parent links; a walk that meets its own trail is a cycle
    std::vector<std::uint8_t> state(node_count, 0);  // 0 new, 1 on the current walk, 2 done
    std::vector<std::size_t> trail;
    for (std::size_t i = 0; i < node_count; ++i) {
      trail.clear();
      std::size_t k = i;
      bool cycle = false;
      while (true) {
        if (state[k] == 2)
          break;
        if (state[k] == 1) {
          cycle = true;
          break;
        }
        state[k] = 1;
        trail.push_back(k);
        if (doc->nodes[k].parent < 0)
          break;
        k = static_cast<std::size_t>(doc->nodes[k].parent);
      }
      if (cycle)
        c.add(nodeWhere(*doc, k), "is in a cycle of node children");
      for (std::size_t t : trail)
        state[t] = 2;
    }
  }

  // scenes and the scene to load
  std::vector<std::vector<std::uint32_t>> scene_nodes;
  if (scenes) {
    for (std::size_t i = 0; i < scenes->size(); ++i) {
      const json& s = (*scenes)[i];
      const std::string w = "scene " + std::to_string(i);
      std::vector<std::uint32_t> roots;
      std::vector<bool> listed(node_count, false);
      const json* list = nullptr;
      if (c.array(s, "nodes", w, &list) == Got::kOk) {
        for (const json& e : *list) {
          std::int32_t idx = -1;
          if (c.indexValue(e, "nodes", node_count, "nodes", w, &idx) != Got::kOk)
            continue;
          if (doc->nodes[static_cast<std::size_t>(idx)].parent >= 0) {
            c.add(w, nodeWhere(*doc, static_cast<std::size_t>(idx)) +
                         " is listed as a root but has a parent");
            continue;
          }
          if (listed[static_cast<std::size_t>(idx)]) {
            c.add(w, nodeWhere(*doc, static_cast<std::size_t>(idx)) + " is listed twice");
            continue;
          }
          listed[static_cast<std::size_t>(idx)] = true;
          roots.push_back(static_cast<std::uint32_t>(idx));
        }
      }
      scene_nodes.push_back(std::move(roots));
    }
  }
  std::int32_t scene = scene_nodes.empty() ? -1 : 0;
  c.index(root, "scene", scene_nodes.size(), "scenes", "file", &scene);
  if (scene >= 0) {
    const auto si = static_cast<std::size_t>(scene);
    doc->scene_roots = scene_nodes[si];
    std::optional<Vec3> g;
    parseHapticExtras(c, (*scenes)[si], "scene " + std::to_string(scene), nullptr, nullptr, &g,
                      nullptr);
    if (g) {
      doc->gravity = g;
      doc->gravity_where = "scene " + std::to_string(scene);
    }
  } else {
    // no scenes: every root node is in the scene
    for (std::size_t i = 0; i < node_count; ++i) {
      if (doc->nodes[i].parent < 0)
        doc->scene_roots.push_back(static_cast<std::uint32_t>(i));
    }
  }
  if (asset) {
    std::optional<Vec3> g;
    parseHapticExtras(c, *asset, "asset", nullptr, nullptr, &g, nullptr);
    if (g && doc->gravity && *g != *doc->gravity) {
      c.add("asset", "gravity differs from the gravity of " + doc->gravity_where);
    } else if (g && !doc->gravity) {
      doc->gravity = g;
      doc->gravity_where = "asset";
    }
  }
  return !problems->any();
}

}  // namespace hapticd::scene::detail
