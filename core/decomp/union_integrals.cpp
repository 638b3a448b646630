#include "core/decomp/union_integrals.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hapticd::decomp {

using geom::Mat3;
namespace {

struct Box {
  Vec3 lo{std::numeric_limits<double>::infinity()};
  Vec3 hi{-std::numeric_limits<double>::infinity()};
};

Box boxOf(const Cell& cell) {
  Box b;
  for (const auto& loop : cell) {
    for (const Vec3& v : loop) {
      b.lo = glm::min(b.lo, v);
      b.hi = glm::max(b.hi, v);
    }
  }
  return b;
}

// the boxes share more than a layer `tol` thick
bool overlap(const Box& a, const Box& b, double tol) {
  for (int k = 0; k < 3; ++k) {
    if (a.lo[k] >= b.hi[k] - tol || b.lo[k] >= a.hi[k] - tol)
      return false;
  }
  return true;
}

Vec3 meanVertex(const Cell& cell) {
  Vec3 sum{0.0};
  std::size_t n = 0;
  for (const auto& loop : cell) {
    for (const Vec3& v : loop)
      sum += v;
    n += loop.size();
  }
  return n > 0 ? sum / static_cast<double>(n) : sum;
}

// a loop's area vector (Newell), about its first vertex
Vec3 areaVector(const std::vector<Vec3>& loop) {
  Vec3 a{0.0};
  for (std::size_t k = 1; k + 1 < loop.size(); ++k)
    a += glm::cross(loop[k] - loop[0], loop[k + 1] - loop[0]);
  return 0.5 * a;
}

// the cell's face planes, facing out (the cell below each)
std::vector<Plane> facePlanes(const Cell& cell) {
  const Vec3 inside = meanVertex(cell);
  std::vector<Plane> planes;
  planes.reserve(cell.size());
  for (const auto& loop : cell) {
    const Vec3 a = areaVector(loop);
    const double len = glm::length(a);
    if (!(len > 0.0))
      continue;
    Plane p{a / len, 0.0};
    p.d = glm::dot(p.n, loop[0]);
    if (p.signedDistance(inside) > 0.0)
      p = Plane{-p.n, -p.d};
    planes.push_back(p);
  }
  return planes;
}

double surfaceArea(const Cell& cell) {
  double area = 0.0;
  for (const auto& loop : cell)
    area += glm::length(areaVector(loop));
  return area;
}

// the parts of `cell` outside the convex solid below `planes`, appended to `out` as cells; false
// (nothing appended) when the two share no more than a layer `tol` thick, or when `work` (one
// per vertex tested against a plane) passes `max_work`
bool subtract(const Cell& cell,
              const std::vector<Plane>& planes,
              double tol,
              std::vector<Cell>& out,
              std::size_t& work,
              std::size_t max_work) {
  const std::size_t first = out.size();
  Cell rest = cell, below, above;
  std::vector<Vec3> section;
  for (const Plane& plane : planes) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const auto& loop : rest) {
      for (const Vec3& v : loop) {
        const double d = plane.signedDistance(v);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
      work += loop.size();
    }
    if (work > max_work) {
      out.resize(first);
      return false;
    }
    if (hi <= tol)
      continue;  // the rest is inside this plane
    if (lo >= -tol) {
      out.resize(first);  // the rest is outside it: the cell is outside the solid
      return false;
    }
    splitCell(rest, plane, below, above, section);
    if (above.size() >= 4)
      out.push_back(std::move(above));
    above.clear();
    rest.swap(below);
  }
  // the rest is inside the solid: a sliver (a slab's volume over half its area is its
  // thickness) is no overlap
  if (rest.size() < 4 || !(cellIntegrals(rest).volume > 0.5 * tol * surfaceArea(rest))) {
    out.resize(first);
    return false;
  }
  return true;
}

}  // namespace

