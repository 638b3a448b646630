#include "client/ply.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

#include "client/polygon.h"

namespace hapticd::client {
namespace {

using decomp::TriangleMesh;
using decomp::Vec3;

constexpr std::uint32_t kBad = std::numeric_limits<std::uint32_t>::max();

enum class Format { kAscii, kLittle, kBig };

// a scalar type of the format: its size in bytes, and how its bytes read
enum class Kind { kInt, kUint, kFloat };
struct Type {
  std::uint8_t size = 0;
  Kind kind = Kind::kInt;
};

std::optional<Type> typeNamed(const std::string& name) {
  struct Named {
    const char* a;
    const char* b;
    Type t;
  };
  static constexpr std::array<Named, 8> kTypes{{{"char", "int8", {1, Kind::kInt}},
                                                {"uchar", "uint8", {1, Kind::kUint}},
                                                {"short", "int16", {2, Kind::kInt}},
                                                {"ushort", "uint16", {2, Kind::kUint}},
                                                {"int", "int32", {4, Kind::kInt}},
                                                {"uint", "uint32", {4, Kind::kUint}},
                                                {"float", "float32", {4, Kind::kFloat}},
                                                {"double", "float64", {8, Kind::kFloat}}}};
  for (const Named& n : kTypes) {
    if (name == n.a || name == n.b)
      return n.t;
  }
  return std::nullopt;
}

struct Property {
  std::string name;
  Type type;  // of the value, or of a list's items
  bool list = false;
  Type count;  // a list's count
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t data = 0;  // the first byte after the end_header line
};

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t'))
    s.pop_back();
  return s;
}

Result<Header> parseHeader(std::string_view bytes, const std::string& name) {
  auto fail = [&name](std::size_t line, const std::string& what) {
    return Error{name + ": PLY header line " + std::to_string(line) + ": " + what};
  };
  if (bytes.empty())
    return Error{name + ": the file is empty"};
  Header h;
  std::size_t at = 0, line_no = 0;
  bool format_seen = false;
  for (;;) {
    const std::size_t end = bytes.find('\n', at);
    if (end == std::string_view::npos)
      return Error{name + ": PLY header has no end_header line"};
    const std::string line = trimmed(std::string(bytes.substr(at, end - at)));
    at = end + 1;
    ++line_no;
    std::istringstream words(line);
    std::string w;
    words >> w;
    if (line_no == 1) {
      if (w != "ply")
        return Error{name + ": not a PLY file (its first line is not 'ply')"};
      continue;
    }
    if (w.empty() || w == "comment" || w == "obj_info")
      continue;
    if (w == "end_header") {
      if (!format_seen)
        return fail(line_no, "end_header before a format line");
      h.data = at;
      return h;
    }
    if (w == "format") {
      std::string f;
      words >> f;
      if (f == "ascii")
        h.format = Format::kAscii;
      else if (f == "binary_little_endian")
        h.format = Format::kLittle;
      else if (f == "binary_big_endian")
        h.format = Format::kBig;
      else
        return fail(line_no, "unknown format '" + f + "'");
      format_seen = true;
    } else if (w == "element") {
      Element e;
      std::string count;
      words >> e.name >> count;
      char* stop = nullptr;
      errno = 0;
      const unsigned long long n = std::strtoull(count.c_str(), &stop, 10);
      if (e.name.empty() || count.empty() || *stop != '\0' || count[0] == '-' || errno != 0)
        return fail(line_no, "'" + line + "' is not 'element NAME COUNT'");
      e.count = n;
      h.elements.push_back(std::move(e));
    } else if (w == "property") {
      if (h.elements.empty())
        return fail(line_no, "a property before any element");
      Property p;
      std::string t;
      words >> t;
      if (t == "list") {
        std::string ct, it;
        words >> ct >> it >> p.name;
        const auto c = typeNamed(ct), i = typeNamed(it);
        if (!c || !i || p.name.empty() || c->kind == Kind::kFloat)
          return fail(line_no, "'" + line + "' is not 'property list COUNT_TYPE TYPE NAME'");
        p.list = true;
        p.count = *c;
        p.type = *i;
      } else {
        words >> p.name;
        const auto s = typeNamed(t);
        if (!s || p.name.empty())
          return fail(line_no, "'" + line + "' is not 'property TYPE NAME' with a PLY type");
        p.type = *s;
      }
      h.elements.back().properties.push_back(std::move(p));
    }
    // any other line is taken as a comment, as other readers do (Blender 2.4 wrote
    // "Created by Blender3D ..." without the comment keyword)
  }
}

// The data after the header, value by value, in either encoding. Every read says whether it
// found a value; the caller turns a miss into an error naming the element.
class Values {
 public:
  Values(std::string_view data, Format format) : d_(data), format_(format) {}

