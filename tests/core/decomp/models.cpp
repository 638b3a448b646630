#include "tests/core/decomp/models.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

namespace hapticd::decomp::models {
namespace {

constexpr double kPi = std::numbers::pi;

// a deterministic value in [-1, 1] from integers
double hashNoise(std::uint64_t a, std::uint64_t b) {
  std::uint64_t h = (a * 0x9E3779B97F4A7C15ull) ^ (b + 0x632BE59BD9B4E019ull + (a << 6) + (a >> 2));
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  return static_cast<double>(h >> 11) / static_cast<double>(1ull << 53) * 2.0 - 1.0;
}

std::uint32_t u32(std::size_t i) {
  return static_cast<std::uint32_t>(i);
}

}  // namespace

void append(TriangleMesh& a, const TriangleMesh& b) {
  const std::uint32_t base = u32(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (const Triangle& t : b.triangles)
    a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
}

TriangleMesh box(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

TriangleMesh lBlock(double cell, int sub) {
  // voxels (x, y) in a 2 x 2 grid, one high, without (1, 1)
  auto filled = [](int x, int y, int z) {
    return x >= 0 && x < 2 && y >= 0 && y < 2 && z == 0 && !(x == 1 && y == 1);
  };
  TriangleMesh m;
  std::map<std::array<int, 3>, std::uint32_t> index;  // lattice points at 1/sub spacing
  auto vertex = [&](std::array<int, 3> q) {
    const auto [it, fresh] = index.try_emplace(q, u32(m.positions.size()));
    if (fresh)
      m.positions.push_back(Vec3{q[0], q[1], q[2]} * (cell / sub));
    return it->second;
  };
  for (int x = -1; x <= 2; ++x)
    for (int y = -1; y <= 2; ++y)
      for (int z = -1; z <= 1; ++z) {
        if (!filled(x, y, z))
          continue;
        for (int axis = 0; axis < 3; ++axis)
          for (int side : {-1, 1}) {
            std::array<int, 3> nb{x, y, z};
            nb[static_cast<std::size_t>(axis)] += side;
            if (filled(nb[0], nb[1], nb[2]))
              continue;
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            for (int i = 0; i < sub; ++i)
              for (int j = 0; j < sub; ++j) {
                auto corner = [&](int di, int dj) {
                  std::array<int, 3> q{x * sub, y * sub, z * sub};
                  q[static_cast<std::size_t>(axis)] += side > 0 ? sub : 0;
                  q[static_cast<std::size_t>(u)] += i + di;
                  q[static_cast<std::size_t>(v)] += j + dj;
                  return vertex(q);
                };
                const std::uint32_t a = corner(0, 0), b = corner(1, 0), c = corner(1, 1),
                                    d = corner(0, 1);
                if (side > 0) {
                  m.triangles.push_back({a, b, c});
                  m.triangles.push_back({a, c, d});
                } else {
                  m.triangles.push_back({a, c, b});
                  m.triangles.push_back({a, d, c});
                }
              }
          }
      }
  return m;
}

TriangleMesh torus(double R, double r, int nu, int nv) {
  TriangleMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
      m.positions.push_back({(R + r * std::cos(v)) * std::cos(u),
                             (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  auto id = [&](int i, int j) {
    return u32(static_cast<std::size_t>(((i + nu) % nu) * nv + (j + nv) % nv));
  };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

TriangleMesh gear(int teeth, double radius, double width) {
  // outer profile (star-shaped about the axis) and a round bore; rings of quads between them
  const int per_tooth = 8;
  const int n = teeth * per_tooth;
  const double root = 0.8 * radius, bore = 0.3 * radius;
  std::vector<double> outer(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const int phase = k % per_tooth;  // 0-1 root, 2 flank, 3-5 tip, 6 flank, 7 root
    outer[static_cast<std::size_t>(k)] =
        phase >= 3 && phase <= 5 ? radius
                                 : (phase == 2 || phase == 6 ? 0.5 * (radius + root) : root);
  }
  TriangleMesh m;
  for (int layer = 0; layer < 2; ++layer) {
    const double z = layer == 0 ? -0.5 * width : 0.5 * width;
    for (int k = 0; k < n; ++k) {
      const double a = 2 * kPi * k / n;
      m.positions.push_back({outer[static_cast<std::size_t>(k)] * std::cos(a),
                             outer[static_cast<std::size_t>(k)] * std::sin(a), z});
      m.positions.push_back({bore * std::cos(a), bore * std::sin(a), z});
    }
  }
  auto o = [&](int layer, int k) {
    return u32(static_cast<std::size_t>(layer * 2 * n + ((k + n) % n) * 2));
  };
  auto b = [&](int layer, int k) { return o(layer, k) + 1; };
  for (int k = 0; k < n; ++k) {
    // caps (bottom faces -z, top +z)
    m.triangles.push_back({o(0, k), b(0, k), b(0, k + 1)});
    m.triangles.push_back({o(0, k), b(0, k + 1), o(0, k + 1)});
    m.triangles.push_back({o(1, k), o(1, k + 1), b(1, k + 1)});
    m.triangles.push_back({o(1, k), b(1, k + 1), b(1, k)});
    // outer wall, bore wall
    m.triangles.push_back({o(0, k), o(0, k + 1), o(1, k + 1)});
    m.triangles.push_back({o(0, k), o(1, k + 1), o(1, k)});
    m.triangles.push_back({b(0, k), b(1, k + 1), b(0, k + 1)});
    m.triangles.push_back({b(0, k), b(1, k), b(1, k + 1)});
  }
  return m;
}

TriangleMesh noisySphere(double radius,
                         std::size_t triangles,
                         double noise,
                         int holes,
                         double hole_rad) {
  const int n = std::max(4, static_cast<int>(std::sqrt(static_cast<double>(triangles) / 2.0)));
  const int n_lat = n, n_lon = n;
  TriangleMesh m;
  std::vector<Vec3> dirs;
  // poles, then rings
  dirs.push_back({0, 0, 1});
  for (int i = 1; i < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      const double th = kPi * i / n_lat, ph = 2 * kPi * j / n_lon;
      dirs.push_back({std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  dirs.push_back({0, 0, -1});
  for (std::size_t k = 0; k < dirs.size(); ++k)
    m.positions.push_back(dirs[k] * radius * (1.0 + noise * hashNoise(k, 7)));
  auto ring = [&](int i, int j) {
    return u32(static_cast<std::size_t>(1 + (i - 1) * n_lon + (j + n_lon) % n_lon));
  };
  const std::uint32_t south = u32(dirs.size() - 1);
  std::vector<Vec3> centres;
  for (int h = 0; h < holes; ++h) {
    const double z = 0.8 * hashNoise(static_cast<std::uint64_t>(h), 11);
    const double ph = kPi * (hashNoise(static_cast<std::uint64_t>(h), 13) + 1.0);
    centres.push_back(
        {std::sqrt(1 - z * z) * std::cos(ph), std::sqrt(1 - z * z) * std::sin(ph), z});
  }
  auto inHole = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const Vec3 d = glm::normalize(dirs[a] + dirs[b] + dirs[c]);
    for (const Vec3& ctr : centres)
      if (std::acos(std::clamp(glm::dot(d, ctr), -1.0, 1.0)) < hole_rad)
        return true;
    return false;
  };
  auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (!inHole(a, b, c))
      m.triangles.push_back({a, b, c});
  };
  for (int j = 0; j < n_lon; ++j)
    add(0, ring(1, j), ring(1, j + 1));
  for (int i = 1; i + 1 < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      add(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
      add(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
    }
  for (int j = 0; j < n_lon; ++j)
    add(south, ring(n_lat - 1, j + 1), ring(n_lat - 1, j));
  return m;
}

TriangleMesh defective() {
  // part 1: an L-block with defects; part 2: a box wound inside out; part 3: a box crossing part 1
  TriangleMesh m = lBlock(0.1, 2);
  const std::size_t n = m.positions.size();
  // duplicate vertices: every vertex of the first 10 triangles gets a copy, used by those triangles
  for (std::size_t t = 0; t < 10; ++t)
    for (std::uint32_t& v : m.triangles[t]) {
      m.positions.push_back(m.positions[v]);
      v = u32(m.positions.size() - 1);
    }
  m.positions.push_back({5.0, 5.0, 5.0});  // unreferenced
  m.positions.push_back({NAN, 0.0, 0.0});  // non-finite, used by a triangle below
  const std::uint32_t nan_v = u32(m.positions.size() - 1);
  m.triangles.push_back({0, 1, nan_v});
  m.triangles.push_back({0, 1, u32(n + 1000)});  // index out of range
  m.triangles.push_back({2, 2, 3});              // repeated index
  const Triangle first = m.triangles[20];
  m.triangles.push_back(first);  // duplicate
  // a zero-area triangle: three collinear lattice points on an edge of the block
  m.positions.push_back({0.0, 0.0, 0.0});
  m.positions.push_back({0.05, 0.0, 0.0});
  m.positions.push_back({0.1, 0.0, 0.0});
  const std::uint32_t c0 = u32(m.positions.size() - 3);
  m.triangles.push_back({c0, c0 + 1, c0 + 2});
  std::swap(m.triangles[30][1], m.triangles[30][2]);  // one flipped triangle
  // a non-manifold fin: a triangle hanging off an existing edge of the block
  const Triangle e = m.triangles[40];
  m.positions.push_back((m.positions[e[0]] + m.positions[e[1]]) * 0.5 + Vec3{0.0, 0.0, 0.3});
  m.triangles.push_back({e[0], e[1], u32(m.positions.size() - 1)});
  // a hole: drop one triangle
  m.triangles.erase(m.triangles.begin() + 50);
  // part 2: inside out
  TriangleMesh inv = box({0.4, 0.0, 0.0}, {0.5, 0.1, 0.1});
  for (Triangle& t : inv.triangles)
    std::swap(t[1], t[2]);
  append(m, inv);
  // part 3: a bar crossing the block's top face
  append(m, box({0.02, 0.02, 0.03}, {0.05, 0.05, 0.15}));
  return m;
}

std::optional<TriangleMesh> readSimple(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return std::nullopt;
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  TriangleMesh m;
  const bool stl = path.size() > 4 && (path.substr(path.size() - 4) == ".STL" ||
                                       path.substr(path.size() - 4) == ".stl");
  if (stl) {
    if (data.size() < 84)
      return std::nullopt;
    std::uint32_t count = 0;
    std::memcpy(&count, data.data() + 80, 4);
    if (data.size() < 84 + 50ull * count)
      return std::nullopt;
    for (std::uint32_t t = 0; t < count; ++t) {
      const char* rec = data.data() + 84 + 50ull * t + 12;
      Triangle tri{};
      for (std::size_t k = 0; k < 3; ++k) {
        float f[3];
        std::memcpy(f, rec + 12 * k, 12);
        tri[k] = u32(m.positions.size());
        m.positions.push_back({f[0], f[1], f[2]});
      }
      m.triangles.push_back(tri);
    }
    return m;
  }
  std::istringstream lines(data);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      Vec3 p;
      ls >> p.x >> p.y >> p.z;
      m.positions.push_back(p);
    } else if (tag == "f") {
      std::vector<std::uint32_t> poly;
      std::string tok;
      while (ls >> tok)
        poly.push_back(u32(std::stoul(tok.substr(0, tok.find('/'))) - 1));
      for (std::size_t k = 1; k + 1 < poly.size(); ++k)
        m.triangles.push_back({poly[0], poly[k], poly[k + 1]});
    }
  }
  if (m.triangles.empty())
    return std::nullopt;
  return m;
}

std::optional<TriangleMesh> sharedMesh(const std::string& file) {
  namespace fs = std::filesystem;
  if (const char* dir = std::getenv("HAPTICD_MESHES_DIR"); dir != nullptr && *dir != 0) {
    std::error_code ec;
    const fs::path candidate = fs::path(dir) / file;
    if (fs::is_regular_file(candidate, ec))
      return readSimple(candidate.string());
    return std::nullopt;
  }
  std::vector<fs::path> starts{fs::current_path()};
#ifdef HAPTICD_SOURCE_DIR
  starts.push_back(fs::path(HAPTICD_SOURCE_DIR));
#endif
  for (fs::path dir : starts) {
    for (int up = 0; up < 6 && !dir.empty(); ++up, dir = dir.parent_path()) {
      const fs::path candidate = dir / "shared" / "meshes" / file;
      std::error_code ec;
      if (fs::is_regular_file(candidate, ec))
        return readSimple(candidate.string());
      if (dir == dir.parent_path())
        break;
    }
  }
  return std::nullopt;
}

}  // namespace hapticd::decomp::models