geom::VolumeIntegrals cellIntegrals(const Cell& cell) {
  // tetrahedra from a point r inside (the cell is convex) to every loop's fan triangles, in
  // coordinates about r; each counted positive, so a loop's orientation does not matter
  const Vec3 r = meanVertex(cell);
  double volume = 0.0;
  Vec3 first{0.0};
  Mat3 second{0.0};
  for (const auto& loop : cell) {
    if (loop.size() < 3)
      continue;
    const Vec3 a = loop[0] - r;
    for (std::size_t k = 1; k + 1 < loop.size(); ++k) {
      const Vec3 b = loop[k] - r, c = loop[k + 1] - r;
      const double v = std::abs(glm::dot(a, glm::cross(b, c))) / 6.0;
      const Vec3 s = a + b + c;
      volume += v;
      first += v * s / 4.0;
      second += (v / 20.0) * (glm::outerProduct(a, a) + glm::outerProduct(b, b) +
                              glm::outerProduct(c, c) + glm::outerProduct(s, s));
    }
  }
  geom::VolumeIntegrals out;
  out.volume = volume;
  out.first = first + volume * r;
  out.second = second + glm::outerProduct(first, r) + glm::outerProduct(r, first) +
               volume * glm::outerProduct(r, r);
  return out;
}

Cell pieceCell(const ConvexPiece& piece) {
  Cell cell;
  cell.reserve(piece.triangles.size());
  for (const Triangle& t : piece.triangles)
    cell.push_back({piece.vertices[t[0]], piece.vertices[t[1]], piece.vertices[t[2]]});
  return cell;
}

Cell polytopeCell(const geom::Polytope& shape, const geom::Transform& X) {
  Cell cell;
  cell.reserve(shape.faces().size());
  for (std::uint32_t f = 0; f < shape.faces().size(); ++f) {
    std::vector<Vec3> loop;
    for (const geom::Polytope::FaceEdge& e : shape.faceEdges(f))
      loop.push_back(X.apply(shape.vertices()[e.vertex].p));
    cell.push_back(std::move(loop));
  }
  return cell;
}

UnionIntegrals unionIntegrals(std::span<const Cell> solids,
                              std::span<const geom::VolumeIntegrals> own,
                              std::size_t max_work) {
  UnionIntegrals out;
  std::vector<Box> boxes;
  std::vector<std::vector<Plane>> planes;
  Box all;
  for (const Cell& s : solids) {
    boxes.push_back(boxOf(s));
    planes.push_back(facePlanes(s));
    all.lo = glm::min(all.lo, boxes.back().lo);
    all.hi = glm::max(all.hi, boxes.back().hi);
  }
  if (solids.empty())
    return out;
  const auto ownOf = [&](std::size_t i) {
    return own.size() == solids.size() ? own[i] : cellIntegrals(solids[i]);
  };
  const double tol = 1e-9 * glm::length(all.hi - all.lo);
  std::vector<Cell> parts, next;
  for (std::size_t i = 0; i < solids.size(); ++i) {
    parts.assign(1, solids[i]);
    bool cut = false;
    for (std::size_t j = 0; j < i && !parts.empty(); ++j) {
      if (!overlap(boxes[i], boxes[j], tol))
        continue;
      next.clear();
      for (Cell& part : parts) {
        if (overlap(boxOf(part), boxes[j], tol) &&
            subtract(part, planes[j], tol, next, out.work, max_work))
          cut = true;
        else
          next.push_back(std::move(part));
      }
      parts.swap(next);
      if (out.work > max_work) {
        // given up: the plain sum, said by `exact`
        out.exact = false;
        out.integrals = {};
        for (std::size_t k = 0; k < solids.size(); ++k)
          out.integrals.add(ownOf(k));
        return out;
      }
    }
    if (!cut) {
      out.integrals.add(ownOf(i));
      continue;
    }
    ++out.overlapping;
    for (const Cell& part : parts)
      out.integrals.add(cellIntegrals(part));
  }
  return out;
}

}  // namespace hapticd::decomp