  // a scalar as a double (coordinates) or nothing (the data ended, or an ASCII word that is not
  // a number)
  std::optional<double> real(Type t) {
    if (format_ == Format::kAscii)
      return word();
    if (d_.size() - at_ < t.size)
      return std::nullopt;
    std::array<unsigned char, 8> b{};
    std::memcpy(b.data(), d_.data() + at_, t.size);
    at_ += t.size;
    if ((format_ == Format::kBig) != (std::endian::native == std::endian::big))
      std::reverse(b.begin(), b.begin() + t.size);
    switch (t.kind) {
      case Kind::kFloat:
        if (t.size == 4) {
          float f = 0.0f;
          std::memcpy(&f, b.data(), 4);
          return f;
        } else {
          double x = 0.0;
          std::memcpy(&x, b.data(), 8);
          return x;
        }
      case Kind::kUint:
      case Kind::kInt: {
        std::uint64_t u =
            0;  // the bytes (now the host's order, little-endian) as an unsigned number
        for (int k = t.size - 1; k >= 0; --k)
          u = (u << 8) | b[static_cast<std::size_t>(k)];
        const unsigned bits = 8u * t.size;
        if (t.kind == Kind::kUint || (u >> (bits - 1)) == 0)
          return static_cast<double>(u);
        return static_cast<double>(static_cast<std::int64_t>(u) - (std::int64_t{1} << bits));
      }
    }
    return std::nullopt;
  }

  // ASCII: an entry is a line (blank lines skipped); words past its properties are left unread,
  // as other readers do (files whose header lists fewer properties than their lines hold exist)
  void beginEntry() {
    if (format_ != Format::kAscii)
      return;
    at_ = end_ < d_.size() && end_ > 0 ? end_ + 1 : end_;
    for (;;) {
      const std::size_t nl = d_.find('\n', at_);
      end_ = nl == std::string_view::npos ? d_.size() : nl;
      if (end_ >= d_.size() ||
          d_.substr(at_, end_ - at_).find_first_not_of(" \t\r\f\v") != std::string_view::npos)
        return;
      at_ = end_ + 1;
    }
  }

  bool skip(Type t) {
    if (format_ == Format::kAscii)
      return word().has_value();
    if (d_.size() - at_ < t.size)
      return false;
    at_ += t.size;
    return true;
  }

  // at least this many more values could follow (the smallest a value takes: a byte and a
  // separator in ASCII, its size in binary): a count in the header larger than the file can
  // hold is refused before anything is reserved for it
  bool room(std::uint64_t values, std::uint64_t bytes_each) const {
    const std::uint64_t left = d_.size() - at_;
    const std::uint64_t each = format_ == Format::kAscii ? 1 : bytes_each;
    return each == 0 || values <= left / each;
  }

 private:
  std::optional<double> word() {
    while (at_ < end_ && std::isspace(static_cast<unsigned char>(d_[at_])) != 0)
      ++at_;
    const std::size_t begin = at_;
    while (at_ < end_ && std::isspace(static_cast<unsigned char>(d_[at_])) == 0)
      ++at_;
    if (at_ == begin)
      return std::nullopt;
    const std::string w(d_.substr(begin, at_ - begin));
    char* stop = nullptr;
    const double x = std::strtod(w.c_str(), &stop);
    if (*stop != '\0')
      return std::nullopt;
    return x;
  }

  std::string_view d_;
  Format format_;
  std::size_t at_ = 0;
  std::size_t end_ = 0;  // ASCII: the end of the entry's line
};

// an index as read (a double holds every 32-bit integer): outside [0, 2^32 - 1), or not whole,
// it is no vertex
std::uint32_t indexOf(double x) {
  return x >= 0.0 && x < static_cast<double>(kBad) && x == std::floor(x)
             ? static_cast<std::uint32_t>(x)
             : kBad;
}

}  // namespace

Result<TriangleMesh> parsePly(std::string_view bytes, const std::string& name) {
  Result<Header> parsed = parseHeader(bytes, name);
  if (!parsed)
    return parsed.error();
  const Header& h = parsed.value();
  Values values(bytes.substr(h.data), h.format);
  const std::string missing = h.format == Format::kAscii
                                  ? "a value is missing from its line, or is not a number"
                                  : "the file ends";
  TriangleMesh mesh;
  bool vertices_seen = false;
  std::vector<std::uint32_t> poly;
  for (const Element& e : h.elements) {
    auto where = [&](std::uint64_t k) {
      return name + ": PLY element " + e.name + ", " + std::to_string(k + 1) + " of " +
             std::to_string(e.count) + ": ";
    };
    std::uint64_t bytes_each = 0;
    for (const Property& p : e.properties)
      bytes_each += p.list ? p.count.size : p.type.size;
    if (e.count > 0 && e.properties.empty())
      return Error{name + ": PLY element " + e.name + " has entries but no properties"};
    if (!values.room(e.count, bytes_each))
      return Error{name + ": PLY element " + e.name + " counts " + std::to_string(e.count) +
                   " entries, more than the file holds"};
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    const bool is_strips = e.name == "tristrips";
    std::array<int, 3> xyz{-1, -1, -1};
    int indices = -1;
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& p = e.properties[i];
      for (int c = 0; c < 3; ++c) {
        if (!p.list && p.name == std::string(1, static_cast<char>('x' + c)))
          xyz[static_cast<std::size_t>(c)] = static_cast<int>(i);
      }
      if (p.list && (p.name == "vertex_indices" || p.name == "vertex_index") && indices < 0)
        indices = static_cast<int>(i);
    }
    if (is_vertex) {
      if (vertices_seen)
        return Error{name + ": PLY has two vertex elements"};
      vertices_seen = true;
      if (*std::min_element(xyz.begin(), xyz.end()) < 0)
        return Error{name + ": PLY element vertex has no x, y and z properties"};
      mesh.positions.reserve(e.count);
    }
    if ((is_face || is_strips) && indices < 0 && e.count > 0)
      return Error{name + ": PLY element " + e.name +
                   " has no vertex_indices (or vertex_index) list"};
    for (std::uint64_t k = 0; k < e.count; ++k) {
      values.beginEntry();
      Vec3 v{0.0};
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (p.list) {
          const std::optional<double> n = values.real(p.count);
          if (!n || *n < 0.0 || *n != std::floor(*n))
            return Error{where(k) + (n ? "a list count that is not a count" : missing)};
          const auto items = static_cast<std::uint64_t>(*n);
          if (!values.room(items, p.type.size))
            return Error{where(k) + "a list longer than the file holds"};
          const bool keep = static_cast<int>(i) == indices && (is_face || is_strips);
          if (keep)
            poly.clear();
          for (std::uint64_t j = 0; j < items; ++j) {
            const std::optional<double> x = values.real(p.type);
            if (!x)
              return Error{where(k) + missing};
            if (keep)
              poly.push_back(is_strips && *x == -1.0 ? kBad - 1 : indexOf(*x));
          }
          if (keep && is_face) {
            triangulatePolygon(mesh.positions, poly, mesh.triangles);
          } else if (keep) {
            // runs between restarts (-1, read as kBad - 1); the odd triangles of a run turned
            // back; the strips' joining triangles (a vertex twice) are no surface
            std::size_t run = 0;
            for (std::size_t j = 0; j < poly.size(); ++j) {
              if (poly[j] == kBad - 1) {
                run = j + 1;
                continue;
              }
              if (j < run + 2)
                continue;
              const std::size_t t = j - run - 2;
              const std::uint32_t a = poly[j - 2], b = poly[j - 1], c = poly[j];
              if (a == b || b == c || a == c)
                continue;
              mesh.triangles.push_back(t % 2 == 0 ? decomp::Triangle{a, b, c}
                                                  : decomp::Triangle{b, a, c});
            }
          }
          continue;
        }
        const int c =
            static_cast<int>(std::find(xyz.begin(), xyz.end(), static_cast<int>(i)) - xyz.begin());
        if (is_vertex && c < 3) {
          const std::optional<double> x = values.real(p.type);
          if (!x)
            return Error{where(k) + missing};
          v[c] = *x;
        } else if (!values.skip(p.type)) {
          return Error{where(k) + missing};
        }
      }
      if (is_vertex)
        mesh.positions.push_back(v);
    }
  }
  if (!vertices_seen)
    return Error{name + ": PLY has no vertex element"};
  return mesh;
}

Result<TriangleMesh> readPly(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f)
    return Error{path + ": cannot open: " + std::strerror(errno)};
  std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (f.bad())
    return Error{path + ": cannot read: " + std::strerror(errno)};
  return parsePly(bytes, path);
}

}  // namespace hapticd::client
